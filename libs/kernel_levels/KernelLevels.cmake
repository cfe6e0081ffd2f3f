# tilth_add_kernel_levels(NAME SOURCES src... DISPATCH src... [LIBRARIES lib...])
# Builds the static library NAME from SOURCES compiled once per instruction-set level --
# the baseline (on x86-64, -march=x86-64: SSE2) and, on x86-64, x86-64-v3 (AVX2, FMA; with
# -march=x86-64-v3) -- and DISPATCH, compiled once, which picks between them
# (kernel_levels/kernel_levels.h). Only these two: x86-64-v2 and x86-64-v4 (AVX-512, rare
# on industrial PCs) paid less than 10 % on the whole chain (bench/RESULTS.md). SOURCES see
# TILTH_KERNEL_LEVEL, the level's namespace (baseline, x86_64_v3), and
# TILTH_KERNEL_LEVEL_NAME, its name; DISPATCH sees TILTH_KERNEL_LEVELS_X86_64 where the
# x86-64 level is built. Internal to this tree.
function(tilth_add_kernel_levels name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DISPATCH;LIBRARIES" ${ARGN})
  set(levels baseline)
  set(x86_64 FALSE)
  if(CMAKE_SYSTEM_PROCESSOR MATCHES "^(x86_64|AMD64)$")
    set(x86_64 TRUE)
    list(APPEND levels x86-64-v3)
  endif()
  set(objects)
  set(targets ${name})
  foreach(level IN LISTS levels)
    string(REPLACE "-" "_" namespace ${level})
    set(target ${name}_${namespace})
    add_library(${target} OBJECT ${ARG_SOURCES})
    target_compile_definitions(${target} PRIVATE
      TILTH_KERNEL_LEVEL=${namespace} TILTH_KERNEL_LEVEL_NAME="${level}")
    if(NOT level STREQUAL "baseline")
      target_compile_options(${target} PRIVATE -march=${level})
    elseif(x86_64)
      target_compile_options(${target} PRIVATE -march=x86-64)  # whatever the default flags
    endif()
    target_link_libraries(${target} PRIVATE tilth_lib_kernel_levels ${ARG_LIBRARIES})
    list(APPEND objects $<TARGET_OBJECTS:${target}>)
    list(APPEND targets ${target})
  endforeach()
  add_library(${name} STATIC ${objects} ${ARG_DISPATCH})
  target_include_directories(${name} PUBLIC ${CMAKE_CURRENT_SOURCE_DIR})
  target_link_libraries(${name} PUBLIC tilth_lib_kernel_levels ${ARG_LIBRARIES})
  if(x86_64)
    target_compile_definitions(${name} PRIVATE TILTH_KERNEL_LEVELS_X86_64)
  endif()
  foreach(target IN LISTS targets)
    set_target_properties(${target} PROPERTIES
      POSITION_INDEPENDENT_CODE ON CXX_VISIBILITY_PRESET hidden VISIBILITY_INLINES_HIDDEN ON)
    target_compile_features(${target} PRIVATE cxx_std_20)
    target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic)
  endforeach()
endfunction()

# tilth_add_plugin(NAME [SOURCES src...] [STAGES src...] [LIBRARIES lib...])
# Builds the plugin library tilth_NAME.so against the SDK and LIBRARIES. SOURCES are the
# plugin's own files (the one with TILTH_PLUGIN); STAGES, the files of its stages, are
# compiled once into the object library tilth_NAME_stages, which the plugin links and so
# can a test or benchmark (with a TILTH_PLUGIN of its own), to run exactly the code the
# plugin ships. Used in this tree and, through find_package(Tilth), by plugins built out
# of tree.
function(tilth_add_plugin name)
  cmake_parse_arguments(ARG "" "" "SOURCES;STAGES;LIBRARIES" ${ARGN})
  set(target tilth_${name})
  set(targets ${target})
  add_library(${target} MODULE ${ARG_SOURCES})
  set_target_properties(${target} PROPERTIES PREFIX "" LINKER_LANGUAGE CXX)
  target_link_libraries(${target} PRIVATE Tilth::sdk ${ARG_LIBRARIES})
  if(ARG_STAGES)
    set(stages ${target}_stages)
    add_library(${stages} OBJECT ${ARG_STAGES})
    set_target_properties(${stages} PROPERTIES POSITION_INDEPENDENT_CODE ON)
    target_include_directories(${stages} PUBLIC ${CMAKE_CURRENT_SOURCE_DIR})
    target_link_libraries(${stages} PUBLIC Tilth::sdk ${ARG_LIBRARIES})
    target_sources(${target} PRIVATE $<TARGET_OBJECTS:${stages}>)
    list(APPEND targets ${stages})
  endif()
  foreach(each IN LISTS targets)
    set_target_properties(${each} PROPERTIES
      CXX_VISIBILITY_PRESET hidden VISIBILITY_INLINES_HIDDEN ON)
    target_compile_features(${each} PRIVATE cxx_std_20)
    target_compile_options(${each} PRIVATE -Wall -Wextra -Wpedantic)
  endforeach()
  if(DEFINED TILTH_PLUGIN_OUTPUT_DIR)
    set_target_properties(${target} PROPERTIES LIBRARY_OUTPUT_DIRECTORY ${TILTH_PLUGIN_OUTPUT_DIR})
  endif()
  if(DEFINED TILTH_PLUGIN_INSTALL_DIR)
    # The SDK library, from the plugin directory.
    file(RELATIVE_PATH sdk_dir /prefix/${TILTH_PLUGIN_INSTALL_DIR} /prefix/${CMAKE_INSTALL_LIBDIR})
    set_target_properties(${target} PROPERTIES INSTALL_RPATH "$ORIGIN/${sdk_dir}")
    install(TARGETS ${target} LIBRARY DESTINATION ${TILTH_PLUGIN_INSTALL_DIR} COMPONENT runtime)
  endif()
endfunction()

# tilth_add_plugin(NAME SOURCES src... [LIBRARIES lib...])
# Builds the plugin library tilth_NAME.so against the SDK alone. Used in this tree and,
# through find_package(Tilth), by plugins built out of tree.
function(tilth_add_plugin name)
  cmake_parse_arguments(ARG "" "" "SOURCES;LIBRARIES" ${ARGN})
  set(target tilth_${name})
  add_library(${target} MODULE ${ARG_SOURCES})
  set_target_properties(${target} PROPERTIES
    PREFIX ""
    CXX_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON)
  target_compile_features(${target} PRIVATE cxx_std_20)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic)
  target_link_libraries(${target} PRIVATE Tilth::sdk ${ARG_LIBRARIES})
  if(DEFINED TILTH_PLUGIN_OUTPUT_DIR)
    set_target_properties(${target} PROPERTIES LIBRARY_OUTPUT_DIRECTORY ${TILTH_PLUGIN_OUTPUT_DIR})
  endif()
  if(DEFINED TILTH_PLUGIN_INSTALL_DIR)
    install(TARGETS ${target} LIBRARY DESTINATION ${TILTH_PLUGIN_INSTALL_DIR} COMPONENT runtime)
  endif()
endfunction()

# Writes a header holding the report's script and style sheet as string constants:
#   cmake -DJS=report.js -DCSS=report.css -DOUT=report_assets.h -P embed_assets.cmake
file(READ ${JS} js)
file(READ ${CSS} css)
foreach(text js css)
  string(FIND "${${text}}" ")tilth_asset\"" found)
  if(NOT found EQUAL -1)
    message(FATAL_ERROR "${text} contains the raw-string delimiter )tilth_asset\"")
  endif()
endforeach()
file(WRITE ${OUT}.tmp
  "// Generated from report.js and report.css by embed_assets.cmake.\n#pragma once\n"
  "#include <string_view>\n"
  "inline constexpr std::string_view kReportJs = R\"tilth_asset(${js})tilth_asset\";\n"
  "inline constexpr std::string_view kReportCss = R\"tilth_asset(${css})tilth_asset\";\n")
file(COPY_FILE ${OUT}.tmp ${OUT} ONLY_IF_DIFFERENT)
file(REMOVE ${OUT}.tmp)

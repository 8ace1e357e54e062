# The HTML report's front end (docs/report.md). Its chart library (uPlot) comes from the npm registry
# at build time: `npm ci` on report/package-lock.json in the build folder (node_modules never goes
# into the source tree), then report/embed_assets.cmake writes a C++ source that embeds the
# library's minified script and styles with the page's own template, script and styles, so
# `cheval report` writes a self-contained page and the executable works anywhere.
#
# Sets CHEVAL_REPORT_SOURCES (the library's report sources, with the embedded files or without them)
# and, with the report, CHEVAL_REPORT_NODE_MODULES (the folder the browser test takes
# playwright-core from).
find_program(CHEVAL_NPM_EXECUTABLE npm)
set(cheval_report_default OFF)
if(CHEVAL_NPM_EXECUTABLE)
  set(cheval_report_default ON)
endif()
option(CHEVAL_BUILD_REPORT "Embed the HTML report's chart library (uPlot, installed with npm ci at build time)"
       ${cheval_report_default})

set(CHEVAL_REPORT_SOURCES
  ${PROJECT_SOURCE_DIR}/src/report/decimate.cc
  ${PROJECT_SOURCE_DIR}/src/report/report.cc
  ${PROJECT_SOURCE_DIR}/src/report/html.cc
  ${PROJECT_SOURCE_DIR}/src/report/distribution.cc
  ${PROJECT_SOURCE_DIR}/src/report/series.cc
  ${PROJECT_SOURCE_DIR}/src/report/sections.cc
  ${PROJECT_SOURCE_DIR}/src/report/rotor_page.cc)

if(CHEVAL_BUILD_REPORT)
  if(NOT CHEVAL_NPM_EXECUTABLE)
    message(FATAL_ERROR "CHEVAL_BUILD_REPORT=ON needs npm (not found); install it or configure with -DCHEVAL_BUILD_REPORT=OFF")
  endif()
  set(report_source ${PROJECT_SOURCE_DIR}/report)
  set(report_build ${PROJECT_BINARY_DIR}/report)
  set(CHEVAL_REPORT_NODE_MODULES ${report_build}/node_modules)
  # The browser test's driver (playwright-core) is a development dependency: only with the tests.
  set(npm_flags --no-audit --no-fund --ignore-scripts)
  if(NOT CHEVAL_BUILD_TESTS)
    list(APPEND npm_flags --omit=dev)
  endif()
  file(MAKE_DIRECTORY ${report_build})
  add_custom_command(
    OUTPUT ${CHEVAL_REPORT_NODE_MODULES}/.package-lock.json
    COMMAND ${CMAKE_COMMAND} -E copy_if_different ${report_source}/package.json ${report_source}/package-lock.json
            ${report_build}
    COMMAND ${CHEVAL_NPM_EXECUTABLE} ci ${npm_flags}
    WORKING_DIRECTORY ${report_build}
    DEPENDS ${report_source}/package.json ${report_source}/package-lock.json
    COMMENT "npm ci in ${report_build} (the report's chart library)"
    VERBATIM)
  set(uplot ${CHEVAL_REPORT_NODE_MODULES}/uplot)
  add_custom_command(
    OUTPUT ${report_build}/report_assets.cc
    COMMAND ${CMAKE_COMMAND}
            -DOUTPUT=${report_build}/report_assets.cc
            -DASSETS_HEADER=${PROJECT_SOURCE_DIR}/src/report/assets.h
            -DFRAME=${report_source}/frame.html
            -DPAGE_TEMPLATE=${report_source}/page.html
            -DPAGE_SCRIPT=${report_source}/charts.js|${report_source}/report.js
            -DPAGE_STYLE=${report_source}/report.css
            -DCHART_SCRIPT=${uplot}/dist/uPlot.iife.min.js
            -DCHART_STYLE=${uplot}/dist/uPlot.min.css
            -DCHART_PACKAGE=${uplot}/package.json
            -DROTOR_TEMPLATE=${report_source}/rotors.html
            -DROTOR_SCRIPT=${report_source}/charts.js|${report_source}/rotors.js
            -P ${report_source}/embed_assets.cmake
    DEPENDS ${CHEVAL_REPORT_NODE_MODULES}/.package-lock.json ${report_source}/embed_assets.cmake
            ${report_source}/page.html ${report_source}/charts.js ${report_source}/report.js ${report_source}/report.css
            ${report_source}/frame.html ${report_source}/rotors.html ${report_source}/rotors.js
    COMMENT "Embedding the report page and uPlot"
    VERBATIM)
  list(APPEND CHEVAL_REPORT_SOURCES ${report_build}/report_assets.cc)
else()
  message(STATUS "cheval report: off (CHEVAL_BUILD_REPORT=OFF; npm found: ${CHEVAL_NPM_EXECUTABLE})")
  list(APPEND CHEVAL_REPORT_SOURCES ${PROJECT_SOURCE_DIR}/src/report/assets_unavailable.cc)
endif()

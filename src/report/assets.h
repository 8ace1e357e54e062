#pragma once
// Internal: the files the report page is made of, embedded into the library at build time
// (report/embed_assets.cmake writes them from report/ and the chart library's npm package), or
// none when the build has no chart library (CMake option CHEVAL_BUILD_REPORT=OFF).

#include <optional>
#include <string_view>

namespace cheval::report::detail {

struct PageAssets {
  std::string_view page_template;  ///< report/page.html, with {{NAME}} markers
  std::string_view page_script;    ///< report/charts.js then report/report.js
  std::string_view page_style;     ///< report/report.css
  std::string_view chart_script;   ///< the chart library's minified script
  std::string_view chart_style;    ///< and its styles
  std::string_view chart_library;  ///< its name and version, e.g. "uplot 1.6.32"
};

/// The embedded files, or nullopt in a build without them.
std::optional<PageAssets> EmbeddedPageAssets();

}  // namespace cheval::report::detail

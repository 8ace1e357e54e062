#pragma once
// Internal: the files the report page is made of, embedded into the library at build time
// (report/embed_assets.cmake writes them from report/ and the chart library's npm package), or
// none when the build has no chart library (CMake option CHEVAL_BUILD_REPORT=OFF).

#include <optional>
#include <string>
#include <string_view>

namespace cheval::report::detail {

struct PageAssets {
  std::string_view page_template;  ///< report/page.html: the report's <main> (no markers)
  std::string_view page_script;    ///< report/charts.js then report/report.js
  std::string_view page_style;     ///< report/report.css
  std::string_view chart_script;   ///< the chart library's minified script
  std::string_view chart_style;    ///< and its styles
  std::string_view chart_library;  ///< its name and version, e.g. "uplot 1.6.32"
  std::string_view frame;           ///< report/frame.html: every page around its <main>, {{NAME}} markers
  std::string_view rotor_template;  ///< report/rotors.html: the <main> of `estimate rotors --report`
  std::string_view rotor_script;    ///< report/charts.js then report/rotors.js
};

/// The embedded files, or nullopt in a build without them.
std::optional<PageAssets> EmbeddedPageAssets();

/// A page: the frame's {{NAME}} markers replaced by `body` (a page's <main>), the chart library's
/// script and styles, the pages' styles, `page_script`, the data (escaped for a script element) and
/// `title` (plain text, escaped). Throws UsageError when the build has no page (RequireReportPage).
std::string RenderPage(std::string_view body, std::string_view page_script, std::string_view data_json,
                       std::string_view title);

}  // namespace cheval::report::detail

#include "cheval/report/report.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "assets.h"
#include "cheval/common/error.h"

namespace cheval::report {
namespace {

// Text for an HTML element's content or an attribute value.
std::string EscapeHtml(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// JSON inside <script type="application/json">: every '<' (only possible inside strings) as \u003c,
// so no "</script>" or "<!--" in a file name can end the element early.
std::string EscapeJsonForScript(std::string_view json) {
  std::string out;
  out.reserve(json.size());
  for (const char c : json) {
    if (c == '<') {
      out += "\\u003c";
    } else {
      out += c;
    }
  }
  return out;
}

}  // namespace

bool ReportPageAvailable() { return detail::EmbeddedPageAssets().has_value(); }

void RequireReportPage() {
  if (!ReportPageAvailable()) {
    throw UsageError(
        "cheval report is not available in this build: it was built without the report's chart library (CMake option "
        "CHEVAL_BUILD_REPORT=OFF, the default when npm is not found at configure time); reconfigure with npm "
        "installed, or with -DCHEVAL_BUILD_REPORT=ON");
  }
}

namespace detail {

std::string RenderPage(std::string_view body, std::string_view page_script, std::string_view data_json,
                       std::string_view title) {
  RequireReportPage();
  const PageAssets assets = *EmbeddedPageAssets();
  const std::pair<std::string_view, std::string> values[] = {
      {"TITLE", EscapeHtml(title)},
      {"BODY", std::string(body)},
      {"CHART_LIBRARY", EscapeHtml(assets.chart_library)},
      {"CHART_STYLE", std::string(assets.chart_style)},
      {"PAGE_STYLE", std::string(assets.page_style)},
      {"CHART_SCRIPT", std::string(assets.chart_script)},
      {"PAGE_SCRIPT", std::string(page_script)},
      {"DATA", EscapeJsonForScript(data_json)},
  };
  // One pass over the template: a marker's value is never scanned for markers itself.
  const std::string_view page = assets.frame;
  std::string out;
  out.reserve(page.size() + body.size() + data_json.size() + assets.chart_script.size() + page_script.size() + 4096);
  size_t at = 0;
  while (true) {
    const size_t open = page.find("{{", at);
    if (open == std::string_view::npos) break;
    const size_t close = page.find("}}", open);
    if (close == std::string_view::npos) throw std::logic_error("report page template: unterminated {{ marker");
    const std::string_view name = page.substr(open + 2, close - open - 2);
    const auto* value =
        std::find_if(std::begin(values), std::end(values), [&](const auto& v) { return v.first == name; });
    if (value == std::end(values))
      throw std::logic_error("report page template: unknown marker {{" + std::string(name) + "}}");
    out.append(page.substr(at, open - at));
    out += value->second;
    at = close + 2;
  }
  out.append(page.substr(at));
  return out;
}

}  // namespace detail

std::string RenderReportHtml(std::string_view data_json, std::string_view title) {
  RequireReportPage();
  const detail::PageAssets assets = *detail::EmbeddedPageAssets();
  return detail::RenderPage(assets.page_template, assets.page_script, data_json, title);
}

}  // namespace cheval::report

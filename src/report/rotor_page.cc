#include "cheval/report/rotor_page.h"

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "assets.h"
#include "cheval/common/error.h"
#include "cheval/common/options.h"
#include "cheval/report/report.h"
#include "series.h"

namespace cheval::report {
namespace {

using detail::Json;

std::string FileName(const std::string& path) { return std::filesystem::path(path).filename().string(); }

Json ErrorJson(const estim::RotorError& error) {
  Json json;
  json["rpm"] = {error.rpm[0], error.rpm[1], error.rpm[2], error.rpm[3]};
  json["percent"] = {error.percent[0], error.percent[1], error.percent[2], error.percent[3]};
  return json;
}

// [first, last] s of each run of consecutive samples outside the scored ones, reaching to the
// neighbouring scored samples so the shading meets the scored spans without a gap.
Json Unscored(const std::vector<estim::RotorStateEstimate>& samples) {
  Json runs = Json::array();
  size_t i = 0;
  while (i < samples.size()) {
    if (samples[i].scored) {
      ++i;
      continue;
    }
    const size_t first = i;
    while (i < samples.size() && !samples[i].scored) ++i;
    const double begin = samples[first > 0 ? first - 1 : first].t;
    const double end = samples[i < samples.size() ? i : i - 1].t;
    runs.push_back({begin, end});
  }
  return runs;
}

}  // namespace

void RotorPageOptions::Validate() const {
  const OptionCheck check("RotorPageOptions");
  check(max_points >= 16, "max_points", "must be at least 16, got {}", max_points);
}

std::string RotorPageData(const estim::RotorEstimate& estimate, const RotorPageOptions& options) {
  options.Validate();
  if (estimate.samples.empty()) throw ComputeError("the rotor estimate has no samples to plot");
  Json data;
  data["page"] = "rotors";
  data["version"] = 1;
  data["generator"] = options.generator;
  data["flight"] = FileName(options.flight_path);
  data["vehicle"] = FileName(options.vehicle_path);
  data["unit"] = "rpm";
  data["duration_s"] = estimate.duration_s;
  data["scored_samples"] = estimate.scored_samples;
  data["samples"] = estimate.samples.size();
  data["seconds"] = estimate.seconds;
  data["states"] = estimate.states;
  data["segments"] = estimate.segments;
  data["iterations"] = estimate.iterations;
  data["converged"] = estimate.converged;
  data["error"] = ErrorJson(estimate.error);
  data["baseline"] = ErrorJson(estimate.baseline);
  data["max_points"] = options.max_points;
  data["unscored"] = Unscored(estimate.samples);

  const size_t n = estimate.samples.size();
  std::vector<double> t(n);
  for (size_t i = 0; i < n; ++i) t[i] = estimate.samples[i].t;
  Json motors = Json::array();
  for (int m = 0; m < 4; ++m) {
    detail::Columns columns = {{"estimated", std::vector<double>(n)},
                               {"measured", std::vector<double>(n)},
                               {"baseline", std::vector<double>(n)}};
    for (size_t i = 0; i < n; ++i) {
      const estim::RotorStateEstimate& s = estimate.samples[i];
      columns[0].second[i] = s.rotor[m] * estim::kRpmPerRadps;
      columns[1].second[i] = s.measured[m] * estim::kRpmPerRadps;
      columns[2].second[i] = s.baseline[m] * estim::kRpmPerRadps;
    }
    Json motor;
    motor["name"] = fmt::format("m{}", m + 1);
    motor["series"] = detail::TimeSeries(t, columns, options.max_points);
    motors.push_back(std::move(motor));
  }
  data["motors"] = std::move(motors);
  return data.dump();
}

std::string RenderRotorPageHtml(std::string_view data_json, std::string_view title) {
  RequireReportPage();
  const detail::PageAssets assets = *detail::EmbeddedPageAssets();
  return detail::RenderPage(assets.rotor_template, assets.rotor_script, data_json, title);
}

std::string RotorPageHtml(const estim::RotorEstimate& estimate, const RotorPageOptions& options) {
  RequireReportPage();
  return RenderRotorPageHtml(
      RotorPageData(estimate, options),
      fmt::format("cheval estimate rotors: {} with {}", FileName(options.flight_path), FileName(options.vehicle_path)));
}

}  // namespace cheval::report

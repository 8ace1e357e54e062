#pragma once
/// \file
/// The HTML page of `cheval estimate rotors --report` (docs/estimator_real_data.md): for each motor
/// m1..m4 the estimated, measured and flatness-baseline rotor speeds over time (the spans outside
/// the scored samples shaded), and the table of per-motor errors of the estimate and of the
/// baseline. The same machinery as `cheval report`'s page (report.h): chart library, styles and
/// chart helpers inlined, the series decimated by min/max buckets (decimate.h).

#include <cstddef>
#include <string>
#include <string_view>

#include "cheval/estim/rotor_estimator.h"
#include "cheval/report/report.h"  // RequireReportPage, checked by a caller before any work

namespace cheval::report {

/// Options of RotorPageData.
struct RotorPageOptions {
  /// Most points of one motor's plotted series (its three speeds decimated together by min/max
  /// buckets; the errors in the table use every sample).
  std::size_t max_points = 5000;
  /// The flight and vehicle files; the page shows only their file names.
  std::string flight_path, vehicle_path;
  /// Shown in the page's footer, e.g. "cheval 0.1.0".
  std::string generator;

  /// Throws OptionError for max_points < 16.
  void Validate() const;
};

/// The page's data (JSON): `page` ("rotors"), `version`, `generator`, `flight` and `vehicle` (file
/// names), `unit` ("rpm"), the estimate's summary (`duration_s`, `scored_samples`, `samples`,
/// `seconds`, `states`, `segments`, `iterations`, `converged`), `error` and `baseline` ({"rpm": [4],
/// "percent": [4]}: RotorEstimate::error and ::baseline), `max_points`, `unscored` ([first, last] s
/// of each run of samples outside the scored ones) and `motors` (4 of {"name": "m1", "series": {"t",
/// "estimated", "measured", "baseline" in rpm, "n"}}, decimated; a value that is not finite is null, a
/// gap). Throws OptionError for bad options, ComputeError for an estimate without samples.
std::string RotorPageData(const estim::RotorEstimate& estimate, const RotorPageOptions& options);

/// The self-contained HTML page around RotorPageData's JSON (report.h's RenderReportHtml with the
/// rotor page's template and script). Throws UsageError when !ReportPageAvailable().
std::string RenderRotorPageHtml(std::string_view data_json, std::string_view title);

/// RotorPageData and RenderRotorPageHtml: the page of `estimate` with a title naming the flight.
std::string RotorPageHtml(const estim::RotorEstimate& estimate, const RotorPageOptions& options);

}  // namespace cheval::report

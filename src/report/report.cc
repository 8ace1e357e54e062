#include "cheval/report/report.h"

#include <algorithm>
#include <filesystem>
#include <cmath>
#include <numeric>
#include <optional>
#include <string>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cheval/common/error.h"
#include "cheval/common/memory.h"
#include "cheval/common/option_names.h"
#include "cheval/common/options.h"
#include "cheval/eval/pairs.h"
#include "cheval/eval/velocity.h"
#include "sections.h"
#include "series.h"

namespace cheval::report {
namespace {

using detail::Clock;
using detail::Json;
using detail::Rounded;
using detail::TimeSeries;

// Columns vx, vy, vz and speed of 3 x n velocities.
detail::Columns VelocityColumns(const Eigen::Ref<const Eigen::Matrix3Xd>& v) {
  detail::Columns columns = {{"vx", {}}, {"vy", {}}, {"vz", {}}, {"speed", {}}};
  for (Eigen::Index i = 0; i < v.cols(); ++i) {
    for (int axis = 0; axis < 3; ++axis) columns[axis].second.push_back(v(axis, i));
    columns[3].second.push_back(v.col(i).norm());
  }
  return columns;
}

// The estimate's states with an alignment applied, every pose (not only the paired ones).
struct AlignedStates {
  Eigen::Matrix3Xd positions, velocities;
};

AlignedStates Aligned(const traj::TrajectoryView& est, const eval::Similarity& alignment, bool velocity,
                      bool body_frame) {
  eval::Association all;
  all.ref.resize(static_cast<size_t>(est.size()));
  std::iota(all.ref.begin(), all.ref.end(), Eigen::Index{0});
  all.est = all.ref;
  eval::PairedStates states(est, est, all);
  if (velocity) states.SetEstimateVelocityInBodyFrame(body_frame);
  states.SetAlignment(alignment);
  AlignedStates out{Eigen::Matrix3Xd(3, est.size()), Eigen::Matrix3Xd(3, velocity ? est.size() : 0)};
  for (Eigen::Index k = 0; k < est.size(); ++k) {
    out.positions.col(k) = states.EstimatePosition(k);
    if (velocity) out.velocities.col(k) = states.EstimateVelocity(k);
  }
  return out;
}

// `reference` and `estimate` carry the names the page shows (Shown) in their path.
eval::EvaluationReport Evaluated(const ReportInput& reference, const ReportInput& estimate,
                                 const eval::EvaluationOptions& evaluation, eval::MetricKind metric) {
  eval::EvaluationReport e;
  e.reference_path = reference.path;
  e.reference_poses = reference.trajectory.size();
  e.estimate_path = estimate.path;
  e.estimate_poses = estimate.trajectory.size();
  e.options = evaluation;
  e.options.metric = metric;
  e.result = eval::Evaluate(reference.trajectory, estimate.trajectory, e.options);
  return e;
}

// The result exactly as `cheval ape|ase --json` writes it for this one estimate.
Json ResultJson(const eval::EvaluationReport& report) {
  return Json::parse(eval::EvaluationJson(std::span<const eval::EvaluationReport>(&report, 1)));
}

// The diagnostics of the reference's Chebyshev fit: every window's interval, samples and degrees;
// the coefficient magnitudes of up to max_windows windows spread evenly; σ and the residual.
Json FitDiagnostics(const cheb::Curve& curve, const Clock& clock, std::size_t max_windows) {
  const double shift = clock.stamps ? static_cast<double>(curve.origin_ns() - clock.origin_ns) * 1e-9 : 0.0;
  Json windows = Json::array();
  std::vector<const cheb::CurveWindow*> all;
  for (size_t s = 0; s < curve.segments().size(); ++s) {
    for (const cheb::CurveWindow& w : curve.segments()[s].windows) {
      windows.push_back({{"segment", s},
                         {"begin", Rounded(w.fit_begin + shift, 9)},
                         {"end", Rounded(w.fit_end + shift, 9)},
                         {"core_begin", Rounded(w.core_begin + shift, 9)},
                         {"core_end", Rounded(w.core_end + shift, 9)},
                         {"samples", w.samples},
                         {"degrees", w.degrees},
                         {"verdict", std::string(cheb::ToString(w.verdict))}});
      if (w.residual_rms.size() == curve.dimension()) {  // end caps are chosen otherwise (docs/velocity.md)
        Json residual = Json::array();
        for (Eigen::Index c = 0; c < w.residual_rms.size(); ++c) residual.push_back(Rounded(w.residual_rms[c], 4));
        windows.back()["residual_rms"] = residual;
        if (w.noise_sigma.size() == curve.dimension()) {
          Json sigma = Json::array();
          for (Eigen::Index c = 0; c < w.noise_sigma.size(); ++c) sigma.push_back(Rounded(w.noise_sigma[c], 4));
          windows.back()["noise_sigma"] = sigma;
        }
      }
      all.push_back(&w);
    }
  }
  Json coefficients = Json::array();
  const size_t shown = std::min(all.size(), max_windows);
  for (size_t i = 0; i < shown; ++i) {
    const size_t index = shown == 1 ? 0 : (i * (all.size() - 1) + (shown - 1) / 2) / (shown - 1);
    const cheb::CurveWindow& w = *all[index];
    Json magnitudes = Json::array();
    for (Eigen::Index c = 0; c < w.coefficient_magnitudes.cols(); ++c) {
      Json column = Json::array();
      for (Eigen::Index k = 0; k < w.coefficient_magnitudes.rows(); ++k) {
        column.push_back(Rounded(w.coefficient_magnitudes(k, c), 4));
      }
      magnitudes.push_back(column);
    }
    // White noise of σ on m samples puts the coefficients of a least-squares fit at about σ·sqrt(2/m).
    // σ is the one the window was tested against (the noise profile's), where it has one.
    const Eigen::VectorXd& sigma = w.noise_sigma.size() == curve.noise_sigma().size() ? w.noise_sigma : curve.noise_sigma();
    Json noise = Json::array();
    for (Eigen::Index c = 0; c < sigma.size(); ++c) {
      noise.push_back(Rounded(sigma[c] * std::sqrt(2.0 / static_cast<double>(std::max<Eigen::Index>(w.samples, 1))), 4));
    }
    coefficients.push_back({{"window", index}, {"magnitudes", magnitudes}, {"noise_level", noise}});
  }
  const auto& sigma = curve.noise_sigma();
  const auto& residual = curve.residual_rms();
  return Json{{"segments", curve.segments().size()},
              {"windows", windows},
              {"coefficients", coefficients},
              {"noise_sigma", std::vector<double>(sigma.data(), sigma.data() + sigma.size())},
              {"noise_sigma_max", std::vector<double>(curve.noise_sigma_max().data(),
                                                      curve.noise_sigma_max().data() + curve.noise_sigma_max().size())},
              {"noisier_samples", curve.noisier_samples()},
              {"stamp_noise_s", curve.stamp_noise_s()},
              {"resolution", std::vector<double>(curve.resolution().data(), curve.resolution().data() + curve.resolution().size())},
              {"at_rounding", [&curve] {
                 std::vector<bool> at(static_cast<size_t>(curve.dimension()));
                 for (int c = 0; c < curve.dimension(); ++c) at[static_cast<size_t>(c)] = curve.AtRounding(c);
                 return at;
               }()},
              {"staircase", curve.staircase()},
              {"residual_rms", std::vector<double>(residual.data(), residual.data() + residual.size())},
              {"unresolved_windows", curve.unresolved_windows()},
              {"local_samples", curve.local_samples()}};
}

// The reference's velocity three ways and its Chebyshev fit; what cannot be computed is a note.
Json ReferenceVelocity(const ReportInput& reference, const ReportOptions& options, const Clock& clock,
                       std::vector<std::string>* notes, Json* fit) {
  const traj::TrajectoryView& ref = reference.trajectory;
  Json velocity = Json::object();
  if (!ref.has_stamps()) {
    notes->push_back(fmt::format("{} has no stamps: its velocity from positions and the Chebyshev fit are not shown",
                                 reference.label));
    return velocity;
  }
  const std::vector<double> t = clock.Poses(ref);
  const std::pair<eval::VelocityMethod, const char*> methods[] = {{eval::VelocityMethod::kChebyshev, "chebyshev"},
                                                                  {eval::VelocityMethod::kCentral, "central"}};
  for (const auto& [method, name] : methods) {
    eval::VelocityOptions velocity_options = options.ase.velocity;
    velocity_options.method = method;
    velocity_options.angular = false;
    try {
      const eval::VelocityEstimate estimate = eval::EstimateVelocity(ref, velocity_options);
      velocity[name] = TimeSeries(t, VelocityColumns(estimate.velocities), options.max_points);
      if (estimate.curve) *fit = FitDiagnostics(*estimate.curve, clock, options.max_fit_windows);
    } catch (const ComputeError& e) {
      notes->push_back(fmt::format("the reference velocity by {} cannot be shown: {}", name,
                                   SpellOptions(e.what(), options.option_names)));
    }
  }
  if (ref.has_velocity()) velocity["given"] = TimeSeries(t, VelocityColumns(ref.velocities()), options.max_points);
  return velocity;
}

}  // namespace

void ReportOptions::Validate() const {
  ape.Validate();
  ase.Validate();
  const OptionCheck check("ReportOptions");
  check(max_points >= 16, "max_points", "must be at least 16, got {}", max_points);
  check(max_fit_windows >= 1, "max_fit_windows", "must be at least 1, got {}", max_fit_windows);
}

namespace {

// The memory the plotted series take, before anything is computed: every plotted number is a JSON
// value, its text in the data and its copy in the page (measured: 36 bytes a value on 200,000-pose
// files with max_points above that). A series has at most min(its samples, max_points) points; the
// reference has its path (7 columns) and up to three velocities (t, vx, vy, vz, speed), each estimate
// its APE series (t, error), path (t, x, y, z, roll, pitch, yaw, error) and RPE series (t, trans, rot),
// and with velocity its ASE series and velocity (5 columns each).
void CheckPlottedMemory(const ReportInput& reference, const std::vector<ReportInput>& estimates,
                        const ReportOptions& options) {
  constexpr double kBytesPerValue = 64;
  auto points = [&](Eigen::Index samples) {
    return static_cast<double>(std::min(static_cast<std::size_t>(std::max<Eigen::Index>(samples, 0)), options.max_points));
  };
  const traj::TrajectoryView& ref = reference.trajectory;
  double values = points(ref.size()) * (7 + 5 * (ref.has_velocity() ? 3 : 2));
  for (const ReportInput& estimate : estimates) {
    const traj::TrajectoryView& est = estimate.trajectory;
    values += points(est.size()) * (2 + 8 + 3 + (est.has_velocity() ? 10 : 0));
  }
  CheckMemory({"ReportOptions", "max_points", values * kBytesPerValue,
               fmt::format("{:.4g} plotted values for {} poses of the reference and {} estimate(s)", values, ref.size(),
                           estimates.size()),
               MemoryCost::kData});
}

// The JSON pointer and value of the first number of `json` that is not finite (nlohmann writes it as
// null), depth first; nullopt when every number is finite.
std::optional<std::pair<std::string, double>> FirstNonFinite(const Json& json, const std::string& at = "") {
  if (json.is_number_float()) {
    const double value = json.get<double>();
    return std::isfinite(value) ? std::nullopt : std::optional(std::pair(at.empty() ? "/" : at, value));
  }
  if (json.is_object()) {
    for (const auto& [key, item] : json.items()) {
      if (auto bad = FirstNonFinite(item, at + "/" + key)) return bad;
    }
  } else if (json.is_array()) {
    for (size_t i = 0; i < json.size(); ++i) {
      if (auto bad = FirstNonFinite(json[i], at + "/" + std::to_string(i))) return bad;
    }
  }
  return std::nullopt;
}

// Paths and attitude are smooth curves drawn by a stride: half the points of a series over time.
std::size_t PathPoints(const ReportOptions& options) { return std::max<std::size_t>(options.max_points / 2, 16); }

// The inputs as the page names them: `path` becomes the file path with options.show_paths, else
// the label; `label` is the given label, else the file name, and default labels that two estimates
// share get their parent folders until they differ (two runs are often both .../result.csv).
std::vector<ReportInput> Shown(const std::vector<ReportInput>& inputs, bool show_paths) {
  std::vector<ReportInput> shown(inputs);
  std::vector<std::filesystem::path> paths;
  for (const ReportInput& input : inputs) paths.emplace_back(input.path);
  for (size_t depth = 1;; ++depth) {
    bool longer = false;
    for (size_t i = 0; i < shown.size(); ++i) {
      if (!inputs[i].label.empty()) continue;
      std::vector<std::filesystem::path> parts(paths[i].begin(), paths[i].end());
      std::erase_if(parts, [](const std::filesystem::path& p) { return p.empty() || p == "/"; });
      const size_t from = parts.size() > depth ? parts.size() - depth : 0;
      std::filesystem::path tail;
      for (size_t k = from; k < parts.size(); ++k) tail /= parts[k];
      shown[i].label = tail.empty() ? inputs[i].path : tail.generic_string();
      longer = longer || from > 0;
    }
    bool distinct = true;
    for (size_t i = 0; i < shown.size() && distinct; ++i) {
      for (size_t j = i + 1; j < shown.size(); ++j) distinct = distinct && shown[i].label != shown[j].label;
    }
    if (distinct || !longer) break;
  }
  for (ReportInput& input : shown) {
    if (!show_paths) input.path = input.label;
  }
  return shown;
}

}  // namespace

Report BuildReport(const ReportInput& reference_input, const std::vector<ReportInput>& estimate_inputs,
                   const ReportOptions& options) {
  options.Validate();
  CheckPlottedMemory(reference_input, estimate_inputs, options);
  const ReportInput reference = Shown({reference_input}, options.show_paths)[0];
  const std::vector<ReportInput> estimates = Shown(estimate_inputs, options.show_paths);
  const traj::TrajectoryView& ref = reference.trajectory;
  Clock clock;
  clock.stamps = ref.has_stamps() && !ref.empty();
  clock.origin_ns = clock.stamps ? *std::min_element(ref.stamps_ns().begin(), ref.stamps_ns().end()) : 0;

  Report report;
  Json data;
  data["format"] = "cheval-report";
  data["version"] = 2;
  data["generator"] = options.generator;
  const auto reference_rotation = ref.has_orientation()
                                      ? std::function<Eigen::Matrix3d(Eigen::Index)>(
                                            [&](Eigen::Index i) { return ref.Rotation(i); })
                                      : nullptr;
  data["reference"] = {{"label", reference.label},
                       {"path", reference.path},
                       {"poses", ref.size()},
                       {"has_stamps", ref.has_stamps()},
                       {"has_orientation", ref.has_orientation()},
                       {"has_velocity", ref.has_velocity()},
                       {"path_xyz", detail::PathSeries(ref.positions(), clock.Poses(ref), reference_rotation, nullptr,
                                                       PathPoints(options))}};
  data["time_axis"] = clock.stamps ? "s" : "index";
  data["time_origin_ns"] = std::to_string(clock.origin_ns);  // a string: int64 does not fit a JavaScript number
  data["options"] = {{"align", std::string(eval::ToString(options.ape.alignment.method))},
                     {"n_align", options.ape.alignment.n_align},
                     {"relation", std::string(eval::ToString(options.ape.relation))},
                     {"t_max_diff", options.ape.association.max_diff_s()},
                     {"t_offset", options.ape.association.offset_s()},
                     {"association", options.ape.continuous_reference ? "continuous" : "nearest"},
                     {"gt_velocity", std::string(eval::ToString(options.ase.reference_velocity))},
                     {"velocity_frame", options.ase.estimate_velocity_body_frame ? "body" : "world"},
                     {"max_points", options.max_points},
                     {"show_paths", options.show_paths}};
  const std::vector<double> rpe_distances = detail::RpeDistances(ref);
  data["rpe_distances"] = rpe_distances;

  Json entries = Json::array();
  for (const ReportInput& estimate : estimates) {
    const traj::TrajectoryView& est = estimate.trajectory;
    const eval::EvaluationReport& ape =
        report.ape.emplace_back(Evaluated(reference, estimate, options.ape, eval::MetricKind::kApe));
    Json entry;
    entry["label"] = estimate.label;
    entry["path"] = estimate.path;
    entry["poses"] = est.size();
    entry["has_velocity"] = est.has_velocity();
    entry["ape"] = ResultJson(ape);
    entry["ape_series"] = TimeSeries(clock.Pairs(ape.result, ref), {{"error", ape.result.errors}}, options.max_points);
    entry["ape_distribution"] = detail::DistributionJson(ape.result.errors);
    {
      // Every pose with its APE (NaN when unpaired), for the top view coloured by error.
      std::vector<double> pose_errors(static_cast<size_t>(est.size()), std::nan(""));
      for (size_t k = 0; k < ape.result.errors.size(); ++k) {
        pose_errors[static_cast<size_t>(ape.result.association.est[k])] = ape.result.errors[k];
      }
      const eval::Similarity& alignment = ape.result.alignment.transform;
      const auto rotation = est.has_orientation() ? std::function<Eigen::Matrix3d(Eigen::Index)>([&](Eigen::Index i) {
        return alignment.ApplyToRotation(est.Rotation(i));
      })
                                                  : nullptr;
      entry["path_xyz"] = detail::PathSeries(Aligned(est, alignment, false, false).positions,
                                             clock.Poses(est, options.ape.association.offset_ns), rotation,
                                             &pose_errors, PathPoints(options));
    }
    entry["rpe"] = detail::RpeJson(ref, est, ape.result, rpe_distances, clock, options.max_points, estimate.label,
                                   &report.notes);
    std::optional<eval::EvaluationReport>& ase = report.ase.emplace_back();
    // Why the estimate has no ASE, if it has none.
    std::string absent;
    if (!est.has_velocity()) {
      absent = "no velocity";
      report.notes.push_back(fmt::format(
          "{} has no velocity: its ASE and velocity are not shown (give a file with velocity columns: tumv, euroc, "
          "vins, or csv with vx,vy,vz)",
          estimate.label));
    } else {
      try {
        ase = Evaluated(reference, estimate, options.ase, eval::MetricKind::kAse);
      } catch (const ComputeError& e) {
        absent = "no ASE";
        report.notes.push_back(fmt::format("the ASE of {} cannot be computed, so it is not shown: {}", estimate.label,
                                           SpellOptions(e.what(), options.option_names)));
      }
    }
    if (ase) {
      const eval::AseErrors& parts = *ase->result.ase;
      detail::Columns columns = {{"total", parts.total}};
      if (parts.has_rotation) {
        std::vector<double> degrees = detail::RotationPartDegrees(parts.rotation);
        entry["ase_rotation_deg"] = detail::BoxJson(BoxOf(degrees));
        columns.push_back({"rotation_deg", std::move(degrees)});
      }
      columns.push_back({"position", parts.position});
      if (parts.has_velocity) columns.push_back({"velocity", parts.velocity});
      entry["ase"] = ResultJson(*ase);
      entry["ase_series"] = TimeSeries(clock.Pairs(ase->result, ref), columns, options.max_points);
      entry["ase_distribution"] = detail::DistributionJson(parts.total);
    } else {
      entry["ase"] = nullptr;
      entry["ase_absent"] = absent;
    }
    if (est.has_velocity()) {
      // The velocity the ASE scored: world frame (after a body-frame estimate velocity is rotated), with the ASE's alignment
      // (the APE's when there is no ASE).
      const eval::Similarity& alignment = (ase ? ase->result : ape.result).alignment.transform;
      const AlignedStates states = Aligned(est, alignment, true, options.ase.estimate_velocity_body_frame);
      entry["velocity"] = TimeSeries(clock.Poses(est, options.ase.association.offset_ns),
                                     VelocityColumns(states.velocities), options.max_points);
    }
    entries.push_back(std::move(entry));
  }
  data["estimates"] = std::move(entries);
  Json fit = nullptr;
  data["reference_velocity"] = ReferenceVelocity(reference, options, clock, &report.notes, &fit);
  data["fit"] = std::move(fit);
  data["notes"] = report.notes;
  // The APE and ASE are finite (eval::Evaluate checks them); what is computed for the charts alone
  // (reference velocities, speeds, the fit's residuals) may still overflow on huge coordinates.
  if (const auto bad = FirstNonFinite(data)) {
    throw ComputeError(fmt::format("the report's value {} is {}, not a finite number: the coordinates are too large "
                                   "to compute with, a value overflowed",
                                   bad->first, bad->second));
  }
  report.data_json = data.dump();
  return report;
}

}  // namespace cheval::report

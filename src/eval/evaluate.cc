#include "cheval/eval/evaluate.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <span>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cheval/cheb/curve.h"
#include "cheval/common/error.h"
#include "cheval/common/options.h"
#include "cheval/eval/res_table.h"  // CsvField
#include "cheval/traj/stamp.h"
#include "enum_names.h"

namespace cheval::eval {
namespace {

constexpr detail::NameTable<MetricKind, 3> kMetricNames{{
    {MetricKind::kApe, {"ape"}}, {MetricKind::kRpe, {"rpe"}}, {MetricKind::kAse, {"ase"}}}};
constexpr detail::NameTable<ReferenceVelocitySource, 4> kVelocitySourceNames{{
    {ReferenceVelocitySource::kAuto, {"auto"}},
    {ReferenceVelocitySource::kGiven, {"given"}},
    {ReferenceVelocitySource::kChebyshev, {"chebyshev"}},
    {ReferenceVelocitySource::kCentral, {"central"}},
}};

// evo prints δ as Python does: an int for frames, a float ("10.0") otherwise.
std::string DeltaText(double delta, DeltaUnit unit) {
  if (unit == DeltaUnit::kFrames) return fmt::format("{}", static_cast<long long>(delta));
  return delta == std::floor(delta) && std::abs(delta) < 1e15 ? fmt::format("{:.1f}", delta) : fmt::format("{}", delta);
}

std::string AlignmentLine(const AlignmentResult& alignment, Eigen::Index pairs) {
  std::string line(AlignmentTitle(alignment.method));
  if (alignment.method != AlignmentMethod::kNone && alignment.method != AlignmentMethod::kOrigin &&
      alignment.pairs_used < pairs) {
    line += fmt::format(" (aligned poses: {})", alignment.pairs_used);
  }
  return line;
}

std::string_view MetricLabel(MetricKind metric) {
  return metric == MetricKind::kApe ? "APE" : metric == MetricKind::kRpe ? "RPE" : "ASE";
}

// Why a result is not finite: the inputs are (the readers accept only finite numbers), so an
// intermediate value overflowed; or the caller's arrays held a non-finite value.
std::string NonFiniteReason(const traj::TrajectoryView& ref, const traj::TrajectoryView& est) {
  double largest = 0.0;
  for (const traj::TrajectoryView* side : {&ref, &est}) {
    if (side->empty()) continue;
    const bool velocity = side->has_velocity();
    if (!side->positions().allFinite() || (velocity && !side->velocities().allFinite())) {
      return "the inputs hold a value that is not a finite number";
    }
    largest = std::max(largest, side->positions().cwiseAbs().maxCoeff());
    if (velocity) largest = std::max(largest, side->velocities().cwiseAbs().maxCoeff());
  }
  return fmt::format("the coordinates are too large to compute with, a value overflowed (largest magnitude {:.3g})",
                     largest);
}

// The first non-finite entry of `values` (nullopt when all are finite).
std::optional<size_t> FirstNonFinite(std::span<const double> values) {
  const auto bad = std::find_if(values.begin(), values.end(), [](double v) { return !std::isfinite(v); });
  return bad == values.end() ? std::nullopt : std::optional<size_t>(static_cast<size_t>(bad - values.begin()));
}

// Throws ComputeError when anything Evaluate computed is not a finite number (never a NaN or an
// infinity in a result, a statistic, the JSON or the CSV): the alignment, each error and ASE part
// (naming the pair, 1-based, and its estimate stamp), the statistics, the KITTI drift.
void RequireFinite(const EvaluationResult& r, const traj::TrajectoryView& ref, const traj::TrajectoryView& est) {
  const std::string_view metric = MetricLabel(r.metric);
  auto fail = [&](const std::string& what, std::string_view value) {
    throw ComputeError(fmt::format("{} is {}, not a finite number: {}", what, value, NonFiniteReason(ref, est)));
  };
  auto fail_value = [&](const std::string& what, double value) { fail(what, fmt::format("{}", value)); };
  const Similarity& s = r.alignment.transform;
  if (!s.rotation.allFinite() || !s.translation.allFinite() || !std::isfinite(s.scale)) {
    fail(fmt::format("the {} alignment", ToString(r.alignment.method)), "partly undefined");
  }
  auto check_pairs = [&](std::span<const double> values, std::string_view part) {
    if (const std::optional<size_t> k = FirstNonFinite(values)) {
      std::string stamp;
      if (*k < r.stamps_ns.size() && est.has_stamps()) stamp = fmt::format(" (estimate stamp {} s)", traj::FormatSeconds(r.stamps_ns[*k]));
      fail_value(fmt::format("the {}{} of pair {} of {}{}", metric, part, *k + 1, values.size(), stamp), values[*k]);
    }
  };
  check_pairs(r.errors, "");
  if (r.ase) {
    check_pairs(r.ase->rotation, " rotation part");
    check_pairs(r.ase->position, " position part");
    check_pairs(r.ase->velocity, " velocity part");
  }
  const std::pair<const ErrorStatistics*, std::string_view> stats[] = {
      {&r.stats, ""}, {&r.rotation_stats, " rotation"}, {&r.position_stats, " position"}, {&r.velocity_stats, " velocity"}};
  for (const auto& [st, part] : stats) {
    const std::pair<std::string_view, double> values[] = {{"rmse", st->rmse}, {"mean", st->mean}, {"median", st->median},
                                                          {"std", st->std},   {"min", st->min},   {"max", st->max},
                                                          {"sse", st->sse}};
    for (const auto& [name, value] : values) {
      if (!std::isfinite(value)) fail_value(fmt::format("the {}{} {}", metric, part, name), value);
    }
  }
  if (r.drift) {
    bool finite = std::isfinite(r.drift->translation_percent) && std::isfinite(r.drift->rotation_deg_per_m);
    for (const DriftResult::Length& l : r.drift->lengths) {
      finite = finite && std::isfinite(l.translation_percent) && std::isfinite(l.rotation_deg_per_m);
    }
    if (!finite) fail("the KITTI drift", "partly undefined");
  }
}

std::string UnitText(std::string_view unit) { return unit.empty() ? "unit-less" : std::string(unit); }

// Sets the reference velocity of the ASE from the chosen source; returns the source's name.
std::string ProvideReferenceVelocity(PairedStates& pairs, const EvaluationOptions& options) {
  ReferenceVelocitySource source = options.reference_velocity;
  const traj::TrajectoryView& ref = pairs.reference();
  if (source == ReferenceVelocitySource::kAuto) {
    source = ref.has_velocity() ? ReferenceVelocitySource::kGiven : ReferenceVelocitySource::kChebyshev;
  }
  switch (source) {
    case ReferenceVelocitySource::kAuto:
    case ReferenceVelocitySource::kGiven:
      if (!ref.has_velocity()) {
        throw ComputeError("EvaluationOptions::reference_velocity given: the reference has no velocity columns (use "
                           "EvaluationOptions::reference_velocity chebyshev to derive it from its positions)");
      }
      return "given";
    case ReferenceVelocitySource::kChebyshev: {
      if (!ref.has_stamps()) throw ComputeError("a reference velocity from positions needs stamps (KITTI times)");
      VelocityOptions velocity = options.velocity;
      velocity.method = VelocityMethod::kChebyshev;
      const std::vector<int64_t> at = PairedStamps(ref.stamps_ns(), pairs.association().ref);
      pairs.SetReferenceVelocities(EstimateVelocity(ref, velocity, std::span<const int64_t>(at)).velocities);
      return "chebyshev";
    }
    case ReferenceVelocitySource::kCentral: {
      if (!ref.has_stamps()) throw ComputeError("a reference velocity from positions needs stamps (KITTI times)");
      VelocityOptions velocity = options.velocity;
      velocity.method = VelocityMethod::kCentral;
      const Eigen::Matrix3Xd all = EstimateVelocity(ref, velocity).velocities;
      Eigen::Matrix3Xd paired(3, pairs.size());
      for (Eigen::Index k = 0; k < pairs.size(); ++k) paired.col(k) = all.col(pairs.association().ref[static_cast<size_t>(k)]);
      pairs.SetReferenceVelocities(std::move(paired));
      return "central";
    }
  }
  return "none";
}

// The reference evaluated at the estimate stamps inside its fitted curve (see EvaluationOptions::
// continuous_reference), with the pairs (k, estimate index) in estimate file order.
traj::Trajectory ContinuousReference(const traj::TrajectoryView& ref, const traj::TrajectoryView& est,
                                     const cheb::CurveOptions& curve_options, int64_t offset_ns,
                                     Association* association) {
  const std::span<const int64_t> ref_stamps = ref.stamps_ns();
  if (!ref.has_stamps() || !est.has_stamps()) throw ComputeError("EvaluationOptions::continuous_reference needs stamps in both files");
  if (!std::is_sorted(ref_stamps.begin(), ref_stamps.end())) {
    throw ComputeError("EvaluationOptions::continuous_reference needs the reference's stamps in increasing order");
  }
  const Eigen::MatrixXd positions = ref.positions().transpose();
  const cheb::Curve curve = cheb::FitCurve(ref_stamps, positions, curve_options);
  // Estimate stamps inside a segment of the curve (not before, after, or in a gap of the reference).
  std::vector<int64_t> stamps;
  association->ref.clear();
  association->est.clear();
  for (Eigen::Index e = 0; e < est.size(); ++e) {
    const int64_t stamp = est.stamps_ns()[e] + offset_ns;  // est + offset = ref
    const double t = static_cast<double>(stamp - curve.origin_ns()) * 1e-9;
    const bool inside = std::any_of(curve.segments().begin(), curve.segments().end(),
                                    [&](const cheb::CurveSegment& s) { return s.begin <= t && t <= s.end; });
    if (!inside) continue;
    association->ref.push_back(static_cast<Eigen::Index>(stamps.size()));
    association->est.push_back(e);
    stamps.push_back(stamp);
  }
  if (stamps.empty()) {
    throw ComputeError(
        "EvaluationOptions::continuous_reference: no estimate stamp lies within the time covered by the reference");
  }
  Eigen::MatrixXd values, derivatives;
  curve.EvaluateMany(stamps, 1, &values, &derivatives);
  traj::Channels channels;
  channels.orientation = ref.has_orientation() ? traj::OrientationKind::kQuaternion : traj::OrientationKind::kNone;
  channels.velocity = true;
  traj::Trajectory out(channels);
  out.Reserve(static_cast<Eigen::Index>(stamps.size()));
  for (size_t k = 0; k < stamps.size(); ++k) {
    Eigen::Vector4d q(0, 0, 0, 1);
    if (ref.has_orientation()) {
      // Slerp between the reference poses around the stamp.
      const auto upper = std::upper_bound(ref_stamps.begin(), ref_stamps.end(), stamps[k]) - ref_stamps.begin();
      const Eigen::Index j1 = std::clamp<Eigen::Index>(upper, 1, ref.size() - 1), j0 = j1 - 1;
      const double span = static_cast<double>(ref_stamps[j1] - ref_stamps[j0]);
      const double f = span > 0 ? std::clamp(static_cast<double>(stamps[k] - ref_stamps[j0]) / span, 0.0, 1.0) : 0.0;
      q = ref.UnitQuaternion(j0).slerp(f, ref.UnitQuaternion(j1)).coeffs();
    }
    const Eigen::Vector3d p = values.row(static_cast<Eigen::Index>(k)).transpose();
    const Eigen::Vector3d v = derivatives.row(static_cast<Eigen::Index>(k)).transpose();
    out.Append(stamps[k], p.data(), q.data(), v.data());
  }
  return out;
}

// True when `t` has orientations and every one is exactly the identity rotation.
bool AllIdentityOrientations(const traj::TrajectoryView& t) {
  if (!t.has_orientation() || t.empty()) return false;
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    if (t.Rotation(i) != Eigen::Matrix3d::Identity()) return false;
  }
  return true;
}

traj::TrajectoryView WithoutOrientation(const traj::TrajectoryView& t) {
  traj::Channels channels = t.channels();
  channels.orientation = traj::OrientationKind::kNone;
  return traj::TrajectoryView(channels, t.stamps_ns(), t.positions().data(), nullptr,
                              t.has_velocity() ? t.velocities().data() : nullptr,
                              t.has_angular_velocity() ? t.angular_velocities().data() : nullptr);
}

void EvaluateAse(PairedStates& pairs, const EvaluationOptions& options, EvaluationResult* result) {
  const AseErrors ase = AseErrorsOf(pairs, !options.pose_only);
  result->errors = ase.total;
  result->rotation_stats = ComputeStatistics(ase.rotation);
  result->position_stats = ComputeStatistics(ase.position);
  result->velocity_stats = ComputeStatistics(ase.velocity);
  if (ase.has_rotation && ase.has_velocity) {
    result->relation = "state";
    result->title = "ASE on SE_2(3): rotation + position + velocity (unit-less: mixes rad-like, m and m/s)";
  } else if (ase.has_velocity) {
    result->relation = "position+velocity";
    result->title = "ASE position + velocity state error (reference without orientation; mixes m and m/s)";
  } else {
    result->relation = "rotation+position";
    result->title = "ASE pose-only: rotation + position (no velocity; mixes rad-like and m)";
  }
  result->title += fmt::format("\n(reference velocity: {})", result->velocity_source);
  result->ase = ase;
}

}  // namespace

std::string_view ToString(MetricKind metric) { return detail::TextOf(kMetricNames, metric); }
std::string_view ToString(ReferenceVelocitySource source) { return detail::TextOf(kVelocitySourceNames, source); }
std::optional<ReferenceVelocitySource> ReferenceVelocitySourceFromString(std::string_view name) {
  return detail::ValueOf(kVelocitySourceNames, name);
}

void EvaluationOptions::Validate() const {
  association.Validate();
  alignment.Validate();
  if (metric == MetricKind::kRpe) rpe.Validate();
  velocity.Validate();
  const OptionCheck check("EvaluationOptions");
  check(!(pose_only && estimate_velocity_body_frame), "pose_only",
        "ignores velocity: drop EvaluationOptions::estimate_velocity_body_frame");
  check(!continuous_reference || reference_velocity == ReferenceVelocitySource::kAuto ||
            reference_velocity == ReferenceVelocitySource::kChebyshev,
        "continuous_reference",
        "takes the reference velocity from its Chebyshev curve: use EvaluationOptions::reference_velocity auto or "
        "chebyshev");
}

EvaluationResult Evaluate(const traj::TrajectoryView& ref, const traj::TrajectoryView& est,
                          const EvaluationOptions& options) {
  options.Validate();
  EvaluationResult result;
  result.metric = options.metric;
  if (options.continuous_reference) {
    result.continuous_reference =
        ContinuousReference(ref, est, options.velocity.curve, options.association.offset_ns, &result.association);
  } else {
    result.association = Associate(ref, est, options.association);
  }
  traj::TrajectoryView reference = options.continuous_reference ? result.continuous_reference->View() : ref;
  if (options.metric == MetricKind::kAse && options.identity_reference_is_position_only &&
      AllIdentityOrientations(reference)) {
    reference = WithoutOrientation(reference);
    result.warnings.push_back(
        "the reference's orientations are all the identity: taken as position-only, the ASE's rotation part is "
        "left out (to take them as real: EvaluationOptions::identity_reference_is_position_only)");
  }
  PairedStates pairs(reference, est, result.association);
  if (options.metric == MetricKind::kAse) {
    result.velocity_source = "none";
    if (!options.pose_only) {
      if (!est.has_velocity()) {
        throw ComputeError("ASE needs the estimate's velocity and it has none: give a file with velocity columns "
                           "(tumv, euroc, vins, or csv with vx,vy,vz), or ask for the pose-only ASE with "
                           "EvaluationOptions::pose_only");
      }
      pairs.SetEstimateVelocityInBodyFrame(options.estimate_velocity_body_frame);
      result.velocity_source =
          options.continuous_reference ? "chebyshev (continuous)" : ProvideReferenceVelocity(pairs, options);
    }
  }
  result.alignment = ComputeAlignment(pairs, options.alignment);
  pairs.SetAlignment(result.alignment.transform);
  const std::string alignment_line = AlignmentLine(result.alignment, pairs.size());

  switch (options.metric) {
    case MetricKind::kApe: {
      result.relation = ToString(options.relation);
      result.unit = RelationUnit(options.relation);
      result.errors = ApeErrors(pairs, options.relation);
      result.title = fmt::format("APE w.r.t. {} ({})", RelationDescription(options.relation), UnitText(result.unit));
      result.stamps_ns = PairedStamps(est.stamps_ns(), result.association.est);
      break;
    }
    case MetricKind::kRpe: {
      RpeOptions rpe = options.rpe;
      rpe.relation = options.relation;
      result.relation = ToString(options.relation);
      result.unit = RelationUnit(options.relation);
      result.rpe_pairs = RpeIndexPairs(pairs, rpe);
      result.errors = RpeErrors(pairs, result.rpe_pairs, options.relation);
      result.title = fmt::format("RPE w.r.t. {} ({})\nfor delta = {} ({}) using {} pairs",
                                 RelationDescription(options.relation), UnitText(result.unit),
                                 DeltaText(rpe.delta, rpe.delta_unit), DeltaUnitLabel(rpe.delta_unit),
                                 rpe.all_pairs ? "all" : "consecutive");
      for (const IndexPair& p : result.rpe_pairs) {
        result.stamps_ns.push_back(pairs.EstimateStamp(p.i));
        result.stamps_end_ns.push_back(pairs.EstimateStamp(p.j));
      }
      if (options.kitti_drift) result.drift = KittiDrift(pairs);
      break;
    }
    case MetricKind::kAse: {
      EvaluateAse(pairs, options, &result);
      result.stamps_ns = PairedStamps(est.stamps_ns(), result.association.est);
      break;
    }
  }
  result.title += "\n" + alignment_line;
  result.stats = ComputeStatistics(result.errors);
  RequireFinite(result, reference, est);
  return result;
}

namespace {

using Json = nlohmann::ordered_json;

// A mean over `count` items: null when there are none.
Json OrNull(Eigen::Index count, double mean) { return count > 0 ? Json(mean) : Json(nullptr); }

Json StatisticsJson(const ErrorStatistics& s) {
  return Json{{"rmse", s.rmse}, {"mean", s.mean}, {"median", s.median}, {"std", s.std},
              {"min", s.min},   {"max", s.max},   {"sse", s.sse},       {"n", s.n}};
}

Json ReportJson(const EvaluationReport& report) {
  const EvaluationResult& r = report.result;
  const EvaluationOptions& options = report.options;
  const Similarity& s = r.alignment.transform;
  Json j;
  j["command"] = std::string(ToString(r.metric));
  j["reference"] = {{"path", report.reference_path}, {"poses", report.reference_poses}};
  j["estimate"] = {{"path", report.estimate_path}, {"poses", report.estimate_poses}};
  if (!report.estimate_label.empty()) j["estimate"]["label"] = report.estimate_label;
  j["association"] = {{"pairs", r.association.size()},
                      {"max_diff", options.association.max_diff_s()},
                      {"offset", options.association.offset_s()}};
  j["association"]["method"] = r.association.by_index          ? "index"
                               : options.continuous_reference ? "continuous"
                                                              : "nearest";
  Json rotation = Json::array();
  for (int row = 0; row < 3; ++row) rotation.push_back({s.rotation(row, 0), s.rotation(row, 1), s.rotation(row, 2)});
  j["alignment"] = {{"method", std::string(ToString(r.alignment.method))},
                    {"rotation", rotation},
                    {"translation", {s.translation.x(), s.translation.y(), s.translation.z()}},
                    {"scale", s.scale}};
  if (r.alignment.method != AlignmentMethod::kNone) j["alignment"]["pairs_used"] = r.alignment.pairs_used;
  j["metric"] = {{"name", std::string(MetricLabel(r.metric))}, {"relation", r.relation}, {"unit", UnitText(r.unit)}};
  if (r.metric == MetricKind::kRpe) {
    j["metric"]["delta"] = options.rpe.delta;
    j["metric"]["delta_unit"] = std::string(ToString(options.rpe.delta_unit));
    j["metric"]["all_pairs"] = options.rpe.all_pairs;
  }
  j["stats"] = StatisticsJson(r.stats);
  if (r.ase) {
    j["parts"] = Json::object();
    if (r.ase->has_rotation) j["parts"]["rotation"] = StatisticsJson(r.rotation_stats);
    j["parts"]["position"] = StatisticsJson(r.position_stats);
    if (r.ase->has_velocity) j["parts"]["velocity"] = StatisticsJson(r.velocity_stats);
    j["velocity_source"] = r.velocity_source;
  }
  if (r.drift) {
    Json lengths = Json::array();
    for (const auto& l : r.drift->lengths) {
      // No segment of a length: no mean (null), not 0 %.
      lengths.push_back({{"length_m", l.length_m}, {"translation_percent", OrNull(l.segments, l.translation_percent)},
                         {"rotation_deg_per_m", OrNull(l.segments, l.rotation_deg_per_m)}, {"segments", l.segments}});
    }
    j["drift"] = {{"translation_percent", OrNull(r.drift->segments, r.drift->translation_percent)},
                  {"rotation_deg_per_m", OrNull(r.drift->segments, r.drift->rotation_deg_per_m)},
                  {"segments", r.drift->segments},
                  {"lengths", lengths}};
  }
  return j;
}

}  // namespace

std::string EvaluationJson(std::span<const EvaluationReport> reports) {
  Json all = Json::array();
  for (const EvaluationReport& report : reports) all.push_back(ReportJson(report));
  return (all.size() == 1 ? all[0] : all).dump(2) + "\n";
}

std::string EvaluationErrorsCsv(std::span<const EvaluationReport> reports) {
  if (reports.empty()) return "";
  const bool several = reports.size() > 1;
  const EvaluationResult& first = reports.front().result;
  const bool rpe = first.metric == MetricKind::kRpe;
  std::string header = several ? "estimate," : "";
  header += rpe ? "stamp,stamp_end,error" : "stamp,error";
  if (first.ase) {
    if (first.ase->has_rotation) header += ",rotation";
    header += ",position";
    if (first.ase->has_velocity) header += ",velocity";
  }
  fmt::memory_buffer out;
  auto it = std::back_inserter(out);
  fmt::format_to(it, "{}\n", header);
  for (const EvaluationReport& report : reports) {
    const EvaluationResult& r = report.result;
    const std::string estimate = CsvField(report.estimate_path);
    for (size_t k = 0; k < r.errors.size(); ++k) {
      if (several) fmt::format_to(it, "{},", estimate);
      fmt::format_to(it, "{}", traj::FormatSeconds(r.stamps_ns[k]));
      if (rpe) fmt::format_to(it, ",{}", traj::FormatSeconds(r.stamps_end_ns[k]));
      fmt::format_to(it, ",{}", r.errors[k]);
      if (r.ase) {
        if (r.ase->has_rotation) fmt::format_to(it, ",{}", r.ase->rotation[k]);
        fmt::format_to(it, ",{}", r.ase->position[k]);
        if (r.ase->has_velocity) fmt::format_to(it, ",{}", r.ase->velocity[k]);
      }
      fmt::format_to(it, "\n");
    }
  }
  return fmt::to_string(out);
}

}  // namespace cheval::eval

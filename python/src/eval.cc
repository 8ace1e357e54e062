// Evaluation in Python: velocity from positions, association, alignment, and APE / RPE / ASE with the
// CLI's JSON (eval::EvaluationJson, the same text `--json` writes).
#include <optional>

#include <fmt/format.h>
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "cheval/common/error.h"
#include "cheval/eval/extrinsic.h"
#include "cheval/eval/evaluate.h"

namespace cheval::python {
namespace {

// The value of an enum option parsed by the library's FromString, or UsageError listing the choices.
template <typename Enum>
Enum Choice(std::optional<Enum> parsed, const char* option, const std::string& value, const char* choices) {
  if (!parsed) throw UsageError(fmt::format("{}: expected one of {}, got '{}'", option, choices, value));
  return *parsed;
}

bool OneOf(const std::string& value, const char* option, const char* first, const char* second) {
  if (value != first && value != second) {
    throw UsageError(fmt::format("{}: expected '{}' or '{}', got '{}'", option, first, second, value));
  }
  return value == second;
}

py::dict Velocity(const py::object& self, const py::object& at, const std::string& method, const py::object& degree,
                  std::optional<double> window, int savgol_window, bool angular, int threads) {
  const PyTrajectory& t = self.cast<const PyTrajectory&>();
  const traj::TrajectoryView view = t.trajectory.View();
  eval::VelocityOptions options;
  options.method = Choice(eval::VelocityMethodFromString(method), "method", method, "chebyshev, central, savgol");
  if (window && options.method == eval::VelocityMethod::kSavitzkyGolay) {
    throw UsageError("window= is the Chebyshev window in seconds; give the Savitzky-Golay window in samples with "
                     "savgol_window=");
  }
  options.curve = CurveOptionsOf(degree, window, std::nullopt, threads);
  options.savgol_window = savgol_window;
  options.angular = angular;
  std::optional<py::array_t<int64_t>> query;
  if (!at.is_none()) query = StampsArray(at);
  eval::VelocityEstimate estimate;
  {
    py::gil_scoped_release release;
    estimate = eval::EstimateVelocity(view, options,
                                      query ? std::optional<std::span<const int64_t>>(SpanOf(*query)) : std::nullopt);
  }
  py::dict out;
  out["stamps"] = query ? py::object(*query)
                        : py::object(ViewOf(view.stamps_ns().data(), {view.size()},
                                            {static_cast<py::ssize_t>(sizeof(int64_t))}, self));
  out["velocities"] = AdoptColumns(std::move(estimate.velocities));
  out["positions"] = estimate.positions.cols() > 0 ? py::object(AdoptColumns(std::move(estimate.positions))) : py::none();
  out["angular_velocities"] =
      angular ? py::object(AdoptColumns(std::move(estimate.angular_velocities))) : py::object(py::none());
  if (!estimate.orientations.empty()) {
    static_assert(sizeof(Eigen::Quaterniond) == 4 * sizeof(double), "quaternions are 4 packed doubles (x y z w)");
    const auto n = static_cast<py::ssize_t>(estimate.orientations.size());
    constexpr auto kDouble = static_cast<py::ssize_t>(sizeof(double));
    out["orientations"] = AdoptArray<double>(
        std::move(estimate.orientations), [](const std::vector<Eigen::Quaterniond>& q) { return q.front().coeffs().data(); },
        {n, 4}, {4 * kDouble, kDouble});
  } else {
    out["orientations"] = py::none();
  }
  out["curve"] = estimate.curve ? py::cast(std::move(*estimate.curve)) : py::none();
  out["angular_residual_rms"] =
      estimate.rotation_curve ? py::cast(estimate.rotation_curve->residual_rms_rad()) : py::object(py::none());
  if (estimate.rounded_stamps) {
    py::dict rounded;
    rounded["resolution_s"] = estimate.rounded_stamps->resolution_s();
    rounded["rate_hz"] = estimate.rounded_stamps->rate_hz();
    out["rounded_stamps"] = rounded;
  } else {
    out["rounded_stamps"] = py::none();
  }
  return out;
}

py::dict Associate(const PyTrajectory& ref, const PyTrajectory& est, double t_max_diff, double t_offset) {
  const eval::AssociationOptions options = eval::AssociationOptions::FromSeconds(t_max_diff, t_offset);
  eval::Association association;
  {
    py::gil_scoped_release release;
    association = eval::Associate(ref.trajectory.View(), est.trajectory.View(), options);
  }
  py::dict out;
  out["ref"] = AdoptVector(std::move(association.ref));
  out["est"] = AdoptVector(std::move(association.est));
  out["by_index"] = association.by_index;
  return out;
}

py::dict Align(const PyTrajectory& ref, const PyTrajectory& est, const std::string& method, Eigen::Index n_align,
               double t_max_diff, double t_offset) {
  eval::EvaluationOptions options;
  options.association = eval::AssociationOptions::FromSeconds(t_max_diff, t_offset);
  options.alignment.method = Choice(eval::AlignmentMethodFromString(method), "method", method,
                                    "none, origin, se3, sim3, scale, posyaw, full");
  options.alignment.n_align = n_align;
  options.Validate();
  eval::AlignmentResult result;
  {
    py::gil_scoped_release release;
    const traj::TrajectoryView r = ref.trajectory.View(), e = est.trajectory.View();
    const eval::Association association = eval::Associate(r, e, options.association);
    result = eval::ComputeAlignment(eval::PairedStates(r, e, association), options.alignment);
  }
  py::dict out;
  out["method"] = std::string(eval::ToString(result.method));
  out["rotation"] = Eigen::Matrix3d(result.transform.rotation);
  out["translation"] = Eigen::Vector3d(result.transform.translation);
  out["scale"] = result.transform.scale;
  out["pairs_used"] = result.pairs_used;
  // The estimate with the alignment applied to every state, as ape/rpe/ase apply it (a left similarity).
  eval::Extrinsic left;
  left.rotation = Eigen::Matrix3d(result.transform.rotation);
  left.translation = result.transform.translation;
  left.scale = result.transform.scale;
  PyTrajectory aligned{eval::TransformTrajectory(est.trajectory.View(), &left, nullptr), est.path, est.format,
                       est.quat_wxyz};
  out["trajectory"] = std::move(aligned);
  return out;
}

// One evaluation: the JSON text of `cheval ape|rpe|ase --json` and the per-pair arrays (no copies).
py::tuple Evaluate(const PyTrajectory& ref, const PyTrajectory& est, const std::string& metric, const std::string& align,
                   Eigen::Index n_align, double t_max_diff, double t_offset, const std::string& association,
                   const std::string& relation, double delta, const std::string& delta_unit, bool all_pairs,
                   bool kitti_drift, const std::string& gt_velocity, const std::string& velocity_frame,
                   bool pose_only) {
  eval::EvaluationReport report;
  eval::EvaluationOptions& options = report.options;
  options.metric = metric == "ape" ? eval::MetricKind::kApe : metric == "rpe" ? eval::MetricKind::kRpe : eval::MetricKind::kAse;
  options.association = eval::AssociationOptions::FromSeconds(t_max_diff, t_offset);
  options.continuous_reference = OneOf(association, "association", "nearest", "continuous");
  options.alignment.method = Choice(eval::AlignmentMethodFromString(align), "align", align,
                                    "none, origin, se3, sim3, scale, posyaw, full");
  options.alignment.n_align = n_align;
  options.relation = Choice(eval::PoseRelationFromString(relation), "relation", relation,
                            "trans_part, rot_part, full, angle_deg, angle_rad, point_distance");
  options.rpe.delta = delta;
  options.rpe.delta_unit =
      Choice(eval::DeltaUnitFromString(delta_unit), "delta_unit", delta_unit, "frames, meters, degrees, radians (or f, m, d, r)");
  options.rpe.all_pairs = all_pairs;
  options.kitti_drift = kitti_drift;
  options.reference_velocity = Choice(eval::ReferenceVelocitySourceFromString(gt_velocity), "gt_velocity",
                                      gt_velocity, "auto, given, chebyshev, central");
  options.estimate_velocity_body_frame = OneOf(velocity_frame, "velocity_frame", "world", "body");
  options.pose_only = pose_only;
  options.Validate();
  report.reference_path = ref.path;
  report.reference_poses = ref.trajectory.size();
  report.estimate_path = est.path;
  report.estimate_poses = est.trajectory.size();
  std::string json;
  {
    py::gil_scoped_release release;
    report.result = eval::Evaluate(ref.trajectory.View(), est.trajectory.View(), options);
    json = eval::EvaluationJson(std::span<const eval::EvaluationReport>(&report, 1));
  }
  eval::EvaluationResult& r = report.result;
  py::dict details;
  details["stamps"] = AdoptVector(std::move(r.stamps_ns));
  if (options.metric == eval::MetricKind::kRpe) details["stamps_end"] = AdoptVector(std::move(r.stamps_end_ns));
  details["error"] = AdoptVector(std::move(r.errors));
  if (r.ase) {
    if (r.ase->has_rotation) details["rotation"] = AdoptVector(std::move(r.ase->rotation));
    details["position"] = AdoptVector(std::move(r.ase->position));
    if (r.ase->has_velocity) details["velocity"] = AdoptVector(std::move(r.ase->velocity));
  }
  return py::make_tuple(json, details);
}

}  // namespace

void BindEvaluation(py::module_& m) {
  // Every default is the library's (the options structs); every keyword comes from option_names.cc.
  const eval::EvaluationOptions defaults;
  const eval::VelocityOptions velocity;
  const auto k = [](const char* field) { return py::arg(Keyword(field)); };
  m.def("velocity", &Velocity, py::arg("trajectory"), py::kw_only(), py::arg("at") = py::none(),
        k("VelocityOptions::method") = std::string(eval::ToString(velocity.method)),
        k("CurveOptions::degree_method") = eval::DegreeName(velocity.curve), k("CurveOptions::window_s") = py::none(),
        k("VelocityOptions::savgol_window") = velocity.savgol_window, k("VelocityOptions::angular") = velocity.angular,
        k("CurveOptions::threads") = velocity.curve.threads, "The compiled velocity; use cheval.velocity (docs/python.md).");
  m.def("associate", &Associate, py::arg("ref"), py::arg("est"), py::kw_only(),
        k("AssociationOptions::max_diff_ns") = defaults.association.max_diff_s(),
        k("AssociationOptions::offset_ns") = defaults.association.offset_s(),
        "The compiled association; use cheval.associate.");
  m.def("align", &Align, py::arg("ref"), py::arg("est"), py::kw_only(), py::arg("method") = "se3",
        k("AlignmentOptions::n_align") = defaults.alignment.n_align,
        k("AssociationOptions::max_diff_ns") = defaults.association.max_diff_s(),
        k("AssociationOptions::offset_ns") = defaults.association.offset_s(),
        "The compiled alignment; use cheval.align.");
  m.def("evaluate", &Evaluate, py::arg("ref"), py::arg("est"), py::arg("metric"), py::kw_only(),
        k("AlignmentOptions::method") = std::string(eval::ToString(defaults.alignment.method)),
        k("AlignmentOptions::n_align") = defaults.alignment.n_align,
        k("AssociationOptions::max_diff_ns") = defaults.association.max_diff_s(),
        k("AssociationOptions::offset_ns") = defaults.association.offset_s(),
        py::arg("association") = defaults.continuous_reference ? "continuous" : "nearest",
        k("EvaluationOptions::relation") = std::string(eval::ToString(defaults.relation)),
        k("RpeOptions::delta") = defaults.rpe.delta,
        k("RpeOptions::delta_unit") = std::string(eval::ToString(defaults.rpe.delta_unit)),
        k("RpeOptions::all_pairs") = defaults.rpe.all_pairs, k("EvaluationOptions::kitti_drift") = defaults.kitti_drift,
        k("EvaluationOptions::reference_velocity") = std::string(eval::ToString(defaults.reference_velocity)),
        k("EvaluationOptions::estimate_velocity_body_frame") = defaults.estimate_velocity_body_frame ? "body" : "world",
        k("EvaluationOptions::pose_only") = defaults.pose_only,
        "The compiled evaluation; use cheval.ape, cheval.rpe, cheval.ase.");
  m.def("defaults", [defaults] {
    py::dict out;
    out["t_max_diff"] = defaults.association.max_diff_s();
    out["t_offset"] = defaults.association.offset_s();
    return out;
  }, "The library's defaults the Python signatures repeat (cheval/__init__.py).");
}

}  // namespace cheval::python

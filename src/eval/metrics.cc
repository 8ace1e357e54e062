#include "cheval/eval/metrics.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "cheval/common/error.h"
#include "cheval/common/options.h"
#include "enum_names.h"

namespace cheval::eval {
namespace {

// A rigid pose [R t; 0 1] with evo's operations (lie_algebra.se3_inverse, relative_se3).
struct Pose {
  Eigen::Matrix3d R;
  Eigen::Vector3d t;

  Pose Inverse() const {
    const Eigen::Matrix3d r_inv = R.transpose();
    return {r_inv, -(r_inv * t)};
  }
  Pose operator*(const Pose& other) const { return {R * other.R, R * other.t + t}; }
  // ‖[R t; 0 1] − I₄‖_F
  double DistanceToIdentity() const { return std::sqrt((R - Eigen::Matrix3d::Identity()).squaredNorm() + t.squaredNorm()); }
};

// relative_se3(a, b) = a⁻¹ · b
Pose Relative(const Pose& a, const Pose& b) { return a.Inverse() * b; }

Pose ReferencePose(const PairedStates& pairs, Eigen::Index k) {
  return {pairs.ReferenceRotation(k), pairs.ReferencePosition(k)};
}
Pose EstimatePose(const PairedStates& pairs, Eigen::Index k) {
  return {pairs.EstimateRotation(k), pairs.EstimatePosition(k)};
}

constexpr double kRadToDeg = 180.0 / std::numbers::pi;

// evo's -r name, its wording in titles, and the unit ("" = unit-less).
constexpr detail::NameTable<PoseRelation, 6, 3> kRelationNames{{
    {PoseRelation::kTranslation, {"trans_part", "translation part", "m"}},
    {PoseRelation::kRotation, {"rot_part", "rotation part", ""}},
    {PoseRelation::kFull, {"full", "full transformation", ""}},
    {PoseRelation::kAngleDeg, {"angle_deg", "rotation angle in degrees", "deg"}},
    {PoseRelation::kAngleRad, {"angle_rad", "rotation angle in radians", "rad"}},
    {PoseRelation::kPointDistance, {"point_distance", "point distance", "m"}},
}};

// The unit's name and evo's label.
constexpr detail::NameTable<DeltaUnit, 4, 2> kDeltaUnitNames{{
    {DeltaUnit::kFrames, {"frames", "frames"}},
    {DeltaUnit::kMeters, {"meters", "m"}},
    {DeltaUnit::kDegrees, {"degrees", "deg"}},
    {DeltaUnit::kRadians, {"radians", "rad"}},
}};  // numpy.rad2deg multiplies by this constant

// The error of a relative or absolute SE(3) error pose E for one relation (not point distance).
double PoseErrorOf(const Pose& E, PoseRelation relation) {
  switch (relation) {
    case PoseRelation::kTranslation:
    case PoseRelation::kPointDistance: return E.t.norm();
    case PoseRelation::kRotation: return (E.R - Eigen::Matrix3d::Identity()).norm();
    case PoseRelation::kFull: return E.DistanceToIdentity();
    case PoseRelation::kAngleRad: return RotationAngle(E.R);
    case PoseRelation::kAngleDeg: return RotationAngle(E.R) * kRadToDeg;
  }
  return 0;
}

void RequireOrientation(const PairedStates& pairs, std::string_view what) {
  if (!pairs.has_reference_orientation() || !pairs.has_estimate_orientation()) {
    throw ComputeError(fmt::format("{} needs the orientation of both trajectories, and the {} is position only "
                                   "(-r point_distance, and APE trans_part, need positions only)",
                                   what, pairs.has_reference_orientation() ? "estimate" : "reference"));
  }
}

std::vector<IndexPair> Neighbours(const std::vector<Eigen::Index>& ids) {
  std::vector<IndexPair> out;
  for (size_t k = 1; k < ids.size(); ++k) out.push_back({ids[k - 1], ids[k]});
  return out;
}

// evo's geometry.accumulated_distances: d_0 = 0, d_k = d_{k-1} + |p_{k-1} − p_k|.
std::vector<double> AccumulatedDistances(const PairedStates& pairs, bool reference) {
  const Eigen::Index n = pairs.size();
  std::vector<double> d(static_cast<size_t>(n), 0.0);
  Eigen::Vector3d previous = reference ? pairs.ReferencePosition(0) : pairs.EstimatePosition(0);
  for (Eigen::Index k = 1; k < n; ++k) {
    const Eigen::Vector3d p = reference ? pairs.ReferencePosition(k) : pairs.EstimatePosition(k);
    d[static_cast<size_t>(k)] = d[static_cast<size_t>(k - 1)] + (previous - p).norm();
    previous = p;
  }
  return d;
}

std::vector<IndexPair> PairsByPath(const PairedStates& pairs, double delta, double tolerance, bool all_pairs) {
  const Eigen::Index n = pairs.size();
  std::vector<IndexPair> out;
  if (!all_pairs) {
    // filter_pairs_by_path, consecutive: the sum restarts at every id; pose 0 is never one.
    std::vector<Eigen::Index> ids;
    double path = 0;
    Eigen::Vector3d previous = pairs.EstimatePosition(0);
    for (Eigen::Index i = 0; i < n; ++i) {
      const Eigen::Vector3d p = pairs.EstimatePosition(i);
      path += (p - previous).norm();
      previous = p;
      if (path >= delta) {
        ids.push_back(i);
        path = 0;
      }
    }
    return Neighbours(ids);
  }
  // All pairs: evo takes, for each i, argmin_j>i |(d_j − d_i) − δ| (first on ties) and keeps it when
  // that is <= tol. v_j = d_j − d_i is non-decreasing in j (rounding is monotone), so the minimum is at
  // the first j with v_j >= δ or at the first j whose v_j equals the largest value below δ.
  const std::vector<double> d = AccumulatedDistances(pairs, false);
  for (Eigen::Index i = 0; i + 1 < n; ++i) {
    const double di = d[static_cast<size_t>(i)];
    auto first_at_least = [&](double value) {
      return std::partition_point(d.begin() + i + 1, d.end(), [&](double dj) { return dj - di < value; }) - d.begin();
    };
    const Eigen::Index above = first_at_least(delta);
    Eigen::Index best = -1;
    double best_residual = 0;
    if (above < n) {
      best = above;
      best_residual = std::abs((d[static_cast<size_t>(above)] - di) - delta);
    }
    if (above > i + 1) {
      const double below_value = d[static_cast<size_t>(above - 1)] - di;
      const Eigen::Index below = first_at_least(below_value);
      const double residual = std::abs(below_value - delta);
      if (best < 0 || residual <= best_residual) {
        best = below;
        best_residual = residual;
      }
    }
    if (best >= 0 && !(best_residual > tolerance)) out.push_back({i, best});
  }
  return out;
}

std::vector<IndexPair> PairsByAngle(const PairedStates& pairs, double delta_rad, double tolerance_rad, bool all_pairs) {
  const Eigen::Index n = pairs.size();
  std::vector<IndexPair> out;
  if (!all_pairs) {
    // filter_pairs_by_angle, consecutive: accumulate the angles between neighbours.
    double accumulated = 0;
    Eigen::Index start = 0;
    Eigen::Matrix3d previous = pairs.EstimateRotation(0);
    for (Eigen::Index i = 1; i < n; ++i) {
      const Eigen::Matrix3d current = pairs.EstimateRotation(i);
      accumulated += RotationAngle(previous.transpose() * current);
      previous = current;
      if (accumulated >= delta_rad) {
        out.push_back({start, i});
        accumulated = 0;
        start = i;
      }
    }
    return out;
  }
  // All pairs: every (i, j > i) with the direct angle within δ ± tol. Quadratic, as in evo.
  std::vector<Eigen::Matrix3d> rotations(static_cast<size_t>(n));
  for (Eigen::Index k = 0; k < n; ++k) rotations[static_cast<size_t>(k)] = pairs.EstimateRotation(k);
  const double lower = delta_rad - tolerance_rad, upper = delta_rad + tolerance_rad;
  for (Eigen::Index i = 0; i + 1 < n; ++i) {
    const Eigen::Matrix3d ri_t = rotations[static_cast<size_t>(i)].transpose();
    for (Eigen::Index j = i + 1; j < n; ++j) {
      const double angle = RotationAngle(ri_t * rotations[static_cast<size_t>(j)]);
      if (lower <= angle && angle <= upper) out.push_back({i, j});
    }
  }
  return out;
}

}  // namespace

std::string_view ToString(PoseRelation relation) { return detail::TextOf(kRelationNames, relation); }
std::optional<PoseRelation> PoseRelationFromString(std::string_view name) {
  return detail::ValueOf(kRelationNames, name);
}
std::string_view RelationDescription(PoseRelation relation) { return detail::TextOf(kRelationNames, relation, 1); }
std::string_view RelationUnit(PoseRelation relation) { return detail::TextOf(kRelationNames, relation, 2); }

bool RelationNeedsOrientation(PoseRelation relation, bool relative) {
  if (relation == PoseRelation::kPointDistance) return false;
  return relative || relation != PoseRelation::kTranslation;
}

double RotationAngle(const Eigen::Matrix3d& R) {
  // scipy Rotation.from_matrix (the branch of the largest of R00, R11, R22, tr R; first on ties) ...
  const double d[4] = {R(0, 0), R(1, 1), R(2, 2), R(0, 0) + R(1, 1) + R(2, 2)};
  int c = 0;
  for (int k = 1; k < 4; ++k) {
    if (d[k] > d[c]) c = k;
  }
  double q[4];  // x, y, z, w
  if (c < 3) {
    const int i = c, j = (i + 1) % 3, k = (j + 1) % 3;
    q[i] = 1 - d[3] + 2 * R(i, i);
    q[j] = R(j, i) + R(i, j);
    q[k] = R(k, i) + R(i, k);
    q[3] = R(k, j) - R(j, k);
  } else {
    q[0] = R(2, 1) - R(1, 2);
    q[1] = R(0, 2) - R(2, 0);
    q[2] = R(1, 0) - R(0, 1);
    q[3] = 1 + d[3];
  }
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  for (double& v : q) v /= norm;
  if (q[3] < 0) {
    for (double& v : q) v = -v;
  }
  // ... then as_rotvec, whose norm evo takes.
  const double vector_norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
  const double angle = 2 * std::atan2(vector_norm, q[3]);
  double scale;
  if (angle <= 1e-3) {
    const double angle2 = angle * angle;
    scale = 2 + angle2 / 12 + 7 * angle2 * angle2 / 2880;
  } else {
    scale = angle / std::sin(angle / 2);
  }
  const double x = scale * q[0], y = scale * q[1], z = scale * q[2];
  return std::sqrt(x * x + y * y + z * z);
}

std::vector<double> ApeErrors(const PairedStates& pairs, PoseRelation relation) {
  const Eigen::Index n = pairs.size();
  std::vector<double> errors(static_cast<size_t>(n));
  if (!RelationNeedsOrientation(relation, false)) {
    for (Eigen::Index k = 0; k < n; ++k) {
      errors[static_cast<size_t>(k)] = (pairs.EstimatePosition(k) - pairs.ReferencePosition(k)).norm();
    }
    return errors;
  }
  RequireOrientation(pairs, fmt::format("APE {}", ToString(relation)));
  for (Eigen::Index k = 0; k < n; ++k) {
    errors[static_cast<size_t>(k)] = PoseErrorOf(Relative(EstimatePose(pairs, k), ReferencePose(pairs, k)), relation);
  }
  return errors;
}

std::string_view ToString(DeltaUnit unit) { return detail::TextOf(kDeltaUnitNames, unit); }
std::optional<DeltaUnit> DeltaUnitFromString(std::string_view name) {
  // evo's one-letter names first: "m" is both evo's letter for meters and the label of kMeters.
  if (name.size() == 1) {
    for (const auto& [unit, texts] : kDeltaUnitNames) {
      if (texts[0].front() == name.front()) return unit;
    }
    return std::nullopt;
  }
  return detail::ValueOf(kDeltaUnitNames, name);
}
std::string_view DeltaUnitLabel(DeltaUnit unit) { return detail::TextOf(kDeltaUnitNames, unit, 1); }

void RpeOptions::Validate() const {
  const OptionCheck check("RpeOptions");
  check(delta > 0 && std::isfinite(delta), "delta", "must be positive, got {}", delta);
  check(delta_unit != DeltaUnit::kFrames || delta == std::floor(delta), "delta",
        "must be an integer for RpeOptions::delta_unit frames, got {}", delta);
  const bool degrees = delta_unit == DeltaUnit::kDegrees;
  check(!(degrees || delta_unit == DeltaUnit::kRadians) || delta <= (degrees ? 180.0 : std::numbers::pi), "delta",
        "must be within [0, {}] for RpeOptions::delta_unit {}, got {}", degrees ? "180" : "pi", ToString(delta_unit),
        delta);
}

std::vector<IndexPair> RpeIndexPairs(const PairedStates& pairs, const RpeOptions& options) {
  options.Validate();
  const double delta = options.delta;
  const Eigen::Index n = pairs.size();
  std::vector<IndexPair> out;
  switch (options.delta_unit) {
    case DeltaUnit::kFrames: {
      const Eigen::Index step = delta < 9e18 ? static_cast<Eigen::Index>(delta) : n;
      if (options.all_pairs) {
        for (Eigen::Index i = 0; i < n - step; ++i) out.push_back({i, i + step});
      } else {
        std::vector<Eigen::Index> ids;
        for (Eigen::Index i = 0; i < n; i += step) ids.push_back(i);
        out = Neighbours(ids);
      }
      break;
    }
    case DeltaUnit::kMeters:
      out = PairsByPath(pairs, delta, delta * options.relative_delta_tolerance, options.all_pairs);
      break;
    case DeltaUnit::kDegrees:
    case DeltaUnit::kRadians: {
      const bool degrees = options.delta_unit == DeltaUnit::kDegrees;
      RequireOrientation(pairs, "RPE with an angular RpeOptions::delta_unit");
      const double to_rad = degrees ? std::numbers::pi / 180.0 : 1.0;  // numpy.deg2rad
      out = PairsByAngle(pairs, delta * to_rad, delta * options.relative_delta_tolerance * to_rad, options.all_pairs);
      break;
    }
  }
  if (out.empty()) {
    throw ComputeError(fmt::format("RPE: RpeOptions::delta {} {} gives no pair of poses among the {} associated ones; "
                                   "try a smaller RpeOptions::delta{}",
                                   delta, ToString(options.delta_unit), n,
                                   options.all_pairs ? "" : " or RpeOptions::all_pairs"));
  }
  return out;
}

std::vector<double> RpeErrors(const PairedStates& pairs, std::span<const IndexPair> index_pairs, PoseRelation relation) {
  std::vector<double> errors(index_pairs.size());
  if (relation == PoseRelation::kPointDistance) {
    for (size_t k = 0; k < index_pairs.size(); ++k) {
      const auto [i, j] = index_pairs[k];
      const double ref = (pairs.ReferencePosition(i) - pairs.ReferencePosition(j)).norm();
      const double est = (pairs.EstimatePosition(i) - pairs.EstimatePosition(j)).norm();
      errors[k] = std::abs(ref - est);
    }
    return errors;
  }
  RequireOrientation(pairs, fmt::format("RPE {}", ToString(relation)));
  for (size_t k = 0; k < index_pairs.size(); ++k) {
    const auto [i, j] = index_pairs[k];
    const Pose q_rel = Relative(ReferencePose(pairs, i), ReferencePose(pairs, j));
    const Pose p_rel = Relative(EstimatePose(pairs, i), EstimatePose(pairs, j));
    errors[k] = PoseErrorOf(Relative(q_rel, p_rel), relation);
  }
  return errors;
}

DriftResult KittiDrift(const PairedStates& pairs) {
  RequireOrientation(pairs, "KITTI drift");
  constexpr Eigen::Index kStep = 10;  // the devkit's step_size
  const std::vector<double> distance = AccumulatedDistances(pairs, true);
  const Eigen::Index n = pairs.size();
  DriftResult result;
  double t_sum = 0, r_sum = 0;
  for (int length_index = 1; length_index <= 8; ++length_index) {
    DriftResult::Length length;
    length.length_m = 100.0 * length_index;
    double t_length = 0, r_length = 0;
    for (Eigen::Index first = 0; first < n; first += kStep) {
      const double target = distance[static_cast<size_t>(first)] + length.length_m;
      const Eigen::Index last =
          std::upper_bound(distance.begin() + first, distance.end(), target) - distance.begin();
      if (last >= n) continue;
      const Pose delta_ref = Relative(ReferencePose(pairs, first), ReferencePose(pairs, last));
      const Pose delta_est = Relative(EstimatePose(pairs, first), EstimatePose(pairs, last));
      const Pose error = Relative(delta_est, delta_ref);
      const double cosine = std::clamp(0.5 * (error.R(0, 0) + error.R(1, 1) + error.R(2, 2) - 1.0), -1.0, 1.0);
      t_length += error.t.norm() / length.length_m;
      r_length += std::acos(cosine) / length.length_m;
      ++length.segments;
    }
    if (length.segments > 0) {
      length.translation_percent = 100.0 * t_length / static_cast<double>(length.segments);
      length.rotation_deg_per_m = kRadToDeg * r_length / static_cast<double>(length.segments);
    }
    t_sum += t_length;
    r_sum += r_length;
    result.segments += length.segments;
    result.lengths.push_back(length);
  }
  if (result.segments > 0) {
    result.translation_percent = 100.0 * t_sum / static_cast<double>(result.segments);
    result.rotation_deg_per_m = kRadToDeg * r_sum / static_cast<double>(result.segments);
  }
  return result;
}

AseErrors AseErrorsOf(const PairedStates& pairs, bool use_velocity) {
  AseErrors ase;
  ase.has_velocity = use_velocity;
  if (use_velocity && !(pairs.has_reference_velocity() && pairs.has_estimate_velocity())) {
    throw ComputeError(fmt::format(
        "ASE needs velocity and the {} has none{}", pairs.has_estimate_velocity() ? "reference" : "estimate",
        pairs.has_estimate_velocity()
            ? " (use EvaluationOptions::reference_velocity chebyshev or central to derive it from the reference "
              "positions)"
            : " (give a file with velocity columns, e.g. tumv/euroc/vins, or ask for the pose-only ASE with "
              "EvaluationOptions::pose_only)"));
  }
  if (!pairs.has_estimate_orientation() && pairs.has_reference_orientation()) {
    throw ComputeError("ASE: the estimate has no orientation; give the reference as position only (its "
                       "ReadOptions::columns without quaternions) to compare position and velocity alone");
  }
  ase.has_rotation = pairs.has_reference_orientation() && pairs.has_estimate_orientation();
  const Eigen::Index n = pairs.size();
  for (auto* v : {&ase.total, &ase.rotation, &ase.position, &ase.velocity}) v->assign(static_cast<size_t>(n), 0.0);
  for (Eigen::Index k = 0; k < n; ++k) {
    const size_t s = static_cast<size_t>(k);
    // E = Q⁻¹ S(P) = (R_qᵀ R_p, R_qᵀ (p_p − p_q), R_qᵀ (v_p − v_q)); a position-only reference has R_q = I.
    const Eigen::Matrix3d r_q_t =
        ase.has_rotation ? Eigen::Matrix3d(pairs.ReferenceRotation(k).transpose()) : Eigen::Matrix3d::Identity();
    if (ase.has_rotation) {
      ase.rotation[s] = (r_q_t * pairs.EstimateRotation(k) - Eigen::Matrix3d::Identity()).norm();
    }
    ase.position[s] = (r_q_t * (pairs.EstimatePosition(k) - pairs.ReferencePosition(k))).norm();
    if (ase.has_velocity) {
      ase.velocity[s] = (r_q_t * (pairs.EstimateVelocity(k) - pairs.ReferenceVelocity(k))).norm();
    }
    ase.total[s] = std::sqrt(ase.rotation[s] * ase.rotation[s] + ase.position[s] * ase.position[s] +
                             ase.velocity[s] * ase.velocity[s]);
  }
  return ase;
}

}  // namespace cheval::eval

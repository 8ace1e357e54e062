#include "cheval/eval/align.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <Eigen/SVD>
#include <fmt/format.h>

#include "cheval/common/error.h"
#include "cheval/common/options.h"
#include "enum_names.h"

namespace cheval::eval {
namespace {

constexpr Eigen::Index kMinPairs = 3;

void RequirePairs(Eigen::Index n, std::string_view method) {
  if (n < kMinPairs) {
    throw ComputeError(fmt::format("{} alignment needs at least {} associated pairs, got {} (check "
                                   "AssociationOptions::max_diff_ns, AssociationOptions::offset_ns or "
                                   "AlignmentOptions::n_align)",
                                   method, kMinPairs, n));
  }
}

// Means and the cross-covariance C = (1/n) Σ (y - ȳ)(x - x̄)ᵀ of Umeyama, plus σ_x² = (1/n) Σ |x - x̄|².
struct Moments {
  Eigen::Vector3d mean_est, mean_ref;
  Eigen::Matrix3d covariance;
  double est_variance = 0;
};

// The moments of the point pairs point(k) = (estimate, reference), k < n, in two passes (means, then
// the centred sums) so that nothing is copied.
template <typename PointPair>
Moments ComputeMoments(Eigen::Index n, const PointPair& point) {
  Moments m;
  m.mean_est.setZero();
  m.mean_ref.setZero();
  for (Eigen::Index k = 0; k < n; ++k) {
    const auto [x, y] = point(k);
    m.mean_est += x;
    m.mean_ref += y;
  }
  m.mean_est /= static_cast<double>(n);
  m.mean_ref /= static_cast<double>(n);
  m.covariance.setZero();
  double squares = 0;
  for (Eigen::Index k = 0; k < n; ++k) {
    const auto [x, y] = point(k);
    const Eigen::Vector3d dx = x - m.mean_est;
    m.covariance += (y - m.mean_ref) * dx.transpose();
    squares += dx.squaredNorm();
  }
  m.covariance *= 1.0 / static_cast<double>(n);
  m.est_variance = squares / static_cast<double>(n);
  return m;
}

using PointPair = std::pair<Eigen::Vector3d, Eigen::Vector3d>;

Moments MatrixMoments(const Eigen::Ref<const Eigen::Matrix3Xd>& est, const Eigen::Ref<const Eigen::Matrix3Xd>& ref) {
  return ComputeMoments(est.cols(), [&](Eigen::Index k) { return PointPair(est.col(k), ref.col(k)); });
}

Moments PairMoments(const PairedStates& pairs, Eigen::Index n) {
  return ComputeMoments(
      n, [&](Eigen::Index k) { return PointPair(pairs.RawEstimatePosition(k), pairs.ReferencePosition(k)); });
}

// Umeyama's solution from the moments (see the header).
Similarity SolveUmeyama(const Moments& m, Eigen::Index n, bool with_scale) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(m.covariance, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d d = svd.singularValues();
  const double eps = std::numeric_limits<double>::epsilon();
  if ((d.array() > eps).count() < 2) {
    throw ComputeError(fmt::format(
        "Umeyama alignment is degenerate: the {} associated positions lie on a line or at one point (singular values "
        "of their covariance {:.3g}, {:.3g}, {:.3g}); use AlignmentOptions::method none or origin, or more of the trajectory",
        n, d[0], d[1], d[2]));
  }
  const Eigen::Matrix3d& U = svd.matrixU();
  const Eigen::Matrix3d& V = svd.matrixV();
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  if (U.determinant() * V.determinant() < 0.0) S(2, 2) = -1;
  Similarity s;
  s.rotation = U * S * V.transpose();
  s.scale = with_scale ? (d.asDiagonal() * S).trace() / m.est_variance : 1.0;
  s.translation = m.mean_ref - s.scale * (s.rotation * m.mean_est);
  return s;
}

// The 4-DoF solution from the moments (see the header).
Similarity SolvePositionYaw(const Moments& m) {
  const Eigen::Matrix3d& C = m.covariance;
  const double cosine = C(0, 0) + C(1, 1), sine = C(1, 0) - C(0, 1);
  if (!(std::hypot(cosine, sine) > std::numeric_limits<double>::epsilon())) {
    throw ComputeError("position + yaw alignment is degenerate: the associated positions have no horizontal extent");
  }
  const double yaw = std::atan2(sine, cosine);
  Similarity s;
  s.rotation << std::cos(yaw), -std::sin(yaw), 0, std::sin(yaw), std::cos(yaw), 0, 0, 0, 1;
  s.translation = m.mean_ref - s.rotation * m.mean_est;
  return s;
}

// Σ over the first n pairs of the squared ASE of the estimate moved by S, with the channels both
// sides have (the objective of the full alignment).
double StateCost(const PairedStates& pairs, Eigen::Index n, const Similarity& s, bool rotation, bool velocity) {
  double cost = 0;
  for (Eigen::Index k = 0; k < n; ++k) {
    cost += (s.ApplyToPoint(pairs.RawEstimatePosition(k)) - pairs.ReferencePosition(k)).squaredNorm();
    if (rotation) {
      cost += (pairs.ReferenceRotation(k).transpose() * s.ApplyToRotation(pairs.RawEstimateRotation(k)) -
               Eigen::Matrix3d::Identity())
                  .squaredNorm();
    }
    if (velocity) cost += (s.ApplyToVector(pairs.RawEstimateVelocity(k)) - pairs.ReferenceVelocity(k)).squaredNorm();
  }
  return cost;
}

// The SE(3) minimising StateCost in closed form. With orthonormal rotations the cost is
// const - 2 tr(R M), M = Σ (p_i - p̄)(q_i - q̄)ᵀ + v_i u_iᵀ + R_p,i R_q,iᵀ (p, v, R_p estimate; q, u, R_q
// reference), maximised over SO(3) by R = V diag(1, 1, det(V Uᵀ)) Uᵀ with U D Vᵀ = svd(M)
// (Kabsch); then t = q̄ - R p̄ as in Umeyama.
Similarity FullStateAlignment(const PairedStates& pairs, Eigen::Index n, bool rotation, bool velocity) {
  const Moments m = PairMoments(pairs, n);
  Eigen::Matrix3d M = static_cast<double>(n) * m.covariance.transpose();  // Σ (p_i − p̄)(q_i − q̄)ᵀ
  for (Eigen::Index k = 0; k < n; ++k) {
    if (rotation) M += pairs.RawEstimateRotation(k) * pairs.ReferenceRotation(k).transpose();
    if (velocity) M += pairs.RawEstimateVelocity(k) * pairs.ReferenceVelocity(k).transpose();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d d = svd.singularValues();
  if (!(d[1] > 1e-12 * d[0])) {
    throw ComputeError("full alignment is degenerate: the positions, velocities and orientations of the pairs used "
                       "do not fix a rotation (the trajectory barely moves)");
  }
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  if ((svd.matrixV() * svd.matrixU().transpose()).determinant() < 0) S(2, 2) = -1;
  Similarity s;
  s.rotation = svd.matrixV() * S * svd.matrixU().transpose();
  s.translation = m.mean_ref - s.rotation * m.mean_est;
  return s;
}

}  // namespace

namespace {

constexpr detail::NameTable<AlignmentMethod, 7, 2> kAlignmentNames{{
    {AlignmentMethod::kNone, {"none", "(not aligned)"}},
    {AlignmentMethod::kOrigin, {"origin", "(with origin alignment)"}},
    {AlignmentMethod::kSE3, {"se3", "(with SE(3) Umeyama alignment)"}},
    {AlignmentMethod::kSim3, {"sim3", "(with Sim(3) Umeyama alignment)"}},
    {AlignmentMethod::kScale, {"scale", "(scale corrected)"}},
    {AlignmentMethod::kPosYaw, {"posyaw", "(with 4-DoF position + yaw alignment)"}},
    {AlignmentMethod::kFull, {"full", "(with full-state SE_2(3) alignment minimising the ASE)"}},
}};

}  // namespace

std::string_view ToString(AlignmentMethod method) { return detail::TextOf(kAlignmentNames, method); }
std::optional<AlignmentMethod> AlignmentMethodFromString(std::string_view name) {
  return detail::ValueOf(kAlignmentNames, name);
}
std::string_view AlignmentTitle(AlignmentMethod method) { return detail::TextOf(kAlignmentNames, method, 1); }

Similarity UmeyamaAlignment(const Eigen::Ref<const Eigen::Matrix3Xd>& est, const Eigen::Ref<const Eigen::Matrix3Xd>& ref,
                            bool with_scale) {
  RequirePairs(est.cols(), with_scale ? "Sim(3) Umeyama" : "SE(3) Umeyama");
  return SolveUmeyama(MatrixMoments(est, ref), est.cols(), with_scale);
}

Similarity PositionYawAlignment(const Eigen::Ref<const Eigen::Matrix3Xd>& est,
                                const Eigen::Ref<const Eigen::Matrix3Xd>& ref) {
  RequirePairs(est.cols(), "position + yaw");
  return SolvePositionYaw(MatrixMoments(est, ref));
}

void AlignmentOptions::Validate() const {
  const OptionCheck check("AlignmentOptions");
  check(n_align >= 0, "n_align", "must be positive, got {}", n_align);
  check(n_align == 0 || method != AlignmentMethod::kNone, "n_align",
        "needs AlignmentOptions::method (se3, sim3, scale, posyaw or full)");
}

AlignmentResult ComputeAlignment(const PairedStates& pairs, const AlignmentOptions& options) {
  AlignmentResult result;
  result.method = options.method;
  if (options.method == AlignmentMethod::kNone) return result;
  options.Validate();
  const Eigen::Index n = options.n_align > 0 ? std::min(options.n_align, pairs.size()) : pairs.size();
  result.pairs_used = n;
  if (options.method == AlignmentMethod::kOrigin) {
    if (n < 1) throw ComputeError("origin alignment needs at least one associated pair");
    if (!pairs.has_reference_orientation() || !pairs.has_estimate_orientation()) {
      throw ComputeError("origin alignment needs the orientation of both trajectories (one is position only); use "
                         "AlignmentOptions::method se3 or posyaw");
    }
    // T = T_ref,0 · T_est,0⁻¹ (the inverse by transpose).
    const Eigen::Matrix3d r_est = pairs.RawEstimateRotation(0);
    result.transform.rotation = pairs.ReferenceRotation(0) * r_est.transpose();
    result.transform.translation =
        pairs.ReferencePosition(0) - result.transform.rotation * pairs.RawEstimatePosition(0);
    result.pairs_used = 1;
    return result;
  }
  auto umeyama = [&](bool with_scale) {
    RequirePairs(n, with_scale ? "Sim(3) Umeyama" : "SE(3) Umeyama");
    return SolveUmeyama(PairMoments(pairs, n), n, with_scale);
  };
  switch (options.method) {
    case AlignmentMethod::kSE3: result.transform = umeyama(false); break;
    case AlignmentMethod::kSim3: result.transform = umeyama(true); break;
    case AlignmentMethod::kScale: result.transform.scale = umeyama(true).scale; break;
    case AlignmentMethod::kPosYaw:
      RequirePairs(n, "position + yaw");
      result.transform = SolvePositionYaw(PairMoments(pairs, n));
      break;
    case AlignmentMethod::kFull: {
      RequirePairs(n, "full");
      const bool rotation = pairs.has_reference_orientation() && pairs.has_estimate_orientation();
      const bool velocity = pairs.has_reference_velocity() && pairs.has_estimate_velocity();
      const Similarity position_only = umeyama(false);
      const Similarity full = FullStateAlignment(pairs, n, rotation, velocity);
      result.position_only_cost = StateCost(pairs, n, position_only, rotation, velocity);
      result.full_cost = StateCost(pairs, n, full, rotation, velocity);
      // The closed form is the global minimum for orthonormal rotations; keep the guarantee also for
      // input whose rotations are not (KITTI matrices as read).
      result.transform = result.full_cost <= result.position_only_cost ? full : position_only;
      result.full_cost = std::min(result.full_cost, result.position_only_cost);
      break;
    }
    case AlignmentMethod::kNone:
    case AlignmentMethod::kOrigin: break;
  }
  return result;
}

}  // namespace cheval::eval

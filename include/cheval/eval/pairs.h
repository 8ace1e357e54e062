#pragma once
/// \file
/// The associated states of a reference and an estimate, pair by pair, with the estimate's
/// alignment applied on access. Non-owning and lazy: it holds the two trajectory views and the
/// index pairs (16 bytes a pair), and forms rotations, positions and velocities when asked, so that
/// evaluating 10 million poses needs memory proportional to n and no copy of either trajectory.
///
/// Frames: every quantity is in the reference's world frame once the alignment is applied;
/// velocities are world-frame (an estimate that writes body-frame velocity is rotated by its own
/// orientation first, SetEstimateVelocityInBodyFrame).

#include <cstdint>
#include <optional>

#include <Eigen/Core>

#include "cheval/eval/associate.h"
#include "cheval/traj/trajectory.h"

namespace cheval::eval {

/// A similarity S = (c, R, t) acting on estimate states: R' = R·R_i, p' = R·(c·p_i) + t,
/// v' = R·(c·v_i). SE(3) has c = 1, a pure scale R = I and t = 0. (The product is formed as evo's
/// `scale()` then `transform()`: scale the position first, then rotate and translate.)
struct Similarity {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  double scale = 1.0;

  Eigen::Vector3d ApplyToPoint(const Eigen::Vector3d& p) const { return rotation * (scale * p) + translation; }
  Eigen::Vector3d ApplyToVector(const Eigen::Vector3d& v) const { return rotation * (scale * v); }
  Eigen::Matrix3d ApplyToRotation(const Eigen::Matrix3d& r) const { return rotation * r; }
};

/// The associated pairs of two trajectories. Pair k compares reference pose association.ref[k]
/// with estimate pose association.est[k]. The views and the association must outlive this object.
class PairedStates {
 public:
  PairedStates(const traj::TrajectoryView& ref, const traj::TrajectoryView& est, const Association& association);

  /// Number of pairs.
  Eigen::Index size() const { return association_->size(); }
  const traj::TrajectoryView& reference() const { return ref_; }
  const traj::TrajectoryView& estimate() const { return est_; }
  const Association& association() const { return *association_; }

  bool has_reference_orientation() const { return ref_.has_orientation(); }
  bool has_estimate_orientation() const { return est_.has_orientation(); }
  /// Reference velocity: its own columns, or the ones set with SetReferenceVelocities.
  bool has_reference_velocity() const { return ref_velocities_.has_value() || ref_.has_velocity(); }
  bool has_estimate_velocity() const { return est_.has_velocity(); }

  /// Replaces the reference velocity with per-pair values (3 x size(), world frame, m/s), e.g. the
  /// Chebyshev derivative of its positions at the paired reference stamps (C-ASE).
  void SetReferenceVelocities(Eigen::Matrix3Xd velocities);
  /// Declares the estimate's velocity columns body-frame: they are rotated by the estimate's own
  /// (unaligned) orientation into its world frame before the alignment. Needs estimate orientation.
  void SetEstimateVelocityInBodyFrame(bool body_frame);
  bool estimate_velocity_in_body_frame() const { return est_velocity_body_; }

  /// The alignment applied to every estimate state (identity until set).
  void SetAlignment(const Similarity& alignment) { alignment_ = alignment; }
  const Similarity& alignment() const { return alignment_; }

  int64_t ReferenceStamp(Eigen::Index k) const { return ref_.stamps_ns()[RefIndex(k)]; }
  int64_t EstimateStamp(Eigen::Index k) const { return est_.stamps_ns()[EstIndex(k)]; }

  /// Reference rotation R_world_body (evo's quaternion normalisation, or the KITTI matrix as read).
  Eigen::Matrix3d ReferenceRotation(Eigen::Index k) const { return ref_.Rotation(RefIndex(k)); }
  Eigen::Vector3d ReferencePosition(Eigen::Index k) const { return ref_.positions().col(RefIndex(k)); }
  Eigen::Vector3d ReferenceVelocity(Eigen::Index k) const;

  /// Estimate states with the alignment applied.
  Eigen::Matrix3d EstimateRotation(Eigen::Index k) const { return alignment_.ApplyToRotation(RawEstimateRotation(k)); }
  Eigen::Vector3d EstimatePosition(Eigen::Index k) const { return alignment_.ApplyToPoint(RawEstimatePosition(k)); }
  Eigen::Vector3d EstimateVelocity(Eigen::Index k) const { return alignment_.ApplyToVector(RawEstimateVelocity(k)); }

  /// Estimate states as read (world-frame velocity after the body-frame conversion), unaligned.
  Eigen::Matrix3d RawEstimateRotation(Eigen::Index k) const { return est_.Rotation(EstIndex(k)); }
  Eigen::Vector3d RawEstimatePosition(Eigen::Index k) const { return est_.positions().col(EstIndex(k)); }
  Eigen::Vector3d RawEstimateVelocity(Eigen::Index k) const;

 private:
  Eigen::Index RefIndex(Eigen::Index k) const { return association_->ref[static_cast<size_t>(k)]; }
  Eigen::Index EstIndex(Eigen::Index k) const { return association_->est[static_cast<size_t>(k)]; }

  traj::TrajectoryView ref_;
  traj::TrajectoryView est_;
  const Association* association_;
  std::optional<Eigen::Matrix3Xd> ref_velocities_;
  bool est_velocity_body_ = false;
  Similarity alignment_;
};

}  // namespace cheval::eval

#pragma once
/// \file
/// Extrinsics: a constant transform applied to every pose of a trajectory before association, as
/// evo_traj's `--transform_left` / `--transform_right` do (docs/evaluation.md, "Extrinsics"). Left,
/// P' = T·P, changes the world frame; right, P' = P·T, changes the body frame (e.g. an estimator's
/// camera or body frame to the ground truth's IMU frame).
///
/// Files, in the formats evo's `load_transform` reads:
/// - `.json`: an object with numbers `x y z qx qy qz qw` (translation, quaternion) and optionally `scale`;
/// - `.npy`: a 4x4 float64 array (C or Fortran order, little or big endian);
/// - anything else: a 4x4 text matrix, 16 numbers separated by spaces, tabs, commas or line breaks.
/// The rotation must be orthonormal (|RᵀR − I| <= 1e-6 elementwise, det R > 0) after taking out a
/// positive scale (a 4x4 matrix's upper-left block may be s·R), every value finite, the last row of
/// a matrix 0 0 0 1; a quaternion must have a norm within 1e-6 of 1. Every failure is an InputError
/// naming the file, the key or row, and what was expected.

#include <string>
#include <string_view>

#include <Eigen/Core>

#include "cheval/traj/trajectory.h"

namespace cheval::eval {

/// T = [s·R  t; 0 1]: a rigid transform (scale 1) or a similarity.
struct Extrinsic {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  double scale = 1.0;
};

/// Reads and validates an extrinsic file (see the file comment); the format is chosen by extension.
Extrinsic ReadExtrinsic(const std::string& path);

/// Parses `content` as `format` ("json", "npy" or "matrix"); `path` names the file in messages.
Extrinsic ParseExtrinsic(std::string_view content, std::string_view format, const std::string& path);

/// `t` with every pose P replaced by left·P·right (either may be null). Left: positions s·R·p + t,
/// orientations R·R_i, world velocities s·R·v. Right (scale 1 only): positions p_i + R_i·t,
/// orientations R_i·R, body angular velocities Rᵀ·ω; world velocities unchanged, which is exact only
/// without a translation (a lever arm would add ω × R_i·t): a right translation with velocity columns
/// is a UsageError, as are a right scale and a right translation on a position-only trajectory.
/// Orientations come out as quaternions (x, y, z, w).
traj::Trajectory TransformTrajectory(const traj::TrajectoryView& t, const Extrinsic* left, const Extrinsic* right);

}  // namespace cheval::eval

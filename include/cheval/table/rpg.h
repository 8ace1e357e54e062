#pragma once
/// \file
/// rpg_trajectory_evaluation's numbers (uzh-rpg/rpg_trajectory_evaluation, docs/table.md "rpg mode"):
/// its file reading, timestamp association, alignment from `eval_cfg.yaml`, absolute errors and
/// relative errors over sub-trajectories of the ground-truth length. Every convention follows its
/// Python code (file and function named at each declaration); the code here is cheval's own.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace cheval::table {

/// A `stamped_*.txt` file as rpg reads it (`trajectory_loading.py`, np.loadtxt): rows of
/// `time x y z qx qy qz qw` (Hamilton, w last), seconds as doubles (no rounding to nanoseconds: rpg
/// associates on the float stamps). Commas and tabs count as spaces, `#` starts a comment.
struct RpgPoses {
  std::vector<double> t;
  Eigen::Matrix3Xd p;
  Eigen::Matrix4Xd q;  ///< x, y, z, w as read (not normalised)
  Eigen::Index size() const { return static_cast<Eigen::Index>(t.size()); }
};

/// Reads a `stamped_*.txt` file. InputError naming the file and line for a row without 8 numbers
/// or a non-finite value; an empty file gives no rows.
RpgPoses ReadRpgPoses(const std::string& path);

/// `eval_cfg.yaml`: `align_type` (posyaw, sim3, se3, none) and `align_num_frames` (-1: all).
struct RpgEvalConfig {
  std::string align_type = "sim3";
  int align_num_frames = -1;
  /// Optional `start_end_time.yaml` of the folder: ground-truth stamps outside are left out.
  double start_time_s = -1.0 / 0.0, end_time_s = 1.0 / 0.0;
};

/// Reads `eval_cfg.yaml` (and `start_end_time.yaml` when present) of a run folder; rpg's defaults
/// (sim3 over all frames) without one. InputError for an unknown align_type or a non-integer count.
RpgEvalConfig ReadRpgEvalConfig(const std::string& folder);

/// rpg's association (`associate_timestamps.py`, `associate`): every (estimate i, ground truth j)
/// with |t_i − t_j| < max_diff (strict, in double arithmetic), sorted by (|Δt|, i, j), taken greedily
/// one to one; returned as (i, j) pairs sorted by i. O((n + m) log m) instead of rpg's O(n m).
std::vector<std::pair<Eigen::Index, Eigen::Index>> RpgAssociate(const std::vector<double>& est_t,
                                                                const std::vector<double>& gt_t,
                                                                double max_diff = 0.02);

/// The similarity gt ≈ s R est + t of `align_utils.py` (`alignTrajectory`).
struct RpgAlignment {
  double s = 1;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
};

/// Solves rpg's alignment on matched poses (columns in pair order). ComputeError for an unknown
/// type, a frame count outside 1..n (or 1 for sim3), or fewer than one pair.
RpgAlignment RpgAlign(const Eigen::Matrix3Xd& p_es, const Eigen::Matrix3Xd& p_gt, const Eigen::Matrix4Xd& q_es,
                      const Eigen::Matrix4Xd& q_gt, const std::string& type, int num_frames);

/// rpg's `transformations.quaternion_matrix` of (x, y, z, w): normalised, identity when |q|² < 4 eps.
Eigen::Matrix3d RpgQuaternionMatrix(const Eigen::Vector4d& xyzw);

/// Relative errors at one sub-trajectory length (`compute_trajectory_errors.compute_relative_error`).
struct RpgRelativeErrors {
  double distance_m = 0;
  std::vector<double> trans_m, trans_percent, rot_deg;
};

/// One run evaluated as rpg does (`trajectory.py`: load_data, align_trajectory,
/// compute_absolute_error, compute_relative_errors with the default 10..50 % of the ground-truth
/// length).
struct RpgResult {
  Eigen::Index matched = 0;
  RpgAlignment alignment;
  std::vector<double> abs_trans_m, abs_rot_deg;
  double rmse_trans_m = 0, rmse_rot_deg = 0;
  double gt_length_m = 0;
  std::vector<RpgRelativeErrors> relative;
};

/// Evaluates `est` against `gt` with `config`. `percentages` are the sub-trajectory lengths as
/// fractions of the ground-truth length (rpg's default 0.1 .. 0.5). ComputeError when nothing is
/// matched or the alignment is impossible.
RpgResult RpgEvaluate(const RpgPoses& gt, const RpgPoses& est, const RpgEvalConfig& config,
                      const std::vector<double>& percentages = {0.1, 0.2, 0.3, 0.4, 0.5});

/// rpg's `results_writer.compute_statistics` RMSE: sqrt(e·e / n).
double RpgRmse(const std::vector<double>& e);

}  // namespace cheval::table

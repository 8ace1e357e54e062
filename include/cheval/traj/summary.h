#pragma once
/// \file
/// What `cheval info` reports about a trajectory (a superset of `evo_traj --full_check`).

#include <cstdint>
#include <span>
#include <string>

#include "cheval/traj/io.h"
#include "cheval/traj/trajectory.h"

namespace cheval::traj {

/// Statistics of a sequence of non-negative numbers.
struct BasicStats {
  double mean = 0, median = 0, min = 0, max = 0, std = 0;  ///< std is the population one (ddof 0)
  Eigen::Index n = 0;
};

/// A summary of a trajectory's sampling and motion.
struct TrajectorySummary {
  Eigen::Index poses = 0;
  bool has_stamps = true;
  bool has_orientation = false;
  bool has_velocity = false;
  bool has_angular_velocity = false;
  int64_t first_stamp_ns = 0;
  int64_t last_stamp_ns = 0;
  /// last stamp minus first stamp, seconds (as evo; negative if the file runs backwards).
  double duration_s = 0;
  /// Mean rate (poses - 1) / duration, Hz; 0 when undefined.
  double rate_hz = 0;
  /// Positive stamp differences, seconds; `std` is the rate jitter.
  BasicStats dt_s;
  /// Differences larger than 2x the median difference.
  Eigen::Index gaps = 0;
  double largest_gap_s = 0;
  int64_t largest_gap_after_ns = 0;  ///< stamp of the pose before the largest gap
  /// Number of poses whose stamp equals an earlier pose's stamp (anywhere in the file).
  Eigen::Index duplicate_stamps = 0;
  /// Number of poses whose stamp is <= the previous pose's stamp (duplicates in a row included).
  Eigen::Index non_increasing_stamps = 0;
  /// Sum of |p_i - p_{i-1}| in file order, metres.
  double path_length_m = 0;
  /// Speed, m/s: from the velocity columns if present, else |Δp|/Δt over positive Δt (none when the
  /// trajectory has no stamps).
  BasicStats speed_mps;
  bool speed_from_velocity = false;
  /// Quaternions whose norm differs from 1 by more than kQuaternionNormTolerance (normalised on read).
  Eigen::Index non_unit_quaternions = 0;
  double max_quaternion_norm_error = 0;
  /// For stored matrices (KITTI): max ||RᵀR - I||_F.
  double max_orthonormality_error = 0;
};

/// Tolerance on |‖q‖ - 1| above which a quaternion is reported as non-unit: numpy.allclose's
/// default relative tolerance at 1, which evo's trajectory check uses (atol 1e-8 is negligible).
/// Files that print quaternions with 6 decimals stay below it.
inline constexpr double kQuaternionNormTolerance = 1e-5;

/// Computes the summary; O(n log n) (duplicate detection sorts a copy of the stamps).
TrajectorySummary Summarize(const TrajectoryView& trajectory);

/// Statistics of `values` (copied and sorted for the median). Empty input gives zeros.
BasicStats ComputeBasicStats(std::vector<double> values);

/// One summarised file: its path as the caller names it, the format it was read as, its summary.
struct FileSummary {
  std::string path;
  Format format = Format::kAuto;
  TrajectorySummary summary;
};

/// The JSON of `cheval info --json` (docs/formats.md): per file path, format, poses, has_stamps,
/// first_stamp_s and last_stamp_s (exact decimal strings), duration_s, rate_hz, dt_s {mean, median,
/// min, max, std, n}, gaps, largest_gap_s, path_length_m, speed_mps {...}, speed_source ("velocity"
/// or "finite_differences"), has_orientation, has_velocity, has_angular_velocity, duplicate_stamps,
/// non_increasing_stamps, non_unit_quaternions, max_quaternion_norm_error,
/// max_orthonormality_error. One object for one file, an array for several; keys sorted, 2-space
/// indentation and a final newline.
std::string SummaryJson(std::span<const FileSummary> files);

}  // namespace cheval::traj

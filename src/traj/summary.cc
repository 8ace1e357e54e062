#include "cheval/traj/summary.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include <nlohmann/json.hpp>

#include "cheval/common/error.h"
#include "cheval/traj/stamp.h"

namespace cheval::traj {

BasicStats ComputeBasicStats(std::vector<double> values) {
  BasicStats stats;
  stats.n = static_cast<Eigen::Index>(values.size());
  if (values.empty()) return stats;
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  stats.min = values.front();
  stats.max = values.back();
  stats.median = n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
  stats.mean = std::accumulate(values.begin(), values.end(), 0.0) / static_cast<double>(n);
  double squares = 0;
  for (double v : values) squares += (v - stats.mean) * (v - stats.mean);
  stats.std = std::sqrt(squares / static_cast<double>(n));
  return stats;
}

TrajectorySummary Summarize(const TrajectoryView& trajectory) {
  TrajectorySummary s;
  const Eigen::Index n = trajectory.size();
  s.poses = n;
  s.has_stamps = trajectory.has_stamps();
  s.has_orientation = trajectory.has_orientation();
  s.has_velocity = trajectory.has_velocity();
  s.has_angular_velocity = trajectory.has_angular_velocity();
  if (n == 0) return s;
  const auto stamps = trajectory.stamps_ns();
  const auto p = trajectory.positions();
  s.first_stamp_ns = stamps.front();
  s.last_stamp_ns = stamps.back();
  s.duration_s = ToSeconds(s.last_stamp_ns - s.first_stamp_ns);
  if (n > 1 && s.duration_s > 0) s.rate_hz = static_cast<double>(n - 1) / s.duration_s;

  std::vector<double> dts, speeds;
  dts.reserve(n);
  for (Eigen::Index i = 1; i < n; ++i) {
    const int64_t dt = stamps[i] - stamps[i - 1];
    const double step = (p.col(i) - p.col(i - 1)).norm();
    s.path_length_m += step;
    if (dt <= 0) {
      ++s.non_increasing_stamps;
      continue;
    }
    dts.push_back(ToSeconds(dt));
    if (!trajectory.has_velocity() && trajectory.has_stamps()) speeds.push_back(step / ToSeconds(dt));
  }
  if (!std::isfinite(s.path_length_m)) {
    throw ComputeError("the path length is not a finite number: the coordinates are too large to compute with");
  }
  s.dt_s = ComputeBasicStats(dts);
  if (s.dt_s.n > 0) {
    for (Eigen::Index i = 1; i < n; ++i) {
      const double dt = ToSeconds(stamps[i] - stamps[i - 1]);
      if (dt > 2.0 * s.dt_s.median) {
        ++s.gaps;
        if (dt > s.largest_gap_s) s.largest_gap_s = dt, s.largest_gap_after_ns = stamps[i - 1];
      }
    }
  }
  std::vector<int64_t> sorted(stamps.begin(), stamps.end());
  std::sort(sorted.begin(), sorted.end());
  for (size_t i = 1; i < sorted.size(); ++i) s.duplicate_stamps += sorted[i] == sorted[i - 1] ? 1 : 0;

  if (trajectory.has_velocity()) {
    s.speed_from_velocity = true;
    const auto v = trajectory.velocities();
    speeds.reserve(n);
    for (Eigen::Index i = 0; i < n; ++i) speeds.push_back(v.col(i).norm());
  }
  s.speed_mps = ComputeBasicStats(std::move(speeds));

  if (trajectory.channels().orientation == OrientationKind::kQuaternion) {
    const auto q = trajectory.quaternions();
    for (Eigen::Index i = 0; i < n; ++i) {
      const double error = std::abs(q.col(i).norm() - 1.0);
      s.max_quaternion_norm_error = std::max(s.max_quaternion_norm_error, error);
      if (error > kQuaternionNormTolerance) ++s.non_unit_quaternions;
    }
  } else if (trajectory.channels().orientation == OrientationKind::kMatrix) {
    for (Eigen::Index i = 0; i < n; ++i) {
      const Eigen::Matrix3d R = trajectory.Rotation(i);
      s.max_orthonormality_error =
          std::max(s.max_orthonormality_error, (R.transpose() * R - Eigen::Matrix3d::Identity()).norm());
    }
  }
  return s;
}

namespace {

nlohmann::json StatsJson(const BasicStats& s) {
  return {{"mean", s.mean}, {"median", s.median}, {"min", s.min}, {"max", s.max}, {"std", s.std}, {"n", s.n}};
}

nlohmann::json FileJson(const FileSummary& file) {
  const TrajectorySummary& s = file.summary;
  nlohmann::json j;  // keys sorted
  j["path"] = file.path;
  j["format"] = std::string(ToString(file.format));
  j["poses"] = s.poses;
  j["has_stamps"] = s.has_stamps;
  j["first_stamp_s"] = FormatSeconds(s.first_stamp_ns);
  j["last_stamp_s"] = FormatSeconds(s.last_stamp_ns);
  j["duration_s"] = s.duration_s;
  j["rate_hz"] = s.rate_hz;
  j["dt_s"] = StatsJson(s.dt_s);
  j["gaps"] = s.gaps;
  j["largest_gap_s"] = s.largest_gap_s;
  j["path_length_m"] = s.path_length_m;
  j["speed_mps"] = StatsJson(s.speed_mps);
  j["speed_source"] = s.speed_from_velocity ? "velocity" : "finite_differences";
  j["has_orientation"] = s.has_orientation;
  j["has_velocity"] = s.has_velocity;
  j["has_angular_velocity"] = s.has_angular_velocity;
  j["duplicate_stamps"] = s.duplicate_stamps;
  j["non_increasing_stamps"] = s.non_increasing_stamps;
  j["non_unit_quaternions"] = s.non_unit_quaternions;
  j["max_quaternion_norm_error"] = s.max_quaternion_norm_error;
  j["max_orthonormality_error"] = s.max_orthonormality_error;
  return j;
}

}  // namespace

std::string SummaryJson(std::span<const FileSummary> files) {
  nlohmann::json all = nlohmann::json::array();
  for (const FileSummary& file : files) all.push_back(FileJson(file));
  return (all.size() == 1 ? all[0] : all).dump(2) + "\n";
}

}  // namespace cheval::traj

#pragma once
// Internal to src/report: the report's clock and the JSON of plotted series (series over time,
// decimated by min/max buckets; paths in space, by a stride), shared by report.cc and sections.cc.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "cheval/eval/evaluate.h"
#include "cheval/report/distribution.h"
#include "cheval/traj/trajectory.h"

namespace cheval::report::detail {

using Json = nlohmann::ordered_json;
using Columns = std::vector<std::pair<std::string, std::vector<double>>>;

// A plotted value with `digits` significant digits (the page draws pixels; the statistics are
// embedded at full precision). Not finite -> NaN, which the JSON writes as null (a gap).
double Rounded(double value, int digits = 6);

// A series over time: {"t": [...], name: [...], ..., "n": samples}, sorted by time, decimated by
// min/max buckets over all columns together (MinMaxDecimation), values to `digits` significant digits.
Json TimeSeries(const std::vector<double>& t, const Columns& columns, std::size_t max_points, int digits = 6);

// The report's clock: seconds from the reference's first stamp, or the pose index without stamps.
struct Clock {
  bool stamps = true;
  int64_t origin_ns = 0;

  // Times of the poses of a trajectory whose stamps plus `offset_ns` are reference stamps.
  std::vector<double> Poses(const traj::TrajectoryView& trajectory, int64_t offset_ns = 0) const;
  // Times of the pairs of a result: the paired reference stamps.
  std::vector<double> Pairs(const eval::EvaluationResult& result, const traj::TrajectoryView& ref) const;
};

// A trajectory's path for the page, decimated by a stride (StrideDecimation) to at most max_points
// poses: {"t" (7 significant digits), "x", "y", "z",
// "n"}, with `rotation` (R_world_body of pose i) also "roll", "pitch", "yaw" in degrees (Z-Y-X
// Euler angles, evo's plot_rpy), with `errors` (one per pose, NaN for an unpaired pose) also
// "error".
Json PathSeries(const Eigen::Matrix3Xd& positions, const std::vector<double>& t,
                const std::function<Eigen::Matrix3d(Eigen::Index)>& rotation, const std::vector<double>* errors,
                std::size_t max_points);

// A box of a box plot as JSON (distribution.h), values rounded for the page.
Json BoxJson(const BoxStatistics& box);
// A distribution (box, histogram, density) as JSON.
Json DistributionJson(std::span<const double> values);

}  // namespace cheval::report::detail

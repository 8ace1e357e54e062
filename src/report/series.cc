#include "series.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numbers>
#include <numeric>

#include "cheval/report/decimate.h"

namespace cheval::report::detail {
namespace {

// Seconds from the report's time origin, to the microsecond.
double SecondsFrom(int64_t origin_ns, int64_t stamp_ns) {
  return std::round(static_cast<double>(stamp_ns - origin_ns) / 1e3) / 1e6;  // divisions: the nearest double
}

Json RoundedArray(const std::vector<double>& values, int digits = 6) {
  Json array = Json::array();
  for (const double v : values) array.push_back(Rounded(v, digits));
  return array;
}

}  // namespace

double Rounded(double value, int digits) {
  if (!std::isfinite(value)) return std::nan("");
  char text[32];
  const auto written = std::to_chars(text, text + sizeof text, value, std::chars_format::general, digits);
  double rounded = value;
  std::from_chars(text, written.ptr, rounded);
  return rounded;
}

Json TimeSeries(const std::vector<double>& t, const Columns& columns, std::size_t max_points, int digits) {
  std::vector<Eigen::Index> order(t.size());
  std::iota(order.begin(), order.end(), Eigen::Index{0});
  std::stable_sort(order.begin(), order.end(), [&](Eigen::Index a, Eigen::Index b) { return t[a] < t[b]; });
  std::vector<std::vector<double>> sorted;
  for (const auto& column : columns) {
    std::vector<double>& s = sorted.emplace_back(order.size());
    for (size_t i = 0; i < order.size(); ++i) s[i] = column.second[static_cast<size_t>(order[i])];
  }
  const std::vector<std::span<const double>> views(sorted.begin(), sorted.end());
  const std::vector<Eigen::Index> kept = MinMaxDecimation(views, max_points);
  Json series;
  Json& times = series["t"] = Json::array();
  for (Eigen::Index i : kept) times.push_back(t[static_cast<size_t>(order[static_cast<size_t>(i)])]);
  for (size_t c = 0; c < columns.size(); ++c) {
    Json& values = series[columns[c].first] = Json::array();
    for (Eigen::Index i : kept) values.push_back(Rounded(sorted[c][static_cast<size_t>(i)], digits));
  }
  series["n"] = t.size();  // samples before decimation
  return series;
}

std::vector<double> Clock::Poses(const traj::TrajectoryView& trajectory, int64_t offset_ns) const {
  std::vector<double> t(static_cast<size_t>(trajectory.size()));
  for (Eigen::Index i = 0; i < trajectory.size(); ++i) {
    t[static_cast<size_t>(i)] = stamps && trajectory.has_stamps()
                                    ? SecondsFrom(origin_ns, trajectory.stamps_ns()[i] + offset_ns)
                                    : static_cast<double>(i);
  }
  return t;
}

std::vector<double> Clock::Pairs(const eval::EvaluationResult& result, const traj::TrajectoryView& ref) const {
  const traj::TrajectoryView paired = result.continuous_reference ? result.continuous_reference->View() : ref;
  std::vector<double> t(static_cast<size_t>(result.association.size()));
  for (size_t k = 0; k < t.size(); ++k) {
    t[k] = stamps ? SecondsFrom(origin_ns, paired.stamps_ns()[result.association.ref[k]]) : static_cast<double>(k);
  }
  return t;
}

Json PathSeries(const Eigen::Matrix3Xd& positions, const std::vector<double>& t,
                const std::function<Eigen::Matrix3d(Eigen::Index)>& rotation, const std::vector<double>* errors,
                std::size_t max_points) {
  Json path;
  const std::vector<Eigen::Index> kept = StrideDecimation(positions.cols(), max_points);
  Json& times = path["t"] = Json::array();
  for (Eigen::Index i : kept) times.push_back(Rounded(t[static_cast<size_t>(i)], 7));
  const char* names[3] = {"x", "y", "z"};
  for (int axis = 0; axis < 3; ++axis) {
    Json& values = path[names[axis]] = Json::array();
    for (Eigen::Index i : kept) values.push_back(Rounded(positions(axis, i)));
  }
  if (rotation) {
    constexpr double kDeg = 180.0 / std::numbers::pi;
    Json roll = Json::array(), pitch = Json::array(), yaw = Json::array();
    for (Eigen::Index i : kept) {
      const Eigen::Matrix3d r = rotation(i);
      roll.push_back(Rounded(std::atan2(r(2, 1), r(2, 2)) * kDeg, 5));
      pitch.push_back(Rounded(std::asin(std::clamp(-r(2, 0), -1.0, 1.0)) * kDeg, 5));
      yaw.push_back(Rounded(std::atan2(r(1, 0), r(0, 0)) * kDeg, 5));
    }
    path["roll"] = std::move(roll);
    path["pitch"] = std::move(pitch);
    path["yaw"] = std::move(yaw);
  }
  if (errors) {
    Json& values = path["error"] = Json::array();
    for (Eigen::Index i : kept) {
      const double e = (*errors)[static_cast<size_t>(i)];
      if (std::isfinite(e)) {
        values.push_back(Rounded(e, 4));
      } else {
        values.push_back(nullptr);  // an unpaired pose: a gap, not a number
      }
    }
  }
  path["n"] = positions.cols();
  return path;
}

Json BoxJson(const BoxStatistics& box) {
  return Json{{"n", box.n},
              {"min", Rounded(box.min)},
              {"q1", Rounded(box.q1)},
              {"median", Rounded(box.median)},
              {"q3", Rounded(box.q3)},
              {"max", Rounded(box.max)},
              {"whisker_low", Rounded(box.whisker_low)},
              {"whisker_high", Rounded(box.whisker_high)},
              {"mean", Rounded(box.mean)},
              {"rmse", Rounded(box.rmse)}};
}

Json DistributionJson(std::span<const double> values) {
  const Distribution d = DistributionOf(values);
  return Json{{"box", BoxJson(d.box)},
              {"bin_start", Rounded(d.bin_start)},
              {"bin_width", Rounded(d.bin_width)},
              {"counts", d.counts},
              {"density_at", RoundedArray(d.density_at, 5)},
              {"density", RoundedArray(d.density, 4)}};
}

}  // namespace cheval::report::detail

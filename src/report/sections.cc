#include "sections.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "cheval/common/error.h"
#include "cheval/eval/metrics.h"
#include "cheval/eval/pairs.h"

namespace cheval::report::detail {

std::vector<double> RpeDistances(const traj::TrajectoryView& ref) {
  double length = 0;
  const auto& p = ref.positions();
  for (Eigen::Index i = 1; i < p.cols(); ++i) length += (p.col(i) - p.col(i - 1)).norm();
  std::vector<double> distances;
  if (!(length >= 1e-3) || !std::isfinite(length)) return distances;
  for (const int percent : {10, 20, 30, 40, 50}) {
    const double d = length * percent / 100.0;
    if (d >= 10) {
      distances.push_back(std::floor(d));
    } else {
      const double scale = std::pow(10.0, std::floor(std::log10(d)) - 1);
      distances.push_back(std::round(d / scale) * scale);
    }
  }
  distances.erase(std::unique(distances.begin(), distances.end()), distances.end());
  return distances;
}

Json RpeJson(const traj::TrajectoryView& ref, const traj::TrajectoryView& est, const eval::EvaluationResult& ape,
             const std::vector<double>& distances, const Clock& clock, std::size_t max_points, const std::string& name,
             std::vector<std::string>* notes) {
  const traj::TrajectoryView paired = ape.continuous_reference ? ape.continuous_reference->View() : ref;
  eval::PairedStates pairs(paired, est, ape.association);
  pairs.SetAlignment(ape.alignment.transform);
  const bool rotation = paired.has_orientation() && est.has_orientation();
  const eval::PoseRelation translation =
      rotation ? eval::PoseRelation::kTranslation : eval::PoseRelation::kPointDistance;
  const std::vector<double> t = clock.Pairs(ape, ref);
  // Each distance's series gets its share of half the points (at least enough for its buckets): one
  // distance is shown at a time, and 4 digits are plenty for a curve.
  const std::size_t columns = rotation ? 2 : 1;
  const std::size_t points =
      std::max<std::size_t>(max_points / (2 * std::max<std::size_t>(distances.size(), 1)), 2 + 4 * columns);
  Json out;
  out["relation"] = std::string(eval::ToString(translation));
  out["rotation"] = rotation;
  Json& entries = out["distances"] = Json::array();
  for (const double delta : distances) {
    eval::RpeOptions options;
    options.relation = translation;
    options.delta = delta;
    options.delta_unit = eval::DeltaUnit::kMeters;
    options.all_pairs = true;
    std::vector<eval::IndexPair> index_pairs;
    try {
      index_pairs = eval::RpeIndexPairs(pairs, options);
    } catch (const ComputeError& e) {
      notes->push_back(fmt::format("the RPE of {} at {} m is not shown: {}", name, delta, e.what()));
      continue;
    }
    Json entry;
    entry["delta"] = delta;
    entry["pairs"] = index_pairs.size();
    const std::vector<double> trans = eval::RpeErrors(pairs, index_pairs, translation);
    entry["trans"] = BoxJson(BoxOf(trans));
    std::vector<double> times;
    times.reserve(index_pairs.size());
    for (const eval::IndexPair& p : index_pairs) times.push_back(t[static_cast<size_t>(p.i)]);
    Columns series = {{"trans", trans}};
    if (rotation) {
      std::vector<double> rot = eval::RpeErrors(pairs, index_pairs, eval::PoseRelation::kAngleDeg);
      entry["rot"] = BoxJson(BoxOf(rot));
      series.push_back({"rot", std::move(rot)});
    }
    entry["series"] = TimeSeries(times, series, points, 4);
    entries.push_back(std::move(entry));
  }
  return out;
}

std::vector<double> RotationPartDegrees(const std::vector<double>& rotation_part) {
  std::vector<double> degrees;
  degrees.reserve(rotation_part.size());
  for (const double f : rotation_part) {
    degrees.push_back(2 * std::asin(std::min(1.0, f / (2 * std::numbers::sqrt2))) * 180 / std::numbers::pi);
  }
  return degrees;
}

}  // namespace cheval::report::detail

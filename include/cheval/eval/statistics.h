#pragma once
/// \file
/// Statistics of per-pair errors, exactly as evo reports them (docs/evaluation.md, "Statistics"; evo's
/// `PE.get_all_statistics`): rmse = sqrt(mean(e²)), mean, median (mean of the two middle values
/// for an even count, as numpy.median), std (population, ddof 0), min, max, sse = Σ e², n.

#include <span>

#include <Eigen/Core>

namespace cheval::eval {

/// The statistics of a list of errors. All zero for an empty list.
struct ErrorStatistics {
  double rmse = 0, mean = 0, median = 0, std = 0, min = 0, max = 0, sse = 0;
  Eigen::Index n = 0;
};

/// Computes the statistics of `errors` (any order; a sorted copy gives the median). O(n log n).
ErrorStatistics ComputeStatistics(std::span<const double> errors);

}  // namespace cheval::eval

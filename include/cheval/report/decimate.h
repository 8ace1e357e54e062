#pragma once
/// \file
/// Choosing which samples of a long series to plot. A chart is a few thousand pixels wide, so more
/// points than that only make the page large and slow; but a plain stride hides exactly what a user
/// looks for in an error plot, its spikes. Time series are therefore decimated by min/max buckets
/// (every bucket keeps its smallest and largest value of every column, so each extreme survives and
/// the drawn envelope is the true one); paths in space, which have no "value" to preserve, by stride.

#include <cstddef>
#include <span>
#include <vector>

#include <Eigen/Core>

namespace cheval::report {

/// Indices (increasing) of the samples of a series to plot, at most `max_points` of them (when
/// max_points >= 2 + 2·columns.size()). All samples when there are at most max_points. Otherwise the
/// samples are cut into B = (max_points − 2) / (2·c) equal buckets of consecutive samples (c
/// columns), and every bucket keeps the index of the smallest and of the largest value of each
/// column (NaN ignored); the first and last sample are always kept. So the global minimum and
/// maximum of every column are kept. Every column must have the same length. Throws
/// std::invalid_argument when they differ or when max_points < 2 + 2·c.
std::vector<Eigen::Index> MinMaxDecimation(std::span<const std::span<const double>> columns, std::size_t max_points);

/// Indices 0, k, 2k, ... and the last of n samples with k = ceil((n − 1) / (max_points − 1)): at
/// most max_points evenly spaced samples including both ends (all of them when n <= max_points).
/// Throws std::invalid_argument when max_points < 2.
std::vector<Eigen::Index> StrideDecimation(Eigen::Index n, std::size_t max_points);

}  // namespace cheval::report

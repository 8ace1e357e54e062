#include "cheval/report/decimate.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace cheval::report {

std::vector<Eigen::Index> MinMaxDecimation(std::span<const std::span<const double>> columns, std::size_t max_points) {
  const std::size_t c = std::max<std::size_t>(columns.size(), 1);
  if (max_points < 2 + 2 * c)
    throw std::invalid_argument("MinMaxDecimation: max_points must be at least 2 + 2 per column");
  const std::size_t n = columns.empty() ? 0 : columns[0].size();
  for (const auto& column : columns) {
    if (column.size() != n) throw std::invalid_argument("MinMaxDecimation: columns of different lengths");
  }
  std::vector<Eigen::Index> kept;
  if (n <= max_points) {
    kept.resize(n);
    std::iota(kept.begin(), kept.end(), Eigen::Index{0});
    return kept;
  }
  const std::size_t buckets = (max_points - 2) / (2 * c);
  kept.reserve(2 + 2 * c * buckets);
  kept.push_back(0);
  for (std::size_t b = 0; b < buckets; ++b) {
    const std::size_t begin = b * n / buckets, end = (b + 1) * n / buckets;
    for (const auto& column : columns) {
      std::size_t low = end, high = end;
      for (std::size_t i = begin; i < end; ++i) {
        if (std::isnan(column[i])) continue;
        if (low == end || column[i] < column[low]) low = i;
        if (high == end || column[i] > column[high]) high = i;
      }
      if (low != end) kept.push_back(static_cast<Eigen::Index>(low));
      if (high != end) kept.push_back(static_cast<Eigen::Index>(high));
    }
  }
  kept.push_back(static_cast<Eigen::Index>(n - 1));
  std::sort(kept.begin(), kept.end());
  kept.erase(std::unique(kept.begin(), kept.end()), kept.end());
  return kept;
}

std::vector<Eigen::Index> StrideDecimation(Eigen::Index n, std::size_t max_points) {
  if (max_points < 2) throw std::invalid_argument("StrideDecimation: max_points must be at least 2");
  std::vector<Eigen::Index> kept;
  if (n <= 0) return kept;
  // Compared as sizes: a max_points beyond Eigen::Index (a wrapped -1) must not turn negative.
  if (static_cast<std::size_t>(n) <= max_points) {
    kept.resize(static_cast<std::size_t>(n));
    std::iota(kept.begin(), kept.end(), Eigen::Index{0});
    return kept;
  }
  const auto limit = static_cast<Eigen::Index>(max_points);  // < n here
  const Eigen::Index stride = (n - 1 + limit - 2) / (limit - 1);
  for (Eigen::Index i = 0; i < n; i += stride) kept.push_back(i);
  if (kept.back() != n - 1) kept.push_back(n - 1);
  return kept;
}

}  // namespace cheval::report

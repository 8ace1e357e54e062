#include "cheval/report/distribution.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace cheval::report {
namespace {

// numpy's default percentile of sorted values: linear interpolation between order statistics.
double Quantile(const std::vector<double>& sorted, double q) {
  const double position = q * static_cast<double>(sorted.size() - 1);
  const auto below = static_cast<std::size_t>(std::floor(position));
  const std::size_t above = std::min(below + 1, sorted.size() - 1);
  const double fraction = position - static_cast<double>(below);
  return sorted[below] + fraction * (sorted[above] - sorted[below]);
}

std::vector<double> SortedFinite(std::span<const double> values) {
  std::vector<double> sorted;
  sorted.reserve(values.size());
  for (const double v : values) {
    if (std::isfinite(v)) sorted.push_back(v);
  }
  std::sort(sorted.begin(), sorted.end());
  return sorted;
}

BoxStatistics BoxOfSorted(const std::vector<double>& sorted) {
  BoxStatistics box;
  box.n = sorted.size();
  if (sorted.empty()) return box;
  box.min = sorted.front();
  box.max = sorted.back();
  box.q1 = Quantile(sorted, 0.25);
  box.median = Quantile(sorted, 0.5);
  box.q3 = Quantile(sorted, 0.75);
  const double iqr = box.q3 - box.q1;
  const double low = box.q1 - 1.5 * iqr, high = box.q3 + 1.5 * iqr;
  box.whisker_low = *std::lower_bound(sorted.begin(), sorted.end(), low);
  box.whisker_high = *(std::upper_bound(sorted.begin(), sorted.end(), high) - 1);
  double sum = 0, squares = 0;
  for (const double v : sorted) {
    sum += v;
    squares += v * v;
  }
  box.mean = sum / static_cast<double>(sorted.size());
  box.rmse = std::sqrt(squares / static_cast<double>(sorted.size()));
  return box;
}

}  // namespace

BoxStatistics BoxOf(std::span<const double> values) { return BoxOfSorted(SortedFinite(values)); }

Distribution DistributionOf(std::span<const double> values, std::size_t bins, std::size_t density_points) {
  if (bins < 1 || density_points < 2) throw std::invalid_argument("DistributionOf: bins >= 1 and density_points >= 2");
  const std::vector<double> sorted = SortedFinite(values);
  Distribution d;
  d.box = BoxOfSorted(sorted);
  if (sorted.empty()) return d;
  const double n = static_cast<double>(sorted.size());
  const double span = d.box.max - d.box.min;
  // Equal bins; one bin of width 1 around a constant.
  d.bin_width = span > 0 ? span / static_cast<double>(bins) : 1.0;
  d.bin_start = span > 0 ? d.box.min : d.box.min - 0.5;
  const std::size_t count = span > 0 ? bins : 1;
  d.counts.assign(count, 0);
  for (const double v : sorted) {
    const auto b = static_cast<std::size_t>((v - d.bin_start) / d.bin_width);
    ++d.counts[std::min(b, count - 1)];
  }
  // Silverman's rule; a constant gets a small width of its own scale.
  double variance = 0;
  for (const double v : sorted) variance += (v - d.box.mean) * (v - d.box.mean);
  const double sigma = sorted.size() > 1 ? std::sqrt(variance / (n - 1)) : 0.0;
  const double iqr = d.box.q3 - d.box.q1;
  double h = 0.9 * std::min(sigma, iqr > 0 ? iqr / 1.34 : sigma) * std::pow(n, -0.2);
  if (!(h > 0)) h = std::max(std::abs(d.box.median) * 1e-3, 1e-12);
  double low = d.box.min - 3 * h;
  const double high = d.box.max + 3 * h;
  if (d.box.min >= 0) low = std::max(low, 0.0);
  // The values on a fine grid (512 cells), then the kernel sum over the cells.
  constexpr std::size_t kCells = 512;
  const double cell = (high - low) / kCells;
  std::vector<double> weights(kCells, 0.0);
  for (const double v : sorted) {
    const auto c = static_cast<std::size_t>(std::max(0.0, (v - low) / cell));
    weights[std::min(c, kCells - 1)] += 1.0;
  }
  const double norm = 1.0 / (n * h * std::sqrt(2 * std::numbers::pi));
  for (std::size_t k = 0; k < density_points; ++k) {
    const double y = low + (high - low) * static_cast<double>(k) / static_cast<double>(density_points - 1);
    double sum = 0;
    for (std::size_t c = 0; c < kCells; ++c) {
      if (weights[c] == 0) continue;
      const double u = (y - (low + (static_cast<double>(c) + 0.5) * cell)) / h;
      sum += weights[c] * std::exp(-0.5 * u * u);
    }
    d.density_at.push_back(y);
    d.density.push_back(sum * norm);
  }
  return d;
}

}  // namespace cheval::report

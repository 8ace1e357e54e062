#pragma once
/// \file
/// Summaries of a set of errors for the report's distribution charts: the box of a box plot (as
/// matplotlib's `boxplot` draws it, which evo and rpg_trajectory_evaluation use), a histogram and a
/// kernel density estimate for a violin. They are computed from every error, so the page shows the
/// true distribution of a series whose plotted samples are decimated.

#include <cstddef>
#include <span>
#include <vector>

namespace cheval::report {

/// The numbers of one box of a box plot. Quartiles by linear interpolation between order
/// statistics (numpy's default percentile, what matplotlib uses); whiskers at the most extreme
/// values within 1.5 IQR of the box (matplotlib's whis = 1.5). Non-finite values are ignored; all
/// fields are 0 when no value is finite.
struct BoxStatistics {
  std::size_t n = 0;
  double min = 0, q1 = 0, median = 0, q3 = 0, max = 0;
  double whisker_low = 0, whisker_high = 0;
  double mean = 0, rmse = 0;
};

/// The box of `values`.
BoxStatistics BoxOf(std::span<const double> values);

/// A histogram of equal bins over [min, max] of the finite values, and a Gaussian kernel density
/// estimate (Silverman's bandwidth, computed on a fine binning of the values: cost O(n + grid²))
/// sampled at `density_points` points over [min − 3h, max + 3h] clipped to [0, ∞) when every value is
/// non-negative (errors are).
struct Distribution {
  BoxStatistics box;
  double bin_start = 0, bin_width = 0;
  std::vector<std::size_t> counts;
  std::vector<double> density_at, density;
};

/// The distribution of `values` with `bins` bins (>= 1) and `density_points` (>= 2) density samples.
Distribution DistributionOf(std::span<const double> values, std::size_t bins = 40, std::size_t density_points = 64);

}  // namespace cheval::report

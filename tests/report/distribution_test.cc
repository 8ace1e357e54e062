// The distribution summaries of the report (include/cheval/report/distribution.h): numpy's
// percentiles and matplotlib's whiskers on hand-checked values, NaN ignored, every value counted,
// a density that integrates to one.
#include "cheval/report/distribution.h"

#include <cmath>
#include <numeric>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

namespace cheval::report {
namespace {

TEST(BoxOf, QuartilesAndWhiskersAsNumpyAndMatplotlib) {
  // numpy.percentile([1..10], [25, 50, 75]) = 3.25, 5.5, 7.75; with 100 appended: 3.5, 6, 8.5.
  std::vector<double> v = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10};
  BoxStatistics box = BoxOf(v);
  EXPECT_DOUBLE_EQ(box.q1, 3.25);
  EXPECT_DOUBLE_EQ(box.median, 5.5);
  EXPECT_DOUBLE_EQ(box.q3, 7.75);
  EXPECT_DOUBLE_EQ(box.whisker_low, 1);
  EXPECT_DOUBLE_EQ(box.whisker_high, 10);
  EXPECT_DOUBLE_EQ(box.mean, 5.5);
  EXPECT_DOUBLE_EQ(box.rmse, std::sqrt(38.5));
  v.push_back(100);
  v.push_back(std::nan(""));
  box = BoxOf(v);
  EXPECT_EQ(box.n, 11u);
  EXPECT_DOUBLE_EQ(box.q1, 3.5);
  EXPECT_DOUBLE_EQ(box.median, 6);
  EXPECT_DOUBLE_EQ(box.q3, 8.5);
  EXPECT_DOUBLE_EQ(box.whisker_high, 10) << "100 is beyond q3 + 1.5 IQR = 16";
  EXPECT_DOUBLE_EQ(box.max, 100);
  EXPECT_EQ(BoxOf(std::vector<double>{}).n, 0u);
}

TEST(DistributionOf, CountsEveryValueAndTheDensityIntegratesToOne) {
  std::mt19937 random(4);
  std::normal_distribution<double> normal(5.0, 1.0);
  std::vector<double> v(20000);
  for (double& x : v) x = normal(random);
  const Distribution d = DistributionOf(v, 40, 200);
  ASSERT_EQ(d.counts.size(), 40u);
  EXPECT_EQ(std::accumulate(d.counts.begin(), d.counts.end(), size_t{0}), v.size());
  EXPECT_DOUBLE_EQ(d.bin_start, d.box.min);
  EXPECT_NEAR(d.bin_start + 40 * d.bin_width, d.box.max, 1e-9);
  double area = 0, peak_at = 0, peak = 0;
  for (size_t k = 1; k < d.density.size(); ++k) {
    area += 0.5 * (d.density[k] + d.density[k - 1]) * (d.density_at[k] - d.density_at[k - 1]);
    if (d.density[k] > peak) peak = d.density[k], peak_at = d.density_at[k];
  }
  EXPECT_NEAR(area, 1.0, 0.01);
  EXPECT_NEAR(peak_at, 5.0, 0.2);
  EXPECT_NEAR(peak, 1 / std::sqrt(2 * M_PI), 0.03);
  // A constant: one bin, a narrow density around it.
  const Distribution c = DistributionOf(std::vector<double>(10, 2.0));
  ASSERT_EQ(c.counts.size(), 1u);
  EXPECT_EQ(c.counts[0], 10u);
  EXPECT_THROW(DistributionOf(v, 0), std::invalid_argument);
}

}  // namespace
}  // namespace cheval::report

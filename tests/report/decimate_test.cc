// The decimation of plotted series (include/cheval/report/decimate.h): at most the asked number of
// points, every column's extremes kept, all points of a short series, both ends of a path.
#include "cheval/report/decimate.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

namespace cheval::report {
namespace {

std::vector<double> Noisy(size_t n, double phase) {
  std::vector<double> v(n);
  // A smooth curve with deterministic spikes: the spikes are what a stride would lose.
  for (size_t i = 0; i < n; ++i) v[i] = std::sin(1e-3 * static_cast<double>(i) + phase) + (i % 997 == 13 ? 5.0 : 0.0);
  return v;
}

TEST(MinMaxDecimationTest, KeepsEverySampleOfAShortSeries) {
  const std::vector<double> a = Noisy(100, 0);
  const std::vector<std::span<const double>> columns = {a};
  const std::vector<Eigen::Index> kept = MinMaxDecimation(columns, 100);
  ASSERT_EQ(kept.size(), 100u);
  for (size_t i = 0; i < kept.size(); ++i) EXPECT_EQ(kept[i], static_cast<Eigen::Index>(i));
}

TEST(MinMaxDecimationTest, BoundedIncreasingAndKeepsEveryColumnsExtremesPerBucket) {
  const size_t n = 200'003;
  const std::vector<double> a = Noisy(n, 0), b = Noisy(n, 1.0);
  const std::vector<std::span<const double>> columns = {a, b};
  for (const size_t max_points : {6u, 50u, 5000u}) {
    const std::vector<Eigen::Index> kept = MinMaxDecimation(columns, max_points);
    EXPECT_LE(kept.size(), max_points);
    EXPECT_EQ(kept.front(), 0);
    EXPECT_EQ(kept.back(), static_cast<Eigen::Index>(n - 1));
    EXPECT_TRUE(std::is_sorted(kept.begin(), kept.end()));
    EXPECT_TRUE(std::adjacent_find(kept.begin(), kept.end()) == kept.end()) << "no index twice";
    // The global extremes of both columns survive (the spikes of 5 among them).
    for (const auto& column : {a, b}) {
      double low = INFINITY, high = -INFINITY;
      for (Eigen::Index i : kept) low = std::min(low, column[i]), high = std::max(high, column[i]);
      EXPECT_EQ(low, *std::min_element(column.begin(), column.end())) << max_points;
      EXPECT_EQ(high, *std::max_element(column.begin(), column.end())) << max_points;
    }
  }
  // With 5000 points (1249 buckets of ~160 samples) every spike, one per 997 samples, is kept.
  const std::vector<Eigen::Index> kept = MinMaxDecimation(columns, 5000);
  for (size_t i = 13; i < n; i += 997) {
    EXPECT_TRUE(std::binary_search(kept.begin(), kept.end(), static_cast<Eigen::Index>(i))) << "spike at " << i;
  }
}

TEST(MinMaxDecimationTest, IgnoresNanAndRejectsBadArguments) {
  std::vector<double> a(1000, std::nan(""));
  a[500] = 1.0;
  const std::vector<std::span<const double>> one = {a};
  const std::vector<Eigen::Index> kept = MinMaxDecimation(one, 10);
  EXPECT_TRUE(std::binary_search(kept.begin(), kept.end(), Eigen::Index{500}));
  EXPECT_LE(kept.size(), 10u);
  EXPECT_THROW(MinMaxDecimation(one, 3), std::invalid_argument);
  const std::vector<double> shorter(10, 0.0);
  const std::vector<std::span<const double>> uneven = {a, shorter};
  EXPECT_THROW(MinMaxDecimation(uneven, 100), std::invalid_argument);
}

TEST(StrideDecimationTest, EvenlySpacedWithBothEnds) {
  EXPECT_TRUE(StrideDecimation(0, 10).empty());
  EXPECT_EQ(StrideDecimation(5, 10), (std::vector<Eigen::Index>{0, 1, 2, 3, 4}));
  EXPECT_EQ(StrideDecimation(10, 4), (std::vector<Eigen::Index>{0, 3, 6, 9}));
  EXPECT_EQ(StrideDecimation(11, 4), (std::vector<Eigen::Index>{0, 4, 8, 10}));
  for (const Eigen::Index n : {2, 4999, 5000, 5001, 20'001, 1'000'000}) {
    const std::vector<Eigen::Index> kept = StrideDecimation(n, 5000);
    EXPECT_LE(kept.size(), 5000u) << n;
    EXPECT_EQ(kept.front(), 0);
    EXPECT_EQ(kept.back(), n - 1);
    if (n > 5000) {
      EXPECT_GE(kept.size(), 2500u) << "a stride of ceil((n-1)/(max-1)) keeps at least half";
    }
  }
  EXPECT_THROW(StrideDecimation(10, 1), std::invalid_argument);
}

// Issue 13: `cheval report --max-points -1` (SIZE_MAX) turned negative as an Eigen::Index, and the
// stride loop grew without end (16.8 GB, then std::bad_alloc). Any max_points at or above n keeps all.
TEST(StrideDecimationTest, AMaxPointsBeyondTheIndexRangeKeepsEverySample) {
  const std::vector<Eigen::Index> all = {0, 1, 2, 3, 4};
  for (const std::size_t max_points : {std::numeric_limits<std::size_t>::max(), std::size_t{1} << 63,
                                       (std::size_t{1} << 63) + 5}) {
    EXPECT_EQ(StrideDecimation(5, max_points), all) << max_points;
  }
  const std::vector<double> a = Noisy(5, 0);
  const std::vector<std::span<const double>> columns = {a};
  EXPECT_EQ(MinMaxDecimation(columns, std::numeric_limits<std::size_t>::max()), all);
}

}  // namespace
}  // namespace cheval::report

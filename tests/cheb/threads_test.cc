// Threads in the curve fit (CurveOptions::threads): the work queue and selection it is built on,
// and a curve that is the same for any number of threads.
#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <numeric>
#include <utility>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "cheval/cheb/curve.h"
#include "noise_profile.h"
#include "work_queue.h"

namespace cheval::cheb {
namespace {

// Ranges [a, b) halved down to single elements: every pushed item is processed, on any number of
// threads, and the leaves cover the range once.
TEST(DrainWork, ProcessesEveryItemAndEveryItemPushed) {
  struct Range {
    int a, b;
  };
  for (const int threads : {1, 2, 5}) {
    std::mutex mutex;
    std::vector<int> leaves;
    std::atomic<int> processed{0};
    internal::DrainWork(
        std::vector<Range>{{1000, 1037}, {0, 1000}}, threads,
        [&](Range r, auto&& push) {
          ++processed;
          if (r.b - r.a > 1) {
            const int middle = (r.a + r.b) / 2;
            push(Range{middle, r.b});
            push(Range{r.a, middle});
            return;
          }
          const std::lock_guard<std::mutex> lock(mutex);
          leaves.push_back(r.a);
        },
        [](const Range& r) { return std::pair(r.a, -r.b); });
    std::sort(leaves.begin(), leaves.end());
    std::vector<int> expected(1037);
    std::iota(expected.begin(), expected.end(), 0);
    EXPECT_EQ(leaves, expected) << threads << " threads";
    EXPECT_EQ(processed.load(), 2 * 1037 - 2) << threads << " threads";  // a binary tree per root
  }
}

// On one thread the last pushed item is taken first: depth first, left before right as pushed.
TEST(DrainWork, OneThreadTakesTheLastPushedFirst) {
  std::vector<int> order;
  internal::DrainWork(
      std::vector<int>{1}, 1,
      [&](int item, auto&& push) {
        order.push_back(item);
        if (item < 4) {
          push(2 * item + 1);
          push(2 * item);
        }
      },
      [](int item) { return item; });
  EXPECT_EQ(order, (std::vector<int>{1, 2, 4, 5, 3, 6, 7}));
}

// Items that throw: the exception rethrown is the one a single thread meets first (items taken
// last first: 150 before 30), on any number of threads, however they are scheduled; items after
// it are not taken. Items take a millisecond, far longer than recording an exception.
TEST(DrainWork, TheExceptionOneThreadMeetsFirstIsRethrown) {
  for (const int threads : {1, 2, 3, 5}) {
    for (int repeat = 0; repeat < 5; ++repeat) {
      std::atomic<int> processed{0};
      std::vector<int> items(200);
      std::iota(items.begin(), items.end(), 0);
      try {
        internal::DrainWork(
            items, threads,
            [&](int item, auto&&) {
              ++processed;
              std::this_thread::sleep_for(std::chrono::milliseconds(item == 30 ? 0 : 1));
              if (item == 150 || item == 30) throw std::runtime_error("item " + std::to_string(item));
            },
            [](int item) { return -item; });
        ADD_FAILURE() << "no exception";
      } catch (const std::runtime_error& e) {
        EXPECT_STREQ(e.what(), "item 150") << threads << " threads";
      }
      EXPECT_LT(processed.load(), 100) << threads << " threads";
    }
  }
}

// An index before the first one to throw still runs and, when it throws too, wins: index 2
// throws after index 3 did.
TEST(ParallelFor, RethrowsTheSmallestIndexThatThrew) {
  for (const int threads : {1, 2, 4}) {
    try {
      internal::ParallelFor(8, threads, [](int i) {
        if (i == 2) std::this_thread::sleep_for(std::chrono::milliseconds(20));
        if (i >= 2) throw std::runtime_error("index " + std::to_string(i));
      });
      ADD_FAILURE() << "no exception";
    } catch (const std::runtime_error& e) {
      EXPECT_STREQ(e.what(), "index 2") << threads << " threads";
    }
  }
}

TEST(ParallelFor, CallsEachIndexOnce) {
  for (const int threads : {1, 2, 8}) {
    std::vector<std::atomic<int>> calls(37);
    internal::ParallelFor(37, threads, [&](int i) { ++calls[static_cast<size_t>(i)]; });
    for (const auto& c : calls) EXPECT_EQ(c.load(), 1) << threads << " threads";
  }
  internal::ParallelFor(0, 2, [](int) { FAIL(); });
}

// The narrowing by bits finds what std::nth_element finds, above and below the size where it
// starts, with ties, zeros, infinities and subnormals.
TEST(SelectNonNegative, FindsWhatNthElementFinds) {
  std::mt19937_64 rng(3);
  std::lognormal_distribution<double> spread(0.0, 3.0);
  std::uniform_int_distribution<int> kind(0, 19);
  for (const size_t size : {size_t{1}, size_t{2}, size_t{1000}, size_t{16384}, size_t{16385}, size_t{100003}}) {
    std::vector<double> values(size);
    for (double& v : values) {
      switch (kind(rng)) {
        case 0: v = 0.0; break;
        case 1: v = std::numeric_limits<double>::infinity(); break;
        case 2: v = std::numeric_limits<double>::denorm_min() * 7; break;
        case 3: v = 1.25; break;  // ties
        default: v = spread(rng);
      }
    }
    for (const size_t k : {size_t{0}, size / 3, size / 2, size - 1}) {
      std::vector<double> expected = values, selected = values;
      std::nth_element(expected.begin(), expected.begin() + static_cast<std::ptrdiff_t>(k), expected.end());
      EXPECT_EQ(internal::SelectNonNegative(&selected, k), expected[k]) << "size " << size << ", k " << k;
    }
  }
  // Many equal values: every bucket the narrowing keeps holds them all.
  std::vector<double> equal(50000, 0.5);
  EXPECT_EQ(internal::SelectNonNegative(&equal, 25000), 0.5);
  std::vector<double> few{1.0, 2.0};
  EXPECT_THROW(internal::SelectNonNegative(&few, 2), std::invalid_argument);
}

// The noise profile asks how many runs exceed a threshold over stretches from block to block; the
// counts kept at blocks' starts (and at the end) are those of a count over every run, also across
// a break, with NaN runs (no usable run) left out and a last block that is not full.
TEST(DifferenceMagnitudes, CountsPerBlockAreThoseOfEveryRun) {
  std::mt19937_64 rng(21);
  std::normal_distribution<double> normal;
  for (const Eigen::Index m : {Eigen::Index{5}, Eigen::Index{64}, Eigen::Index{1000}, Eigen::Index{1013}}) {
    Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(m, 0.0, 0.01 * static_cast<double>(m - 1));
    Eigen::MatrixXd z(m, 2);
    for (Eigen::Index i = 0; i < m; ++i) z.row(i) << std::sin(t[i]) + 1e-3 * normal(rng), 2e-3 * normal(rng);
    const internal::DifferenceMagnitudes magnitudes(t, z, {m / 3});
    const Eigen::Vector2d threshold(1e-3, 2e-3);
    for (const Eigen::Index stride : {Eigen::Index{1}, Eigen::Index{7}, Eigen::Index{32}}) {
      const Eigen::MatrixXi counts = magnitudes.CountsAbove(threshold, stride);
      const Eigen::Index rows = (m + stride - 1) / stride + 1;
      ASSERT_EQ(counts.rows(), rows);
      ASSERT_EQ(counts.cols(), 4);
      for (Eigen::Index row = 0; row < rows; ++row) {
        const Eigen::Index before = std::min(m, row * stride);  // the runs starting before this sample
        for (Eigen::Index c = 0; c < 2; ++c) {
          int usable = 0, above = 0;
          for (Eigen::Index i = 0; i < before; ++i) {
            const double v = magnitudes.fourth()(i, c);
            if (std::isnan(v)) continue;
            ++usable;
            if (internal::kMadScale * v > threshold[c]) ++above;
          }
          EXPECT_EQ(counts(row, 2 * c), usable) << m << " " << stride << " " << row;
          EXPECT_EQ(counts(row, 2 * c + 1), above) << m << " " << stride << " " << row;
        }
      }
      if (m < 64) continue;  // 5 samples split at the second have no usable run
      EXPECT_GT(counts(rows - 1, 1), 0);  // the thresholds are met by some runs and not by others
      EXPECT_LT(counts(rows - 1, 1), counts(rows - 1, 0));
    }
  }
}

// A recording with two gaps, a glitch, a step of the values and a burst of noise: four segments,
// jumps found and a raised noise profile, 11,000 samples (the fit, the end caps, the noise
// estimate and the evaluation of all of them all split their work). Fitted on 1, 2 and 5 threads,
// the curves are the same to the last bit, and so are their values and rates at the samples.
TEST(Threads, TheCurveIsTheSameForAnyNumber) {
  constexpr double kRate = 300.0, kNoise = 5e-5;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::vector<int64_t> stamps;
  std::vector<Eigen::Vector3d> rows;
  for (int i = 0; i < 40 * 300; ++i) {
    const double t = i / kRate;
    if ((t > 10.0 && t < 10.5) || (t > 25.0 && t < 25.3)) continue;  // gaps
    Eigen::Vector3d p(std::sin(0.4 * t) + 1e-3 * std::sin(2 * M_PI * 7 * t), 0.5 * std::cos(0.3 * t),
                      0.2 * std::sin(0.7 * t + 1.0));
    const double noise = t > 30.0 && t < 30.2 ? 6 * kNoise : kNoise;  // a burst
    for (int c = 0; c < 3; ++c) p[c] += noise * gauss(rng);
    if (i == 1500) p[0] += 5e-3;  // a glitch
    if (t > 17.0) p[1] += 3e-3;   // a step
    stamps.push_back(std::llround(t * 1e9));
    rows.push_back(p);
  }
  Eigen::MatrixXd values(static_cast<Eigen::Index>(rows.size()), 3);
  for (size_t i = 0; i < rows.size(); ++i) values.row(static_cast<Eigen::Index>(i)) = rows[i].transpose();

  auto fit = [&](int threads) {
    CurveOptions options;
    options.threads = threads;
    return FitCurve(stamps, values, options);
  };
  const Curve one = fit(1);
  ASSERT_GE(one.segments().size(), 3u);
  ASSERT_FALSE(one.outlier_times().empty());
  ASSERT_GT(one.noisier_samples(), 0);
  Eigen::MatrixXd one_values, one_rates;
  one.EvaluateMany(stamps, 1, &one_values, &one_rates);
  for (const int threads : {2, 5}) {
    const Curve many = fit(threads);
    ASSERT_EQ(many.segments().size(), one.segments().size());
    for (size_t k = 0; k < one.segments().size(); ++k) {
      const std::vector<CurveWindow>& a = one.segments()[k].windows;
      const std::vector<CurveWindow>& b = many.segments()[k].windows;
      ASSERT_EQ(a.size(), b.size()) << "segment " << k;
      for (size_t w = 0; w < a.size(); ++w) {
        EXPECT_EQ(a[w].core_begin, b[w].core_begin);
        EXPECT_EQ(a[w].core_end, b[w].core_end);
        EXPECT_EQ(a[w].degrees, b[w].degrees);
        ASSERT_EQ(a[w].series.coefficients.rows(), b[w].series.coefficients.rows());
        ASSERT_EQ(a[w].series.coefficients.cols(), b[w].series.coefficients.cols());
        EXPECT_EQ(a[w].series.coefficients, b[w].series.coefficients);
        EXPECT_EQ(a[w].missed_motion, b[w].missed_motion);
      }
    }
    EXPECT_EQ(many.outlier_times(), one.outlier_times());
    EXPECT_EQ(many.jump_times(), one.jump_times());
    EXPECT_EQ(many.step_times(), one.step_times());
    EXPECT_EQ(many.noisier_samples(), one.noisier_samples());
    EXPECT_EQ(many.noise_sigma(), one.noise_sigma());
    EXPECT_EQ(many.residual_rms(), one.residual_rms());
    Eigen::MatrixXd many_values, many_rates;
    many.EvaluateMany(stamps, 1, &many_values, &many_rates);
    ASSERT_EQ(many_values.rows(), one_values.rows());
    EXPECT_EQ(many_values, one_values) << threads << " threads";
    EXPECT_EQ(many_rates, one_rates) << threads << " threads";
  }
}

// Progress comes from the fitting threads one call at a time: a call that finds another under
// way fails. The samples done never fall, stay below the total until the last window is fitted
// (the cores tile the samples), and the stage ends with all of them.
TEST(Threads, ProgressCallsNeverOverlapNorFall) {
  std::vector<int64_t> stamps;
  Eigen::MatrixXd values(20000, 1);
  for (Eigen::Index i = 0; i < values.rows(); ++i) {
    stamps.push_back(i * 5'000'000);
    values(i, 0) = std::sin(0.01 * static_cast<double>(i)) + 1e-4 * std::cos(1.3 * static_cast<double>(i));
  }
  std::vector<int64_t> done;
  std::atomic<bool> inside{false};
  CurveOptions options;
  options.threads = 4;
  options.progress = [&](std::string_view stage, int64_t d, int64_t total) {
    EXPECT_FALSE(inside.exchange(true)) << "two calls at once";
    EXPECT_EQ(stage, "fitting windows");
    EXPECT_EQ(total, 20000);
    done.push_back(d);
    std::this_thread::sleep_for(std::chrono::microseconds(200));  // widen the window for an overlap
    inside = false;
  };
  FitCurve(stamps, values, options);
  ASSERT_GE(done.size(), 4u);
  EXPECT_TRUE(std::is_sorted(done.begin(), done.end()));
  EXPECT_EQ(done.back(), 20000);
  EXPECT_LT(done[done.size() - 3], 20000);  // before the last window and the stage's end
}

// Tones at a quarter of the rate under 0.5 mm of noise in four segments (three gaps): the local
// regression scores each segment's stretches, the local interpolant's noisy samples among them,
// with the segments split across threads. On 1 and 2 threads the rates are the same to the last bit.
TEST(Threads, TheLocalRegressionIsTheSameForAnyNumber) {
  constexpr double kRate = 100.0, kNoise = 5e-4;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<std::array<double, 3>> tones;  // axis, Hz, phase
  for (int c = 0; c < 3; ++c) {
    for (int k = 0; k < 3; ++k) tones.push_back({double(c), kRate / 4.0 * (0.6 + 0.4 * unit(rng)), 2 * M_PI * unit(rng)});
  }
  std::vector<int64_t> stamps;
  std::vector<Eigen::Vector3d> rows;
  for (int i = 0; i < 40 * 100; ++i) {
    const double t = i / kRate;
    if ((t > 10.0 && t < 10.5) || (t > 20.0 && t < 20.5) || (t > 30.0 && t < 30.5)) continue;  // gaps
    Eigen::Vector3d p(0.3 * std::sin(0.4 * t), 0.3 * std::cos(0.3 * t), 0.2 * std::sin(0.7 * t));
    for (const auto& [axis, hz, phase] : tones) p[static_cast<int>(axis)] += 0.15 / (2 * M_PI * hz) * std::sin(2 * M_PI * hz * t + phase);
    for (int c = 0; c < 3; ++c) p[c] += kNoise * gauss(rng);
    stamps.push_back(std::llround(t * 1e9));
    rows.push_back(p);
  }
  Eigen::MatrixXd values(static_cast<Eigen::Index>(rows.size()), 3);
  for (size_t i = 0; i < rows.size(); ++i) values.row(static_cast<Eigen::Index>(i)) = rows[i].transpose();
  auto rates = [&](int threads, Eigen::Index* regression) {
    CurveOptions options;
    options.threads = threads;
    const Curve curve = FitCurve(stamps, values, options);
    EXPECT_EQ(curve.segments().size(), 4u);
    *regression = curve.regression_samples();
    Eigen::MatrixXd v, r;
    curve.EvaluateMany(stamps, 1, &v, &r);
    return r;
  };
  Eigen::Index one_regression = 0, two_regression = 0;
  const Eigen::MatrixXd one = rates(1, &one_regression), two = rates(2, &two_regression);
  EXPECT_GT(one_regression, 1000);
  EXPECT_EQ(one_regression, two_regression);
  ASSERT_EQ(one.rows(), two.rows());
  EXPECT_EQ((one - two).cwiseAbs().maxCoeff(), 0.0);
}

}  // namespace
}  // namespace cheval::cheb

// Chebyshev fitting speed. Target (velocity issue): m = 100,000 samples of a 3-vector at degree 400
// in <= 50 ms (docs/velocity.md, "Speed").
//   build/bench/cheb_bench
#include <cmath>
#include <random>

#include <benchmark/benchmark.h>

#include "cheval/cheb/curve.h"
#include "cheval/cheb/degree.h"
#include "cheval/cheb/fit.h"

namespace {

using namespace cheval::cheb;

void BM_FitLeastSquares(benchmark::State& state) {
  const auto m = static_cast<Eigen::Index>(state.range(0));
  const int degree = static_cast<int>(state.range(1));
  std::mt19937_64 rng(1);
  std::normal_distribution<double> noise(0.0, 1e-3);
  Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(m, 0.0, static_cast<double>(m) / 100.0);
  Eigen::MatrixXd z(m, 3);
  for (Eigen::Index i = 0; i < m; ++i) {
    z.row(i) << std::sin(0.3 * t[i]) + noise(rng), std::cos(0.2 * t[i]) + noise(rng), 0.01 * t[i] + noise(rng);
  }
  const Interval interval{t[0], t[m - 1]};
  for (auto _ : state) {
    benchmark::DoNotOptimize(FitLeastSquares(t, z, degree, interval));
  }
  state.SetItemsProcessed(state.iterations() * m);
}
BENCHMARK(BM_FitLeastSquares)->Args({100'000, 400})->Args({20'000, 200})->Unit(benchmark::kMillisecond);

// Evaluation of a series of degree N with 3 columns at m points (vectorised Clenshaw): what the
// residual tests, the end caps and Curve::EvaluateMany spend; items are point-degrees.
void BM_EvaluateSeries(benchmark::State& state) {
  const auto m = static_cast<Eigen::Index>(state.range(0));
  const auto degree = static_cast<Eigen::Index>(state.range(1));
  std::mt19937_64 rng(3);
  std::normal_distribution<double> gauss(0.0, 1.0);
  Eigen::MatrixXd coefficients(degree + 1, 3);
  for (Eigen::Index k = 0; k <= degree; ++k) {
    for (int c = 0; c < 3; ++c) coefficients(k, c) = gauss(rng) / static_cast<double>(1 + k * k);
  }
  const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(m, -1.0, 1.0);
  for (auto _ : state) {
    benchmark::DoNotOptimize(EvaluateSeries(coefficients, x));
  }
  state.SetItemsProcessed(state.iterations() * m * degree * 3);
}
BENCHMARK(BM_EvaluateSeries)->Args({100'000, 140})->Args({1'000, 20})->Unit(benchmark::kMillisecond);

// The whole adaptive curve fit (windows, cross-validation, end refinement) of m samples at 200 Hz
// of a 3-D motion with 0.5 mm noise: what `cheval velocity` spends between reading and writing,
// apart from the evaluation.
void BM_FitCurve(benchmark::State& state) {
  const auto m = static_cast<Eigen::Index>(state.range(0));
  std::mt19937_64 rng(2);
  std::normal_distribution<double> noise(0.0, 5e-4);
  std::vector<int64_t> stamps(static_cast<size_t>(m));
  Eigen::MatrixXd z(m, 3);
  for (Eigen::Index i = 0; i < m; ++i) {
    const double t = static_cast<double>(i) * 0.005;
    stamps[static_cast<size_t>(i)] = static_cast<int64_t>(i) * 5'000'000;
    z.row(i) << 2.0 * std::sin(0.31 * t) + 0.3 * std::sin(1.7 * t) + noise(rng),
        1.5 * std::cos(0.23 * t) + 0.2 * std::sin(2.3 * t + 1.0) + noise(rng), 1.0 + 0.4 * std::sin(0.9 * t) + noise(rng);
  }
  for (auto _ : state) {
    benchmark::DoNotOptimize(FitCurve(stamps, z));
  }
  state.SetItemsProcessed(state.iterations() * m);
}
BENCHMARK(BM_FitCurve)->Arg(100'000)->Unit(benchmark::kMillisecond);

// The noise estimate on the stamps (4th, then 6th and 8th divided differences) of m samples at
// 200 Hz with 0.5 mm of noise, on even stamps (one set of weights) or stamps jittered by 1 % of
// the step (second argument 1: weights per run).
void BM_EstimateNoiseSigma(benchmark::State& state) {
  const auto m = static_cast<Eigen::Index>(state.range(0));
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 5e-4);
  const double spread = state.range(1) != 0 ? 5e-5 : 0.0;
  std::uniform_real_distribution<double> jitter(-spread, spread);
  Eigen::VectorXd t(m);
  Eigen::MatrixXd z(m, 3);
  for (Eigen::Index i = 0; i < m; ++i) {
    t[i] = static_cast<double>(i) * 0.005 + jitter(rng);
    z.row(i) << std::sin(0.31 * t[i]) + noise(rng), std::cos(0.23 * t[i]) + noise(rng), 0.1 * t[i] + noise(rng);
  }
  for (auto _ : state) {
    benchmark::DoNotOptimize(EstimateNoiseSigma(t, z));
  }
  state.SetItemsProcessed(state.iterations() * m);
}
BENCHMARK(BM_EstimateNoiseSigma)->Args({100'000, 0})->Args({100'000, 1})->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();

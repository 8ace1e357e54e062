#include "local_regression.h"

#include "local_rates.h"
#include "noise_profile.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include <Eigen/Cholesky>

#include "cheval/cheb/fit.h"

namespace cheval::cheb::internal {
namespace {

// Half-widths (samples on either side) of the candidate regressions: 7 to 53 samples.
constexpr std::array<int, 12> kHalves{3, 4, 5, 6, 7, 9, 11, 13, 16, 19, 22, 26};
constexpr int kMaxDegree = 7;
// A regression needs this many samples more than its coefficients.
constexpr int kSpareSamples = 3;
// A pilot of the rates and the fit its bias is judged against: half-widths (in kHalves) and
// degrees. The first, degree 7 over 15 samples, has little noise (0.18·σ²/h² at even spacing) and
// little bias up to a tenth of the rate (3 % at an eighth), but misses motion at a quarter of the
// rate whole; the second is the 9-point stencil's rate (degree 7 through 9 samples: 3 % of a
// tone's rate lost at a quarter of the rate, noise 1.36·σ²/h²), judged against the 7-point one's
// (6.6 %). The second is taken only where the first's bias vetoes a candidate (StretchScores::Choose).
struct Pilot {
  int half, degree, reference_half, reference_degree;
};
constexpr std::array<Pilot, 2> kPilots{{{7, 7, 5, 7}, {4, 7, 3, 5}}};
// Spare samples of a pilot or reference: the stencils above have one.
constexpr int kPilotSpareSamples = 1;
// A candidate replaces the windows only when its estimated gain is this many standard errors.
constexpr double kSignificance = 2.0;
// The pilot's bias estimate is discounted by its standard errors only where the noise share it
// subtracts is at least this fraction of the differences it is subtracted from.
constexpr double kBiasNoiseShare = 0.5;
// Samples per block of the gains' standard error: the widest candidate's.
constexpr Eigen::Index kBlock = 53;
// Shorter stretches are left to the windows: fewer than 4 blocks say little about the scatter.
constexpr Eigen::Index kMinStretch = 4 * kBlock;
// The most blocks of a stretch scored (LocalRegressionRuns).
constexpr Eigen::Index kMaxScoredBlocks = 64;
// Windows whose rates differ from the pilot's by less than this fraction of the noise variance
// that σ implies are left alone (σ overstates the noise there).
constexpr double kSmoothFraction = 0.25;

using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxDegree + 1, kMaxDegree + 1>;
using SmallVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxDegree + 1, 1>;

// One regression at one sample: value and rate per coordinate, and the rate's weights on the
// samples [lo, hi] as a polynomial g in x = (t − t_i)/scale: w_j = g(x_j)/scale.
struct Regression {
  Eigen::Index lo = 0, hi = -1;
  double scale = 1.0;
  SmallVector weights;
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 4, 1> value, rate;
  bool ok = false;

  double Weight(double t, double ti) const {
    const double x = (t - ti) / scale;
    double g = 0.0;
    for (Eigen::Index k = weights.size() - 1; k >= 0; --k) g = g * x + weights[k];
    return g / scale;
  }
};

// The regressions of every half-width of kHalves at sample i of a segment's samples (t, z: its
// rows), from power sums accumulated as the (nested) windows grow.
class LocalFits {
 public:
  LocalFits(const Eigen::Ref<const Eigen::VectorXd>& t, const Eigen::Ref<const Eigen::MatrixXd>& z, Eigen::Index i)
      : t_(t), z_(z), i_(i) {
    const Eigen::Index d = z.cols();
    Eigen::Index lo = i, hi = i - 1;
    const auto [lo_max, hi_max] = Bounds(kHalves.back());
    unit_ = std::max({t[hi_max] - t[i], t[i] - t[lo_max], 1e-300});
    Eigen::Matrix<double, 2 * kMaxDegree + 1, 1> powers = Eigen::Matrix<double, 2 * kMaxDegree + 1, 1>::Zero();
    Eigen::Matrix<double, kMaxDegree + 1, Eigen::Dynamic> moments = Eigen::MatrixXd::Zero(kMaxDegree + 1, d);
    auto add = [&](Eigen::Index j) {
      const double u = (t[j] - t[i]) / unit_;
      double p = 1.0;
      for (int q = 0; q <= 2 * kMaxDegree; ++q, p *= u) {
        powers[q] += p;
        if (q <= kMaxDegree) moments.row(q) += p * z.row(j);
      }
    };
    for (size_t h = 0; h < kHalves.size(); ++h) {
      const auto [a, b] = Bounds(kHalves[h]);
      for (Eigen::Index j = a; j < lo; ++j) add(j);
      for (Eigen::Index j = std::max(hi + 1, a); j <= b; ++j) add(j);
      lo = std::min(lo, a);
      hi = std::max(hi, b);
      lo_[h] = lo, hi_[h] = hi;
      powers_[h] = powers;
      moments_[h] = moments;
    }
  }

  // The window [lo, hi] of half-width `half` at sample i, shifted to stay inside the samples.
  std::pair<Eigen::Index, Eigen::Index> Bounds(int half) const {
    const Eigen::Index n = t_.size();
    if (2 * half + 1 >= n) return {0, n - 1};
    const Eigen::Index lo = std::clamp<Eigen::Index>(i_ - half, 0, n - 1 - 2 * half);
    return {lo, lo + 2 * half};
  }

  // The regression of degree `degree` over half-width kHalves[h], with at least `spare` samples
  // more than its coefficients.
  Regression Fit(size_t h, int degree, int spare = kSpareSamples) const {
    Regression r;
    r.lo = lo_[h], r.hi = hi_[h];
    if (r.hi - r.lo + 1 < degree + 1 + spare) return r;
    const double ti = t_[i_];
    r.scale = std::max(t_[r.hi] - ti, ti - t_[r.lo]);
    if (!(r.scale > 0.0)) return r;
    const double ratio = unit_ / r.scale;  // x = u·ratio
    const int n = degree + 1;
    std::array<double, 2 * kMaxDegree + 1> ratio_powers{};  // up to 2·degree: more than a SmallVector holds
    ratio_powers[0] = 1.0;
    for (int q = 1; q <= 2 * degree; ++q) ratio_powers[q] = ratio_powers[q - 1] * ratio;
    Small gram(n, n);
    for (int k = 0; k < n; ++k) {
      for (int l = 0; l < n; ++l) gram(k, l) = powers_[h][k + l] * ratio_powers[k + l];
    }
    const Eigen::LDLT<Small> ldlt(gram);
    if (ldlt.info() != Eigen::Success || !(ldlt.rcond() > 1e-14)) return r;
    SmallVector unit = SmallVector::Zero(n);
    unit[1] = 1.0;
    r.weights = ldlt.solve(unit);
    const Eigen::Index d = z_.cols();
    r.value.resize(d);
    r.rate.resize(d);
    for (Eigen::Index c = 0; c < d; ++c) {
      SmallVector rhs(n);
      for (int k = 0; k < n; ++k) rhs[k] = moments_[h](k, c) * ratio_powers[k];
      // value = e0ᵀG⁻¹b, rate = e1ᵀG⁻¹b/scale = gᵀb/scale.
      const SmallVector coefficients = ldlt.solve(rhs);
      r.value[c] = coefficients[0];
      r.rate[c] = coefficients[1] / r.scale;
    }
    r.ok = true;
    return r;
  }

 private:
  Eigen::Ref<const Eigen::VectorXd> t_;
  Eigen::Ref<const Eigen::MatrixXd> z_;
  Eigen::Index i_;
  double unit_ = 1.0;
  std::array<Eigen::Index, kHalves.size()> lo_{}, hi_{};
  std::array<Eigen::Matrix<double, 2 * kMaxDegree + 1, 1>, kHalves.size()> powers_;
  std::array<Eigen::Matrix<double, kMaxDegree + 1, Eigen::Dynamic>, kHalves.size()> moments_;
};

// Σ_j w_a(j)·w_b(j) over the samples both regressions use.
double WeightProduct(const Eigen::Ref<const Eigen::VectorXd>& t, double ti, const Regression& a, const Regression& b) {
  double sum = 0.0;
  for (Eigen::Index j = std::max(a.lo, b.lo); j <= std::min(a.hi, b.hi); ++j) sum += a.Weight(t[j], ti) * b.Weight(t[j], ti);
  return sum;
}

// |w|² of a regression's rate: (G⁻¹)_11/scale², i.e. g_1/scale².
double WeightNorm(const Regression& r) { return r.weights[1] / (r.scale * r.scale); }

// The candidates: (half-width index, degree) with degree odd 1..7.
std::vector<std::pair<size_t, int>> Candidates() {
  std::vector<std::pair<size_t, int>> candidates;
  for (size_t h = 0; h < kHalves.size(); ++h) {
    for (int degree = 1; degree <= kMaxDegree; degree += 2) {
      if (2 * kHalves[h] + 1 >= degree + 1 + kSpareSamples) candidates.emplace_back(h, degree);
    }
  }
  return candidates;
}

size_t HalfIndex(int half) {
  return static_cast<size_t>(std::find(kHalves.begin(), kHalves.end(), half) - kHalves.begin());
}

// The covariance factor of a window's rate with the pilot's at sample i: w_W·w_P, with w_W(j) =
// s·T'(x_i)ᵀ G⁻¹ T(x_j) from the window's normal matrix (per coordinate degree).
class WindowWeights {
 public:
  WindowWeights(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, const CurveWindow& window) : window_(window) {
    top_ = *std::max_element(window.degrees.begin(), window.degrees.end());
    if (top_ >= 1) cholesky_ = FactorWindow(t, z, window);
  }

  // w_W·w_P per coordinate at time ti for the pilot `pilot` (on the segment's samples `ts`), and
  // |w_W|² into `norm`.
  Eigen::VectorXd Product(const Eigen::Ref<const Eigen::VectorXd>& ts, double ti, const Regression& pilot,
                          Eigen::VectorXd* norm) const {
    const auto d = static_cast<Eigen::Index>(window_.degrees.size());
    Eigen::VectorXd product = Eigen::VectorXd::Zero(d);
    norm->setZero(d);
    if (!cholesky_) return product;
    const Interval& interval = window_.series.interval;
    // u = Σ_j w_P(j) T(x_j), and T'(x_i) = k·U_{k−1}(x_i).
    Eigen::VectorXd u = Eigen::VectorXd::Zero(top_ + 1), derivative(top_ + 1);
    for (Eigen::Index j = pilot.lo; j <= pilot.hi; ++j) {
      if (ts[j] < window_.fit_begin || ts[j] > window_.fit_end) continue;  // not the window's sample
      const double x = interval.ToUnit(ts[j]), w = pilot.Weight(ts[j], ti);
      double previous = 1.0, current = x;
      u[0] += w;
      if (top_ >= 1) u[1] += w * x;
      for (int k = 2; k <= top_; ++k) {
        const double next = 2.0 * x * current - previous;
        previous = current, current = next;
        u[k] += w * current;
      }
    }
    ChebyshevSlopes(interval.ToUnit(ti), interval.DerivativeScale(), derivative);
    // T'ᵀG⁻¹u and T'ᵀG⁻¹T' at each coordinate's degree from one forward solve of each (NestedCholesky::Whiten).
    const Eigen::VectorXd whitened_u = cholesky_->Whiten(top_, u), whitened_derivative = cholesky_->Whiten(top_, derivative);
    for (Eigen::Index c = 0; c < d; ++c) {
      const int degree = window_.degrees[static_cast<size_t>(c)];
      if (degree < 1) continue;
      product[c] = whitened_derivative.head(degree + 1).dot(whitened_u.head(degree + 1));
      (*norm)[c] = whitened_derivative.head(degree + 1).squaredNorm();
    }
    return product;
  }

 private:
  const CurveWindow& window_;
  int top_ = 0;
  std::optional<NestedCholesky> cholesky_;
};

// Sums over a stretch of samples for choosing between the candidates and the windows: squared
// rate differences from the pilot and weight products with it, per candidate (rows) and
// coordinate; the same for the windows; and, summed per block of kBlock samples (they are
// correlated over about a candidate's width; the blocks' means scatter like independent draws),
// the per-sample gains over the windows, D = (v_a − v_P)² − (v_W − v_P)² and P = w_a·w_P − w_W·w_P,
// and the pilot's squared rate differences from the reference and their noise factor |w_P − w_R|².
struct StretchScores {
  StretchScores(Eigen::Index count, Eigen::Index d, Eigen::Index samples)
      : length(samples),
        blocks(samples / kBlock),
        differences(Eigen::MatrixXd::Zero(count, d)),
        products(Eigen::VectorXd::Zero(count)),
        window_differences(Eigen::VectorXd::Zero(d)),
        window_products(Eigen::VectorXd::Zero(d)),
        window_spread(Eigen::VectorXd::Zero(d)),
        usable(static_cast<size_t>(count), 1),
        block_gains(static_cast<size_t>(blocks), Eigen::MatrixXd::Zero(count, d)),
        block_products(static_cast<size_t>(blocks), Eigen::MatrixXd::Zero(count, d)),
        block_bias_differences(static_cast<size_t>(blocks), Eigen::VectorXd::Zero(d)),
        block_bias_variance(static_cast<size_t>(blocks), 0.0) {}

  // The mean per sample of a quantity summed per block (`block_sum(b)`) and its standard error
  // from the scatter of the blocks' means.
  template <class BlockSum>
  std::pair<double, double> MeanAndError(BlockSum&& block_sum) const {
    double sum = 0.0, sum_squares = 0.0;
    for (size_t b = 0; b < block_gains.size(); ++b) {
      const double size = b + 1 == block_gains.size() ? static_cast<double>(length - static_cast<Eigen::Index>(b) * kBlock)
                                                      : static_cast<double>(kBlock);
      const double total = block_sum(b);
      sum += total, sum_squares += (total / size) * (total / size);
    }
    const double mean = sum / static_cast<double>(length), count = static_cast<double>(blocks);
    return {mean, std::sqrt(std::max(0.0, sum_squares / count - mean * mean) / (count - 1.0))};
  }

  // The candidate that replaces the windows in coordinate c (noise σ), or -1; and whether the
  // pilot's bias alone kept the best candidate out.
  struct Choice {
    int candidate = -1;
    bool biased_pilot = false;
  };
  Choice Choose(Eigen::Index c, double sigma) const {
    // The windows' rates differ from the pilot's by at least their noise, σ²·Σ|w_W − w_P|² in
    // expectation: where they differ less, σ overstates the noise there (motion taken for noise,
    // e.g. a noise-free tremor), and the smaller value follows from the differences.
    const double data_variance = sigma * sigma;
    const double variance = std::min(
        data_variance, window_spread[c] > 0.0 ? window_differences[c] / window_spread[c] : data_variance);
    // Windows closer to the pilot than a fraction of that: nothing here tells the pilot's bias
    // from noise, and the windows are kept.
    if (variance < kSmoothFraction * data_variance) return {};
    int chosen = -1;
    double best = std::numeric_limits<double>::infinity();
    for (Eigen::Index a = 0; a < differences.rows(); ++a) {
      const double score = differences(a, c) + 2.0 * variance * products[a];
      if (usable[static_cast<size_t>(a)] && score < best) {
        best = score;
        chosen = static_cast<int>(a);
      }
    }
    // The pilot's squared bias (its rate's mean squared difference from the reference's less
    // the noise's share) counts as far as it stands out of its own scatter where that noise share
    // dominates: the estimate then subtracts a noise term some 10x the bias it leaves, and a
    // per-cent error of σ² or the scatter of the differences would otherwise veto every
    // candidate at random. Where the noise share is under half the differences (nearly
    // noise-free motion), their scatter is the bias's own variation along the stretch, and
    // discounting it let the pilot replace windows ten times better (docs/velocity.md).
    const auto [bias_mean, bias_error] = MeanAndError(
        [&](size_t b) { return block_bias_differences[b][c] - variance * block_bias_variance[b]; });
    double differences_total = 0.0, noise_total = 0.0;
    for (size_t b = 0; b < block_bias_variance.size(); ++b) {
      differences_total += block_bias_differences[b][c];
      noise_total += variance * block_bias_variance[b];
    }
    const double discount = noise_total < kBiasNoiseShare * differences_total ? 0.0 : kSignificance * bias_error;
    const double bias = static_cast<double>(length) * std::max(0.0, bias_mean - discount);
    const double windows_score = window_differences[c] + 2.0 * variance * window_products[c];
    if (chosen < 0) return {};
    if (!(best + 2.0 * bias < windows_score)) return {.biased_pilot = bias > 0.0};
    // The gain must stand out of its own scatter: 2 standard errors of the mean of the blocks'.
    const auto [mean, error] = MeanAndError(
        [&](size_t b) { return block_gains[b](chosen, c) + 2.0 * variance * block_products[b](chosen, c); });
    return {.candidate = mean < -kSignificance * error ? chosen : -1};
  }

  Eigen::Index length, blocks;
  Eigen::MatrixXd differences;
  Eigen::VectorXd products, window_differences, window_products, window_spread;
  std::vector<char> usable;
  std::vector<Eigen::MatrixXd> block_gains, block_products;
  std::vector<Eigen::VectorXd> block_bias_differences;
  std::vector<double> block_bias_variance;
};

}  // namespace

bool RegressionMayGain(const CurveWindow& window) {
  if (window.missed_motion) return true;
  const int top = *std::max_element(window.degrees.begin(), window.degrees.end());
  return window.samples < (2 * kHalves.back() + 1) * static_cast<Eigen::Index>(top + 1);
}

std::vector<LocalRun> LocalRegressionRuns(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, Eigen::Index first,
                                          Eigen::Index last, const CurveSegment& segment,
                                          const Eigen::MatrixXd& window_values, const Eigen::MatrixXd& window_rates,
                                          const Eigen::MatrixXd& fit_values, const Eigen::MatrixXd& fit_rates,
                                          const LocalSamples* local, const NoiseProfile& noise,
                                          const Eigen::VectorXd& rounding, const std::vector<bool>& staircase) {
  std::vector<LocalRun> runs;
  const std::vector<CurveWindow>& windows = segment.windows;
  const Eigen::Index n = last - first, d = z.cols();
  if (windows.size() < 3 || n < 2 * kHalves.back() + 1) return runs;
  // Candidate samples and the window whose core holds each: not in a segment's first or last
  // window. Samples the local interpolant took are candidates too, scored with its rate.
  std::vector<int> owner(static_cast<size_t>(n), -1);
  const std::vector<Eigen::Index> windows_of = SampleWindows(t, first, n, windows);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto w = static_cast<size_t>(windows_of[static_cast<size_t>(i)]);
    if (w > 0 && w + 1 < windows.size() && RegressionMayGain(windows[w])) owner[static_cast<size_t>(i)] = static_cast<int>(w);
    // A local rate chosen knowing the motion's frequency stays: σ then holds motion read as noise
    // (noise-free tones at a quarter of the rate read as 0.2 mm), which would score the noise of
    // the candidates' weights, not the rates' errors.
    if (local && local->modelled.row(i).any()) owner[static_cast<size_t>(i)] = -1;
  }
  // Nor does one in a coordinate whose local samples carry motion rather than noise (EuRoC's
  // ground truth, a filter's output, has its vibration from sample to sample).
  if (local) {
    const std::vector<char> noisy = NoisyLocalSamples(t, z, first, n, *local, noise);
    for (Eigen::Index i = 0; i < n; ++i) {
      for (Eigen::Index c = 0; c < d; ++c) {
        if (local->local(i, c) && !noisy[static_cast<size_t>(c)]) owner[static_cast<size_t>(i)] = -1;
      }
    }
  }
  const bool any = std::any_of(owner.begin(), owner.end(), [](int w) { return w >= 0; });
  if (!any) return runs;

  const auto ts = t.segment(first, n);
  const auto zs = z.middleRows(first, n);
  const std::vector<std::pair<size_t, int>> candidates = Candidates();
  const auto count = static_cast<Eigen::Index>(candidates.size());
  std::vector<std::optional<WindowWeights>> window_weights(windows.size());

  for (Eigen::Index s0 = 0; s0 < n;) {
    if (owner[static_cast<size_t>(s0)] < 0) {
      ++s0;
      continue;
    }
    Eigen::Index s1 = s0;
    while (s1 < n && owner[static_cast<size_t>(s1)] >= 0) ++s1;
    const Eigen::Index length = s1 - s0;
    if (length < kMinStretch) {
      s0 = s1;
      continue;
    }
    // A stretch of more than kMaxScoredBlocks blocks is scored on that many, spread evenly over it:
    // the choice rests on means over samples and their standard error from the blocks' scatter,
    // which a systematic sample of blocks estimates as well, at a cost bounded per stretch (a
    // 720k-sample drone flight has stretches of 315k samples, which took a minute to score).
    const Eigen::Index stretch_blocks = length / kBlock;
    const bool sampled = stretch_blocks > kMaxScoredBlocks;
    std::vector<Eigen::Index> scored;  // the samples scored, in order
    for (Eigen::Index b = 0; b < (sampled ? kMaxScoredBlocks : 1); ++b) {
      const Eigen::Index begin = sampled ? s0 + b * stretch_blocks / kMaxScoredBlocks * kBlock : s0;
      for (Eigen::Index i = begin; i < (sampled ? begin + kBlock : s1); ++i) scored.push_back(i);
    }
    // The stretch's scores against one pilot (none where the pilot cannot be fitted).
    auto score = [&](const Pilot& choice) -> std::optional<StretchScores> {
      const size_t pilot_h = HalfIndex(choice.half), reference_h = HalfIndex(choice.reference_half);
      StretchScores scores(count, d, static_cast<Eigen::Index>(scored.size()));
      Eigen::VectorXd norm(d);
      for (size_t q = 0; q < scored.size(); ++q) {
        const Eigen::Index i = scored[q];
        const LocalFits fits(ts, zs, i);
        const Regression pilot = fits.Fit(pilot_h, choice.degree, kPilotSpareSamples);
        const Regression reference = fits.Fit(reference_h, choice.reference_degree, kPilotSpareSamples);
        if (!pilot.ok || !reference.ok) return std::nullopt;
        const double ti = ts[i];
        const auto block = static_cast<size_t>(std::min(scores.blocks - 1, static_cast<Eigen::Index>(q) / kBlock));
        scores.block_bias_differences[block] += (pilot.rate - reference.rate).cwiseAbs2();
        scores.block_bias_variance[block] +=
            WeightNorm(pilot) - 2.0 * WeightProduct(ts, ti, pilot, reference) + WeightNorm(reference);
        const auto k = static_cast<size_t>(owner[static_cast<size_t>(i)]);
        const Eigen::VectorXd window_difference = (fit_rates.row(first + i).transpose() - pilot.rate).cwiseAbs2();
        Eigen::VectorXd product = Eigen::VectorXd::Zero(d);
        if (!local || !local->local.row(i).all()) {  // the window's weights, where some coordinate has its rate
          if (!window_weights[k]) window_weights[k].emplace(t, z, windows[k]);
          product = window_weights[k]->Product(ts, ti, pilot, &norm);
        }
        for (Eigen::Index c = 0; local && c < d; ++c) {  // a local rate's weights instead of the window's
          if (!local->local(i, c)) continue;
          const auto [lo, weights] = LocalRateWeights(t, first, n, *local, i, c);
          double sum = 0.0;
          for (Eigen::Index j = std::max(lo, pilot.lo); j <= std::min(lo + weights.size() - 1, pilot.hi); ++j) {
            sum += weights[j - lo] * pilot.Weight(ts[j], ti);
          }
          product[c] = sum;
          norm[c] = weights.squaredNorm();
        }
        scores.window_differences += window_difference;
        scores.window_products += product;
        scores.window_spread += ((norm - 2.0 * product).array() + WeightNorm(pilot)).matrix();
        for (Eigen::Index a = 0; a < count; ++a) {
          const auto [h, degree] = candidates[static_cast<size_t>(a)];
          const Regression r = fits.Fit(h, degree);
          if (!r.ok) {
            scores.usable[static_cast<size_t>(a)] = 0;
            continue;
          }
          const Eigen::VectorXd difference = (r.rate - pilot.rate).cwiseAbs2();
          const double weight_product = WeightProduct(ts, ti, r, pilot);
          scores.differences.row(a) += difference.transpose();
          scores.products[a] += weight_product;
          scores.block_gains[block].row(a) += (difference - window_difference).transpose();
          scores.block_products[block].row(a) += (weight_product - product.array()).matrix().transpose();
        }
      }
      return scores;
    };
    // Per coordinate, the first pilot's choice; where its bias alone vetoes the best candidate
    // (motion near a quarter of the rate, which it misses), the second's.
    std::vector<int> chosen(static_cast<size_t>(d), -1);
    std::vector<bool> biased(static_cast<size_t>(d), false);
    const Eigen::VectorXd sigma = noise.Over(first + s0, length);
    for (size_t rung = 0; rung < kPilots.size(); ++rung) {
      if (rung > 0 && std::none_of(biased.begin(), biased.end(), [](bool b) { return b; })) break;
      const std::optional<StretchScores> scores = score(kPilots[rung]);
      if (!scores) break;
      for (Eigen::Index c = 0; c < d; ++c) {
        if (rung > 0 && !biased[static_cast<size_t>(c)]) continue;
        // A staircase's errors are not white, as read or placed.
        if (staircase[static_cast<size_t>(c)] || AtRoundingLevel(sigma[c], rounding[c])) continue;
        const StretchScores::Choice choice = scores->Choose(c, sigma[c]);
        chosen[static_cast<size_t>(c)] = choice.candidate;
        biased[static_cast<size_t>(c)] = choice.biased_pilot;
      }
    }
    const bool replaced = std::any_of(chosen.begin(), chosen.end(), [](int a) { return a >= 0; });
    if (replaced) {
      // The run: the stretch and a sample of the fit on either side.
      const Eigen::Index begin = std::max<Eigen::Index>(0, s0 - 1), stop = std::min(n, s1 + 1);
      LocalRun run;
      run.regression = true;
      run.values.resize(stop - begin, d);
      run.rates.resize(stop - begin, d);
      for (Eigen::Index i = begin; i < stop; ++i) {
        if (!run.times.empty() && !(ts[i] > run.times.back())) continue;
        const auto r = static_cast<Eigen::Index>(run.times.size());
        run.times.push_back(ts[i]);
        const bool inside = i >= s0 && i < s1;  // its ends carry the windows' fit, as the local runs' do
        run.values.row(r) = (inside ? fit_values : window_values).row(first + i);
        run.rates.row(r) = (inside ? fit_rates : window_rates).row(first + i);
        if (i < s0 || i >= s1) continue;
        const LocalFits fits(ts, zs, i);
        for (Eigen::Index c = 0; c < d; ++c) {
          const int a = chosen[static_cast<size_t>(c)];
          if (a < 0) continue;
          const auto [h, degree] = candidates[static_cast<size_t>(a)];
          const Regression fit = fits.Fit(h, degree);
          run.values(r, c) = fit.value[c];
          run.rates(r, c) = fit.rate[c];
        }
      }
      if (run.times.size() >= 2) {
        run.values.conservativeResize(static_cast<Eigen::Index>(run.times.size()), d);
        run.rates.conservativeResize(static_cast<Eigen::Index>(run.times.size()), d);
        runs.push_back(std::move(run));
      }
    }
    s0 = s1;
  }
  return runs;
}

}  // namespace cheval::cheb::internal

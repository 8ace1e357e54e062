#include "local_rates.h"

#include "noise_profile.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <vector>

#include "cheval/cheb/fit.h"
#include "cheval/common/error.h"

namespace cheval::cheb::internal {
namespace {

using Flags = Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic>;

// A slope departing from the mean of its two neighbours by more than this many local scales (and
// more than they do) is an isolated spike: a small step of the values (docs/velocity.md).
constexpr double kSpikeScales = 4.0;
// Slopes per block of the local scale.
constexpr Eigen::Index kBlock = 64;
// Held-out samples a window needs for its interpolant's error to be compared with its own.
constexpr double kMinHeldOut = 8;
// UnderResolvedRates' code for the interpolating spline's slopes.
constexpr int kSpline = 9;
// The variance of the interpolating cubic spline's slopes over σ²/h² for white noise at even spacing.
constexpr double kSplineNoiseGain = 1.392;
// The rates ReviseLocalSamples weighs against the present one: the 3-point one, the 5-point one and
// the spline's slopes (their noise products with the spline's slopes: RateWeights; at even spacing
// w_x·w_s·h² = 0.804, 1.108 and 1.392).
constexpr Eigen::Index kCandidates = 3;
constexpr Eigen::Index kThree = 0, kFive = 1, kSplineSlopes = 2;
// The most the 5-point rate's mean squared departure from the spline's slopes may exceed its noise
// by, as a factor, for the spline's slopes to serve as the reference (ReviseLocalSamples).
constexpr double kReferenceNoise = 4.0;
// Windows on either side of a window pooled into a candidate rate's gain over the present rate,
// and the standard errors of the pooled mean (from the windows' scatter) it must pass by.
constexpr Eigen::Index kPooledGainWindows = 8;
constexpr double kGainSignificance = 2.0;
// Samples on either side of a sample over which the spline's weights there are solved (RateWeights).
constexpr Eigen::Index kSplineReach = 8;
// The most core samples over which a window's rate noise is averaged (RateNoiseGains).
constexpr Eigen::Index kNoiseProbes = 64;
// Windows on either side of a window pooled into its departure from the spline's slopes: the
// smallest windows' cores hold 15–25 samples, too few for a mean square to decide by.
constexpr Eigen::Index kPooledWindows = 2;
// Standard errors of its pooled mean by which a window's departure from the spline's slopes must
// pass the break-even: at the break-even the expected gain is nil, and of the hundreds of windows
// tested, those that pass only by their mean's scatter lose (tests/cheb/under_resolved_test.cc).
constexpr double kDepartureMargin = 1.0;
// The most the mean squared difference of the 3-point and 5-point rates at local samples may exceed
// the noise the two share by, as a factor, for the samples to be called noisy (NoisyLocalSamples).
// At even spacing the 3-point rate's noise is 7.2 times the difference's (0.5 against 0.069·σ²/h²)
// and its squared bias 1–3 times the difference's (b₃ ∝ ω², b₅ ∝ ω⁴; 3 at a quarter of the rate):
// at 10 the noise is still a fifth of the 3-point rate's error, which a smoother may take away.
constexpr double kNoisyLocalRates = 10.0;
// Samples beyond the end sample in the one-sided stencil of higher order (BuildRuns), and the
// largest ratio of its steps it is used over.
constexpr Eigen::Index kOneSided = 5;
constexpr double kOneSidedSpread = 1.5;
// The stamps' resolution, whole nanoseconds (s). Steps are differences of stamps as seconds from
// the first sample, and their rounding must not decide a comparison of steps at a ratio that a
// grid with dropped samples meets exactly (Close; BuildRuns at 1.5, steps of 2h and 3h).
constexpr double kStampResolution = 1e-9;
// The one-sided rates at an end sample, as weights per 1/h on the end sample and the next ones at
// even spacing: the quadratic's through three samples and the quintic's through six.
constexpr std::array<double, 3> kOneSidedQuadratic{-1.5, 2.0, -0.5};
constexpr std::array<double, kOneSided + 1> kOneSidedQuintic{-137.0 / 60.0, 5.0, -5.0, 10.0 / 3.0, -1.25, 0.2};
// A step shorter than this fraction of the shorter step beside it is close (Close): there the
// quadratic that skips the close partner has 1/5 of the 3-point rate's noise variance; they are
// equal near 0.8, and the wider stencil's bias on motion the windows missed grows with its span.
constexpr double kCloseStep = 0.5;

// The slopes of the cubic spline through (times, values) that are C² at rows a..b, given the
// slopes at rows a − 1 and b + 1 (clamped): the tridiagonal system
// h_r·s_{r−1} + 2(h_{r−1} + h_r)·s_r + h_{r−1}·s_{r+1} = 3(h_r·d_{r−1} + h_{r−1}·d_r), h_r and d_r
// the step and slope from row r to r + 1, solved in place of `rates` (Thomas' algorithm).
void SplineSlopes(const std::vector<double>& times, const Eigen::Ref<const Eigen::VectorXd>& values, Eigen::Index a,
                  Eigen::Index b, Eigen::Ref<Eigen::VectorXd> rates) {
  const Eigen::Index k = b - a + 1;
  std::vector<double> upper(static_cast<size_t>(k)), rhs(static_cast<size_t>(k));
  double previous_upper = 0.0, previous_rhs = 0.0;
  for (Eigen::Index r = a; r <= b; ++r) {
    const double h0 = times[r] - times[r - 1], h1 = times[r + 1] - times[r];
    const double d0 = (values[r] - values[r - 1]) / h0, d1 = (values[r + 1] - values[r]) / h1;
    const double lower = h1, diagonal = 2.0 * (h0 + h1);
    double right = 3.0 * (h1 * d0 + h0 * d1), up = h0;
    if (r == a) right -= lower * rates[a - 1];
    if (r == b) right -= up * rates[b + 1], up = 0.0;
    const double pivot = diagonal - (r == a ? 0.0 : lower * previous_upper);
    previous_upper = up / pivot;
    previous_rhs = (right - (r == a ? 0.0 : lower * previous_rhs)) / pivot;
    upper[static_cast<size_t>(r - a)] = previous_upper;
    rhs[static_cast<size_t>(r - a)] = previous_rhs;
  }
  rates[b] = rhs[static_cast<size_t>(k - 1)];
  for (Eigen::Index r = b - 1; r >= a; --r) rates[r] = rhs[static_cast<size_t>(r - a)] - upper[static_cast<size_t>(r - a)] * rates[r + 1];
}

// HeldOut at even spacing: the weights of z_{i-k} .. z_{i+k} (k = 2, 3, 4) and the gains.
constexpr double kEvenWeights[3][9] = {
    {1.0 / 6, -4.0 / 6, 6.0 / 6, -4.0 / 6, 1.0 / 6},
    {-1.0 / 20, 6.0 / 20, -15.0 / 20, 20.0 / 20, -15.0 / 20, 6.0 / 20, -1.0 / 20},
    {1.0 / 70, -8.0 / 70, 28.0 / 70, -56.0 / 70, 70.0 / 70, -56.0 / 70, 28.0 / 70, -8.0 / 70, 1.0 / 70}};
constexpr double kEvenGains[3] = {70.0 / 36, 924.0 / 400, 12870.0 / 4900};
// Each order's held-out error below this fraction of the one before: motion, not noise.
constexpr double kUnderResolved = 0.5;

// Whether step j (between samples j and j + 1 of a segment, `h` its steps) is shorter than
// kCloseStep of the shorter step beside it: a slope over it carries the samples' noise over that
// step, and the 3-point rate at either sample of such a pair takes it almost whole (Σw² of 2.9/h²
// at a ratio of 1/2, h the longer step, and about 1/h_short² below; 1/(2h²) at even spacing); the
// interpolating spline through them too. DIDO's motion capture, whose stamps alternate steps of
// 0.24–0.7 ms with steps of 4–5 ms, was 20x its noise off at such pairs (docs/velocity.md, "Local
// interpolant").
// A step at exactly that fraction is not close: one dropped sample of an even grid puts a step
// beside one twice as long, and the steps' rounding (stamps of whole nanoseconds, as seconds from
// the first) must not decide. It did at segment ends, where the close end step left the end
// sample without a slope (a 10 Hz hand-held recording with dropouts: 4.4 m/s off at its last
// sample, where the motion is under 1 m/s).
bool Close(const Eigen::VectorXd& h, Eigen::Index j) {
  const Eigen::Index n = h.size();
  double beside = std::numeric_limits<double>::infinity();
  if (j >= 1) beside = h[j - 1];
  if (j + 1 < n) beside = std::min(beside, h[j + 1]);
  return std::isfinite(beside) && h[j] > 0.0 && h[j] + kStampResolution < kCloseStep * beside;
}

}  // namespace

std::vector<Eigen::Index> SampleWindows(const Eigen::VectorXd& t, Eigen::Index first, Eigen::Index n,
                                        const std::vector<CurveWindow>& windows) {
  std::vector<Eigen::Index> owner(static_cast<size_t>(n), 0);
  const auto count = static_cast<Eigen::Index>(windows.size());
  Eigen::Index w = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    while (w + 1 < count && t[first + i] >= windows[static_cast<size_t>(w + 1)].core_begin) ++w;
    owner[static_cast<size_t>(i)] = w;
  }
  return owner;
}

std::optional<NestedCholesky> FactorWindow(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, const CurveWindow& window) {
  if (window.degrees.empty()) return std::nullopt;
  const int degree = *std::max_element(window.degrees.begin(), window.degrees.end());
  const auto first = std::lower_bound(t.data(), t.data() + t.size(), window.fit_begin) - t.data();
  const auto last = std::upper_bound(t.data(), t.data() + t.size(), window.fit_end) - t.data();
  try {
    return NestedCholesky(BuildNormalEquations(t.segment(first, last - first), z.middleRows(first, last - first), degree,
                                               window.series.interval),
                          degree);
  } catch (const ComputeError&) {
    return std::nullopt;
  }
}

Eigen::MatrixXd WindowSeriesAt(const CurveWindow& window, const Eigen::Ref<const Eigen::VectorXd>& times, int order) {
  const Interval& interval = window.series.interval;
  Eigen::VectorXd x(times.size());
  for (Eigen::Index i = 0; i < times.size(); ++i) x[i] = interval.ToUnit(times[i]);
  const double scale = interval.DerivativeScale();
  switch (order) {
    case 0: return EvaluateSeries(window.series.coefficients, x);
    case 1: return EvaluateSeries(window.first_derivative, x) * scale;
    case 2: return EvaluateSeries(window.second_derivative, x) * (scale * scale);
    default: throw std::invalid_argument("WindowSeriesAt: order 0..2");
  }
}

void ChebyshevSlopes(double x, double scale, Eigen::Ref<Eigen::VectorXd> slopes) {
  double u_previous = 0.0, u_current = 1.0;  // U_{-1}, U_0
  if (slopes.size() > 0) slopes[0] = 0.0;
  for (Eigen::Index k = 1; k < slopes.size(); ++k) {
    slopes[k] = static_cast<double>(k) * u_current;
    const double next = 2.0 * x * u_current - u_previous;
    u_previous = u_current, u_current = next;
  }
  slopes *= scale;
}

Eigen::VectorXd RateVarianceFactor(const NestedCholesky& cholesky, const Interval& interval,
                                   const std::vector<int>& degrees, double at) {
  const int top = cholesky.degree();
  Eigen::VectorXd basis(top + 1);
  ChebyshevSlopes(interval.ToUnit(at), interval.DerivativeScale(), basis);
  const Eigen::VectorXd whitened = cholesky.Whiten(top, basis);
  Eigen::VectorXd factor(static_cast<Eigen::Index>(degrees.size()));
  for (Eigen::Index c = 0; c < factor.size(); ++c) factor[c] = whitened.head(degrees[static_cast<size_t>(c)] + 1).squaredNorm();
  return factor;
}

std::pair<Eigen::Index, Eigen::Index> SamplesOf(const Eigen::VectorXd& t, Eigen::Index first, Eigen::Index n,
                                                const LocalRun& run) {
  const double* begin = t.data() + first;
  return {std::lower_bound(begin, begin + n, run.times.front()) - begin,
          std::upper_bound(begin, begin + n, run.times.back()) - begin};
}

namespace {

// The first of the segment's samples in each of `count` windows' cores, and the sample count after
// the last, from the samples' windows (SampleWindows); a window without samples starts where the
// next does.
std::vector<Eigen::Index> WindowStarts(const std::vector<Eigen::Index>& owner, Eigen::Index count) {
  const auto n = static_cast<Eigen::Index>(owner.size());
  std::vector<Eigen::Index> starts(static_cast<size_t>(count + 1), n);
  for (Eigen::Index i = n - 1; i >= 0; --i) starts[static_cast<size_t>(owner[static_cast<size_t>(i)])] = i;
  for (Eigen::Index w = count - 1; w >= 0; --w) {
    starts[static_cast<size_t>(w)] = std::min(starts[static_cast<size_t>(w)], starts[static_cast<size_t>(w + 1)]);
  }
  return starts;
}

// The noise σ per coordinate over the cores of windows a..b of a segment (`starts` its
// WindowStarts).
Eigen::VectorXd NoiseOver(const NoiseProfile& noise, Eigen::Index first, const std::vector<Eigen::Index>& starts,
                          Eigen::Index a, Eigen::Index b) {
  return noise.Over(first + starts[static_cast<size_t>(a)], starts[static_cast<size_t>(b + 1)] - starts[static_cast<size_t>(a)]);
}

// Whether the departures (`departure`, column c, defined at slopes 1 .. n − 2) around a spike at
// slope j follow a displaced sample rather than a step of the values, and then the other slope of
// that sample (−1 otherwise). A step δ between samples j and j + 1 departs slopes j − 1, j, j + 1 by
// (−1, 2, −1)·δ/2h; a sample displaced by ε departs the four slopes around it by (−1, 3, −3, 1)·ε/2h,
// its two own slopes equally. Each pattern's amplitude is fitted to the departures of slopes
// j − 2 .. j + 2 by least squares, and the one of least residual is taken.
Eigen::Index DisplacedPartner(const Eigen::MatrixXd& departure, Eigen::Index c, Eigen::Index j, Eigen::Index n) {
  constexpr double kStep[5] = {0, -1, 2, -1, 0}, kBefore[5] = {-1, 3, -3, 1, 0}, kAfter[5] = {0, -1, 3, -3, 1};
  auto misfit = [&](const double (&pattern)[5]) {
    double pp = 0.0, pd = 0.0, dd = 0.0;
    for (Eigen::Index k = 0; k < 5; ++k) {
      const Eigen::Index at = j - 2 + k;
      if (at < 1 || at > n - 2) continue;  // no departure there
      const double value = departure(at, c);
      pp += pattern[k] * pattern[k], pd += pattern[k] * value, dd += value * value;
    }
    return pp > 0.0 ? dd - pd * pd / pp : dd;
  };
  const double step = misfit(kStep), before = misfit(kBefore), after = misfit(kAfter);
  if (std::min(before, after) >= step) return -1;
  return before < after ? j - 1 : j + 1;
}

// Which slopes (between samples j and j + 1 of the segment, from `first`, per coordinate) are not
// spikes: neither a small step of the values nor a slope of a displaced sample.
Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic> UsableSlopes(const Eigen::VectorXd& h, const Eigen::MatrixXd& slopes,
                                                                const NoiseProfile& noise, Eigen::Index first) {
  const Eigen::Index n = slopes.rows(), d = slopes.cols();
  Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic> usable =
      Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic>::Constant(n, d, true);
  if (n < 3) return usable;
  // Samples with equal stamps have no slope between them, nor those much closer than their
  // neighbours (Close).
  for (Eigen::Index j = 0; j < n; ++j) usable.row(j).setConstant(h[j] > 0.0 && !Close(h, j));
  // Departures of the interior slopes (where all three exist), in units of the local scale.
  Eigen::MatrixXd departure = Eigen::MatrixXd::Zero(n, d);
  for (Eigen::Index j = 1; j + 1 < n; ++j) {
    if (h[j - 1] > 0.0 && h[j] > 0.0 && h[j + 1] > 0.0) {
      departure.row(j) = slopes.row(j) - 0.5 * (slopes.row(j - 1) + slopes.row(j + 1));
    }
  }
  // The noise's floor of the local scale per slope, sqrt(5)·σ/h (σ over the slope's two samples).
  Eigen::MatrixXd floors = Eigen::MatrixXd::Zero(n, d);
  for (Eigen::Index j = 1; j + 1 < n; ++j) {
    if (h[j] > 0.0) floors.row(j) = std::sqrt(5.0) * noise.Over(first + j, 2).transpose() / h[j];
  }
  std::vector<double> block;
  for (Eigen::Index c = 0; c < d; ++c) {
    Eigen::VectorXd score = Eigen::VectorXd::Zero(n);
    for (Eigen::Index begin = 1; begin + 1 < n; begin += kBlock) {
      const Eigen::Index end = std::min(n - 1, begin + kBlock);
      block.clear();
      for (Eigen::Index j = begin; j < end; ++j) block.push_back(std::abs(departure(j, c)));
      auto middle = block.begin() + static_cast<std::ptrdiff_t>(block.size() / 2);
      std::nth_element(block.begin(), middle, block.end());
      const double scale = 1.4826 * *middle;
      for (Eigen::Index j = begin; j < end; ++j) {
        if (!(h[j] > 0.0)) continue;
        const double s = std::max(scale, floors(j, c));
        score[j] = s > 0.0 ? std::abs(departure(j, c)) / s : 0.0;
      }
    }
    for (Eigen::Index j = 1; j + 1 < n; ++j) {
      // A step of the values between samples j and j + 1 moves slope j one way and the mean of
      // each neighbour's two neighbours the other: both neighbours depart the opposite way. Smooth
      // motion's curvature moves neighbouring departures together, however large it is locally.
      const bool opposed = departure(j - 1, c) * departure(j, c) < 0.0 && departure(j + 1, c) * departure(j, c) < 0.0;
      if (score[j] > kSpikeScales && opposed && score[j] >= score[j - 1] && score[j] >= score[j + 1]) {
        usable(j, c) = false;
        // A displaced sample's two slopes depart alike, so which is the larger is chance: taking
        // one out as a step left the other's displacement ε/h as the rate at the sample (TUM
        // fr2/desk's ground truth, whose noise bursts hold such samples: 0.4–0.8 m/s off where
        // central differences were 0.01–0.1 off). Both go; the sample takes the secant across it.
        if (const Eigen::Index partner = DisplacedPartner(departure, c, j, n); partner >= 0) usable(partner, c) = false;
      }
    }
  }
  return usable;
}

// The held-out error at sample i of the polynomial of degree 2k − 1 through its k neighbours on
// either side (Lagrange weights on the stamps), and *gain = 1 + the sum of the squared weights
// (the error's variance over σ² for white noise). False where the neighbours are not all inside
// [0, n) of the segment with distinct stamps.
bool HeldOut(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, Eigen::Index first, Eigen::Index n, Eigen::Index i,
             int k, Eigen::Ref<Eigen::RowVectorXd> error, double* gain) {
  if (i < k || i + k >= n) return false;
  Eigen::Index neighbours[8];
  for (int j = 0; j < k; ++j) neighbours[j] = first + i - k + j, neighbours[k + j] = first + i + 1 + j;
  const double ti = t[first + i];
  error = z.row(first + i);
  *gain = 1.0;
  for (int j = 0; j < 2 * k; ++j) {
    double weight = 1.0;
    for (int l = 0; l < 2 * k; ++l) {
      if (l == j) continue;
      const double span = t[neighbours[j]] - t[neighbours[l]];
      if (!(span != 0.0)) return false;
      weight *= (ti - t[neighbours[l]]) / span;
    }
    error -= weight * z.row(neighbours[j]);
    *gain += weight * weight;
  }
  return true;
}

// The derivative of the quadratic through three consecutive samples, from the slopes d0 and d1
// over the steps h0 and h1 between them: at the middle sample, and at an end sample (the near
// step's and the far step's).
double CentredRate(double h0, double d0, double h1, double d1) { return (h1 * d0 + h0 * d1) / (h0 + h1); }
double EndRate(double h_near, double d_near, double h_far, double d_far) {
  return d_near - h_near * (d_far - d_near) / (h_near + h_far);
}

// What the window missed in coordinate c, at least: its generalised cross-validation error
// m·RSS/(m − p)² (p = N + 1 coefficients) less what noise of variance `noise` gives it, σ²·m/(m − p).
double MissedMotion(const CurveWindow& window, Eigen::Index c, double noise) {
  const double m = window.samples, p = window.degrees[static_cast<size_t>(c)] + 1.0;
  const double rms = window.residual_rms[c];
  return m * m * rms * rms / ((m - p) * (m - p)) - noise * m / (m - p);
}

// Σw² of a one-sided rate's weights per 1/h (its noise variance over σ²/h²), and its relative
// error |Σ w_j e^{ijωh} − iωh| / ωh on a tone of frequency ω.
template <size_t N>
double OneSidedNoise(const std::array<double, N>& weights) {
  double sum = 0.0;
  for (const double w : weights) sum += w * w;
  return sum;
}
template <size_t N>
double OneSidedBias(const std::array<double, N>& weights, double omega_h) {
  double re = 0.0, im = 0.0;
  for (size_t j = 0; j < N; ++j) {
    re += weights[j] * std::cos(omega_h * static_cast<double>(j));
    im += weights[j] * std::sin(omega_h * static_cast<double>(j));
  }
  return std::hypot(re, im - omega_h) / omega_h;
}

// The index of the window whose residual test judges the samples of window w: an end cap (no
// residual test of its own) takes the verdict of the end window it was cut from, whose samples it
// covers and whose polynomial it keeps where no cap fit helps.
size_t JudgingIndex(const std::vector<CurveWindow>& windows, size_t w, Eigen::Index d) {
  const bool cap = windows[w].lack_of_fit.size() != d && windows.size() > 1 && (w == 0 || w + 1 == windows.size());
  return cap ? (w == 0 ? 1 : w - 1) : w;
}

const CurveWindow& JudgingWindow(const std::vector<CurveWindow>& windows, size_t w, Eigen::Index d) {
  return windows[JudgingIndex(windows, w, d)];
}

// The derivative at sample i of the polynomial through samples lo .. hi (distinct stamps; i among
// them): the quartic through i − 2 .. i + 2 in the interior, one-sided at a segment's end.
// The weights (samples lo .. hi) of that derivative: the derivative at t_i of the Lagrange
// polynomials of the stamps.
Eigen::VectorXd LagrangeWeights(const Eigen::VectorXd& t, Eigen::Index i, Eigen::Index lo, Eigen::Index hi) {
  Eigen::VectorXd weights(hi - lo + 1);
  double own = 0.0;
  for (Eigen::Index j = lo; j <= hi; ++j) {
    if (j == i) continue;
    own += 1.0 / (t[i] - t[j]);
    double weight = 1.0 / (t[j] - t[i]);
    for (Eigen::Index l = lo; l <= hi; ++l) {
      if (l != j && l != i) weight *= (t[i] - t[l]) / (t[j] - t[l]);
    }
    weights[j - lo] = weight;
  }
  weights[i - lo] = own;
  return weights;
}

double LagrangeRate(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, Eigen::Index i, Eigen::Index c, Eigen::Index lo,
                    Eigen::Index hi) {
  const Eigen::VectorXd weights = LagrangeWeights(t, i, lo, hi);
  double rate = 0.0;
  for (Eigen::Index j = lo; j <= hi; ++j) {
    if (j != i) rate += weights[j - lo] * z(j, c);
  }
  return rate + weights[i - lo] * z(i, c);
}

}  // namespace

LocalRates UnderResolvedRates(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, Eigen::Index first,
                              Eigen::Index last, const CurveSegment& segment, const NoiseProfile& noise) {
  const Eigen::Index n = last - first, d = z.cols();
  const auto count = static_cast<Eigen::Index>(segment.windows.size());
  LocalRates rates{Eigen::ArrayXXi::Constant(count, d, 3),
                   Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic>::Constant(count, d, false), Eigen::MatrixXd(),
                   Eigen::MatrixXd(), Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic>::Constant(count, d, false),
                   Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic>::Constant(count, d, false)};
  // Per window: the held-out errors' sums of squares of the polynomials through 2, 3 and 4
  // neighbours on either side (degree 3, 5, 7) at the samples where all exist, their noise gains,
  // and Σ 1/h² (the 3-point rate's noise).
  constexpr int kOrders = 3;
  Eigen::MatrixXd squares[kOrders], gains = Eigen::MatrixXd::Zero(count, kOrders);
  for (Eigen::MatrixXd& sum : squares) sum = Eigen::MatrixXd::Zero(count, d);
  Eigen::VectorXd used = Eigen::VectorXd::Zero(count), spacing = Eigen::VectorXd::Zero(count);
  Eigen::RowVectorXd errors[kOrders];
  for (Eigen::RowVectorXd& error : errors) error.resize(d);
  // Evenly spaced stamps (to 1e-9 of the step) take the fixed weights.
  bool even = n > 1 && t[first + 1] > t[first];
  for (Eigen::Index i = 1; i < n && even; ++i) {
    even = std::abs(t[first + i] - t[first + i - 1] - (t[first + 1] - t[first])) <= 1e-9 * (t[first + 1] - t[first]);
  }
  // The slopes of the cubic spline through the segment's samples (clamped at the 3-point rates at
  // its ends), and per window Σ (r₃ − r_s)², the 3-point rate's squared departure from them.
  const std::vector<double> times(t.data() + first, t.data() + last);
  const Eigen::VectorXd steps = n >= 3 ? Eigen::VectorXd(t.segment(first + 1, n - 1) - t.segment(first, n - 1))
                                       : Eigen::VectorXd();
  const bool distinct = n >= 3 && (steps.array() > 0.0).all();
  Eigen::MatrixXd spline_rates, three_rates;
  Eigen::MatrixXd departures = Eigen::MatrixXd::Zero(count, d);
  Eigen::VectorXd counted = Eigen::VectorXd::Zero(count);
  if (distinct) {
    spline_rates.resize(n, d);
    three_rates.resize(n, d);
    for (Eigen::Index c = 0; c < d; ++c) {
      const Eigen::VectorXd values = z.col(c).segment(first, n);
      const Eigen::VectorXd slopes = (values.tail(n - 1) - values.head(n - 1)).cwiseQuotient(steps);
      three_rates(0, c) = EndRate(steps[0], slopes[0], steps[1], slopes[1]);
      for (Eigen::Index i = 1; i + 1 < n; ++i) {
        three_rates(i, c) = CentredRate(steps[i - 1], slopes[i - 1], steps[i], slopes[i]);
      }
      three_rates(n - 1, c) = EndRate(steps[n - 2], slopes[n - 2], steps[n - 3], slopes[n - 3]);
      spline_rates(0, c) = three_rates(0, c);
      spline_rates(n - 1, c) = three_rates(n - 1, c);
      SplineSlopes(times, values, 1, n - 2, spline_rates.col(c));
    }
  }
  // An end cap's samples count with the end window it was cut from: they are that window's
  // samples, and the cap alone holds too few to be held out (its rows are the end window's, below).
  std::vector<Eigen::Index> owner = SampleWindows(t, first, n, segment.windows);
  for (Eigen::Index& w : owner) w = static_cast<Eigen::Index>(JudgingIndex(segment.windows, static_cast<size_t>(w), d));
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Index w = owner[static_cast<size_t>(i)];
    if (distinct) {
      departures.row(w) += (three_rates.row(i) - spline_rates.row(i)).cwiseAbs2();
      counted[w] += 1.0;
    }
    double gain[kOrders];
    bool all = i >= kOrders + 1 && i + kOrders + 1 < n;
    if (all && even) {  // the same at even spacing, from fixed weights: Δ⁴z/6, Δ⁶z/20, Δ⁸z/70
      for (Eigen::Index c = 0; c < d; ++c) {
        const double* y = z.col(c).data() + first + i;
        for (int o = 0; o < kOrders; ++o) {
          double e = 0.0;
          for (int j = -(o + 2); j <= o + 2; ++j) e += kEvenWeights[o][j + o + 2] * y[j];
          squares[o](w, c) += e * e;
        }
      }
      for (int o = 0; o < kOrders; ++o) gains(w, o) += kEvenGains[o];
    } else {
      for (int o = 0; o < kOrders && all; ++o) all = HeldOut(t, z, first, n, i, o + 2, errors[o], &gain[o]);
      if (!all) continue;
      for (int o = 0; o < kOrders; ++o) {
        squares[o].row(w) += errors[o].cwiseAbs2();
        gains(w, o) += gain[o];
      }
    }
    if (!all) continue;
    used[w] += 1.0;
    const double h = 0.5 * (t[first + i + 1] - t[first + i - 1]);
    spacing[w] += 1.0 / (h * h);
  }
  const std::vector<Eigen::Index> starts = WindowStarts(owner, count);
  for (Eigen::Index k = 0; k < count; ++k) {
    const CurveWindow& window = segment.windows[static_cast<size_t>(k)];
    if (used[k] < kMinHeldOut || window.residual_rms.size() != d || window.degrees.size() != static_cast<size_t>(d)) {
      continue;
    }
    const Eigen::VectorXd sigma = NoiseOver(noise, first, starts, k, k);
    const auto m = static_cast<double>(window.samples);
    const double span = window.fit_end - window.fit_begin, h = 1.0 / std::sqrt(spacing[k] / used[k]);
    for (Eigen::Index c = 0; c < d; ++c) {
      const double p = window.degrees[static_cast<size_t>(c)] + 1.0;
      if (!(m > p) || !(span > 0.0)) continue;
      // At even spacing h the held-out errors are Δ⁴z/6, Δ⁶z/20 and Δ⁸z/70: for motion of
      // frequency ω each order's is u·(6/20)² and u·(20/70)² of the one before, u = (2 sin(ωh/2))²
      // ≤ 4 (at most 0.36 and 0.33); for white noise 1.19 and 1.14 (the gains' ratios). Only
      // where both ratios are below 1/2 is the cubic's error motion the samples under-resolve
      // (not noise), and u gives ω.
      const double cubic = squares[0](k, c), quintic = squares[1](k, c), septic = squares[2](k, c);
      const bool falls = quintic < kUnderResolved * cubic && septic < kUnderResolved * quintic;
      const double u = std::min(4.0, quintic / cubic / 0.09), omega_h = 2.0 * std::asin(0.5 * std::sqrt(u));
      // The degree-7 error less what the motion gives it bounds the noise.
      const double frequency = omega_h / h, noise_variance = std::max(0.0, septic - 0.0816 * u * quintic) / gains(k, 2);
      // What the window missed (MissedMotion, with that noise): above the 2N/span it resolves, the
      // missed motion's rate errs by that times the frequency.
      const bool above = frequency > 2.0 * (p - 1.0) / span;
      const double missed = MissedMotion(window, c, noise_variance);
      // Each local rate's error: its noise σ²·Σw² and its bias at ω, a fraction of the motion's
      // rate, the motion being 6/u² of the cubic's error. The 3-point rate (central difference):
      // Σw² = 1/(2h²), fraction 1 − sin(ωh)/ωh; the 5-point one (the quartic's derivative):
      // Σw² = 130/(144h²), fraction 1 − (8 sin(ωh) − sin(2ωh))/(6ωh).
      const double motion = std::max(0.0, cubic - noise_variance * gains(k, 0)) / used[k];
      const double scale = 6.0 / (u * u) * frequency, inverse_h2 = spacing[k] / used[k];
      const double bias3 = scale * (1.0 - std::sin(omega_h) / omega_h);
      const double bias5 = scale * (1.0 - (8.0 * std::sin(omega_h) - std::sin(2.0 * omega_h)) / (6.0 * omega_h));
      // The interpolating cubic spline's slopes (C² at the samples): Σw² = 1.392/h², fraction
      // 1 − 3 sin(ωh)/(ωh(2 + cos ωh)).
      const double bias_spline = scale * (1.0 - 3.0 * std::sin(omega_h) / (omega_h * (2.0 + std::cos(omega_h))));
      const double error3 = noise_variance * 0.5 * inverse_h2 + motion * bias3 * bias3;
      const double error5 = noise_variance * 130.0 / 144.0 * inverse_h2 + motion * bias5 * bias5;
      const double error_spline = noise_variance * 1.392 * inverse_h2 + motion * bias_spline * bias_spline;
      const double best = std::min({error3, error5, error_spline});
      rates.stencil(k, c) = best == error_spline ? kSpline : best == error5 ? 5 : 3;
      // Where the model prefers the 3-point rate, the samples may still say otherwise: its bias
      // less the spline's is at least their difference, whose noise is σ²·0.285/h² at even
      // spacing; the spline's slopes are better when its extra noise, σ²·(1.392 − 0.5)/h², is below
      // that bias (mean difference² above σ²·1.177/h²; pure noise reaches it with probability
      // ~1e-5 over 10 independent samples). The model reads motion near a quarter of the rate
      // with a spread spectrum as noise.
      if (rates.stencil(k, c) == 3 && counted[k] > 0.0 &&
          departures(k, c) / counted[k] > 1.177 * sigma[c] * sigma[c] * inverse_h2) {
        rates.stencil(k, c) = kSpline;
      }
      rates.under_resolved(k, c) = falls && above && missed > 0.0 && missed * frequency * frequency > best;
      rates.modelled(k, c) = falls;
      // At the end sample, one-sided: the quintic's error constant is smaller, but at a quarter of
      // the rate it keeps less of a tone's rate than the quadratic (5 % against 31 % lost at ωh = 1,
      // 95 % against 69 % at π/2), and its noise is 10 times larger.
      const double end_bias3 = scale * OneSidedBias(kOneSidedQuadratic, omega_h);
      const double end_bias6 = scale * OneSidedBias(kOneSidedQuintic, omega_h);
      rates.one_sided_quintic(k, c) =
          noise_variance * OneSidedNoise(kOneSidedQuintic) * inverse_h2 + motion * end_bias6 * end_bias6 <
          noise_variance * OneSidedNoise(kOneSidedQuadratic) * inverse_h2 + motion * end_bias3 * end_bias3;
    }
  }
  // An end cap takes the end window's stencil and verdicts. The 3-point default put a one-sided
  // 3-point rate at the segment's end sample, whose error constant is several times the centred
  // one's.
  for (const size_t w : {size_t{0}, segment.windows.size() - 1}) {
    if (count < 2) break;
    const auto judge = static_cast<Eigen::Index>(JudgingIndex(segment.windows, w, d));
    if (judge == static_cast<Eigen::Index>(w)) continue;
    const auto k = static_cast<Eigen::Index>(w);
    rates.stencil.row(k) = rates.stencil.row(judge);
    rates.under_resolved.row(k) = rates.under_resolved.row(judge);
    rates.modelled.row(k) = rates.modelled.row(judge);
    rates.one_sided_quintic.row(k) = rates.one_sided_quintic.row(judge);
  }
  rates.spline_slopes = std::move(spline_rates);
  rates.three_rates = std::move(three_rates);
  return rates;
}

namespace {

// Per window of the segment and coordinate (row-major, window · d + c): whether the window's rate
// departs from the spline's slopes by more than the spline's noise allows, where the window's missed
// motion could hold that departure (ChooseLocalSamples).
std::vector<bool> DepartsFromSpline(const Eigen::VectorXd& t, Eigen::Index first, Eigen::Index n,
                                    const CurveSegment& segment, const LocalRates& rates,
                                    const Eigen::MatrixXd& fit_rates, const NoiseProfile& noise) {
  const std::vector<CurveWindow>& windows = segment.windows;
  const auto count = static_cast<Eigen::Index>(windows.size());
  const Eigen::Index d = fit_rates.cols();
  std::vector<bool> departs(static_cast<size_t>(count * d), false);
  if (rates.spline_slopes.rows() != n) return departs;
  // Per window: Σ (r_s − r_fit)² over its core's interior samples, their count and Σ 1/h² (h half
  // the span of a sample's neighbours).
  Eigen::MatrixXd squares = Eigen::MatrixXd::Zero(count, d), fourth = squares;
  Eigen::VectorXd samples = Eigen::VectorXd::Zero(count), inverse_h2 = Eigen::VectorXd::Zero(count);
  const std::vector<Eigen::Index> owner = SampleWindows(t, first, n, windows);
  for (Eigen::Index i = 1; i + 1 < n; ++i) {
    const Eigen::Index w = owner[static_cast<size_t>(i)];
    const double h = 0.5 * (t[first + i + 1] - t[first + i - 1]);
    const Eigen::RowVectorXd sq = (rates.spline_slopes.row(i) - fit_rates.row(first + i)).cwiseAbs2();
    squares.row(w) += sq;
    fourth.row(w) += sq.cwiseAbs2();
    samples[w] += 1.0;
    inverse_h2[w] += 1.0 / (h * h);
  }
  const std::vector<Eigen::Index> starts = WindowStarts(owner, count);
  for (Eigen::Index k = 0; k < count; ++k) {
    // Only an unresolved window's samples can go to the local rate (ChooseLocalSamples).
    const CurveWindow& window = JudgingWindow(windows, static_cast<size_t>(k), d);
    if (window.verdict != WindowVerdict::kUnresolved || window.residual_rms.size() != d) continue;
    const Eigen::Index a = std::max<Eigen::Index>(0, k - kPooledWindows), b = std::min(count - 1, k + kPooledWindows);
    const double pooled = samples.segment(a, b - a + 1).sum();
    if (pooled < kMinHeldOut) continue;
    const double mean_inverse_h2 = inverse_h2.segment(a, b - a + 1).sum() / pooled;
    const Eigen::VectorXd pooled_sigma = NoiseOver(noise, first, starts, a, b);
    const Eigen::VectorXd sigma = NoiseOver(noise, first, starts, k, k);
    for (Eigen::Index c = 0; c < d; ++c) {
      const double departure = squares.col(c).segment(a, b - a + 1).sum() / pooled;
      const double spline_noise = kSplineNoiseGain * pooled_sigma[c] * pooled_sigma[c] * mean_inverse_h2;
      const double spread = fourth.col(c).segment(a, b - a + 1).sum() / pooled - departure * departure;
      const double se = std::sqrt(std::max(0.0, spread) / pooled);
      if (!(departure - kDepartureMargin * se > 2.0 * spline_noise)) continue;
      if (!(window.samples > window.degrees[static_cast<size_t>(c)] + 1)) continue;
      const double missed = MissedMotion(window, c, sigma[c] * sigma[c]);
      departs[static_cast<size_t>(k * d + c)] =
          missed * std::numbers::pi * std::numbers::pi * mean_inverse_h2 >= departure - spline_noise;
    }
  }
  return departs;
}

// The noise variance of a window's rate over σ², per coordinate at its degree: the mean over its
// core's samples (at most kNoiseProbes, evenly spread) of s²·T'(x_i)ᵀG⁻¹T'(x_i), G the normal
// matrix of its samples and s the interval's derivative scale. Zero where G is singular.
Eigen::VectorXd RateNoiseGains(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, const CurveWindow& window) {
  const auto d = static_cast<Eigen::Index>(window.degrees.size());
  Eigen::VectorXd gains = Eigen::VectorXd::Zero(d);
  if (d == 0) return gains;
  const int top = *std::max_element(window.degrees.begin(), window.degrees.end());
  const auto at = [&](double x) { return std::lower_bound(t.data(), t.data() + t.size(), x) - t.data(); };
  const Eigen::Index first = at(window.fit_begin);
  const Eigen::Index last = std::upper_bound(t.data(), t.data() + t.size(), window.fit_end) - t.data();
  const Eigen::Index core_first = at(window.core_begin), core_last = at(window.core_end);
  if (top < 1 || core_last <= core_first || last - first <= top) return gains;
  const std::optional<NestedCholesky> cholesky = FactorWindow(t, z, window);
  if (!cholesky) return gains;
  const Interval& interval = window.series.interval;
  const Eigen::Index count = core_last - core_first, probes = std::min(count, kNoiseProbes);
  Eigen::MatrixXd derivatives(top + 1, probes);
  for (Eigen::Index q = 0; q < probes; ++q) {
    ChebyshevSlopes(interval.ToUnit(t[core_first + q * count / probes]), interval.DerivativeScale(), derivatives.col(q));
  }
  const Eigen::MatrixXd whitened = cholesky->Whiten(top, derivatives);
  for (Eigen::Index c = 0; c < d; ++c) {
    const int degree = window.degrees[static_cast<size_t>(c)];
    if (degree >= 1) gains[c] = whitened.topRows(degree + 1).colwise().squaredNorm().mean();
  }
  return gains;
}

// The interpolating spline's weights at sample i (1 ≤ i ≤ n − 2) of a segment (from `first`, n
// samples), on its samples p0 − 1 .. p1 + 1 (p0 = max(1, i − kSplineReach), p1 = min(n − 2, i +
// kSplineReach)): the row of A⁻¹B at i for the tridiagonal system of its slopes (SplineSlopes),
// A⁻ᵀe_i solved over kSplineReach samples on either side (its weights fall by 0.27 per sample at
// even spacing: 4e-5 at the patch's edge, where the slopes are held).
Eigen::VectorXd SplineWeights(const Eigen::VectorXd& t, Eigen::Index first, Eigen::Index n, Eigen::Index i) {
  const Eigen::Index p0 = std::max<Eigen::Index>(1, i - kSplineReach), p1 = std::min(n - 2, i + kSplineReach);
  const Eigen::Index q = p1 - p0 + 1;
  auto step = [&](Eigen::Index r) { return t[first + r + 1] - t[first + r]; };  // h_r: r to r + 1
  // Aᵀy = e_i by Thomas' algorithm. Row r of A is h_r·s_{r−1} + 2(h_{r−1} + h_r)·s_r +
  // h_{r−1}·s_{r+1}, so Aᵀ(r, r − 1) = A(r − 1, r) = h_{r−2} and Aᵀ(r, r + 1) = A(r + 1, r) = h_{r+1}.
  Eigen::VectorXd lower(q), diagonal(q), upper(q), y = Eigen::VectorXd::Zero(q);
  for (Eigen::Index r = 0; r < q; ++r) {
    const Eigen::Index row = p0 + r;
    diagonal[r] = 2.0 * (step(row - 1) + step(row));
    lower[r] = r > 0 ? step(row - 2) : 0.0;
    upper[r] = r + 1 < q ? step(row + 1) : 0.0;
  }
  y[i - p0] = 1.0;
  for (Eigen::Index r = 1; r < q; ++r) {
    const double factor = lower[r] / diagonal[r - 1];
    diagonal[r] -= factor * upper[r - 1];
    y[r] -= factor * y[r - 1];
  }
  y[q - 1] /= diagonal[q - 1];
  for (Eigen::Index r = q - 2; r >= 0; --r) y[r] = (y[r] - upper[r] * y[r + 1]) / diagonal[r];
  // w_s over samples p0 − 1 .. p1 + 1: row r of B is 3(h_r·d_{r−1} + h_{r−1}·d_r), d the slopes.
  Eigen::VectorXd spline = Eigen::VectorXd::Zero(q + 2);
  for (Eigen::Index r = 0; r < q; ++r) {
    const Eigen::Index row = p0 + r;
    const double before = step(row - 1), after = step(row);
    spline[r] += y[r] * -3.0 * after / before;
    spline[r + 1] += y[r] * 3.0 * (after / before - before / after);
    spline[r + 2] += y[r] * 3.0 * before / after;
  }
  return spline;
}

// The noise products at sample i of a segment (from `first`, n samples) of the interpolating
// spline's slopes (SplineWeights) with the candidate rates of ReviseLocalSamples, from their
// weights on the samples: w_x·w_s for the 3-point rate, the 5-point one (where i has two samples
// on either side; the 3-point one's otherwise) and the spline's (|w_s|²), and |w₅ − w_s|².
struct RateWeights {
  RateWeights(const Eigen::VectorXd& t, Eigen::Index first, Eigen::Index n, Eigen::Index i) {
    const Eigen::Index p0 = std::max<Eigen::Index>(1, i - kSplineReach);
    const Eigen::VectorXd spline = SplineWeights(t, first, n, i);
    spline_norm = spline.squaredNorm();
    // w·w_s for the weights of the polynomial through samples i − half .. i + half (the 3-point
    // rate: CentredRate's; the 5-point one: LagrangeRate's), and |w|².
    auto product = [&](Eigen::Index half, double* norm) {
      const Eigen::VectorXd weights = LagrangeWeights(t, first + i, first + i - half, first + i + half);
      *norm = weights.squaredNorm();
      return weights.dot(spline.segment(i - half - (p0 - 1), 2 * half + 1));
    };
    double three_norm = 0.0, five_norm = 0.0;
    const double three = product(1, &three_norm);
    has_five = i >= 2 && i + 2 < n;
    const double five = has_five ? product(2, &five_norm) : three;
    if (!has_five) five_norm = three_norm;
    spline_products[kThree] = three;
    spline_products[kFive] = five;
    spline_products[kSplineSlopes] = spline_norm;
    five_departure = five_norm + spline_norm - 2.0 * five;
  }

  std::array<double, kCandidates> spline_products{};
  double spline_norm = 0.0, five_departure = 0.0;
  bool has_five = false;
};

// Whether the mean per sample of the gains summed per window over windows a..b (`gains`, over
// `samples` each) exceeds `threshold` by kGainSignificance standard errors, taken from the scatter
// of the windows' means (the spline's noise correlates neighbouring samples' gains).
bool GainStandsOut(const Eigen::Ref<const Eigen::VectorXd>& gains, const Eigen::VectorXd& samples, Eigen::Index a,
                   Eigen::Index b, double threshold) {
  double sum = 0.0, total = 0.0, windows = 0.0;
  for (Eigen::Index j = a; j <= b; ++j) {
    if (!(samples[j] > 0.0)) continue;
    sum += gains[j], total += samples[j], windows += 1.0;
  }
  if (windows < 3.0) return false;
  const double mean = sum / total;
  double spread = 0.0;
  for (Eigen::Index j = a; j <= b; ++j) {
    if (samples[j] > 0.0) spread += (gains[j] / samples[j] - mean) * (gains[j] / samples[j] - mean);
  }
  return mean - kGainSignificance * std::sqrt(spread / (windows - 1.0) / windows) > threshold;
}

// The local runs of a segment's samples [first, first + n): maximal stretches of samples local in
// some coordinate (`local`, n x d), with a sample of the fit on either side, carrying the samples'
// values and local rates (the 5-point rate where `five`, the spline's slopes where `spline`, the
// 3-point rate otherwise) in the local coordinates and the fit's (`fit_values`, `fit_rates`, at
// the segment's samples) in the others.
std::vector<LocalRun> BuildRuns(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, Eigen::Index first, Eigen::Index n,
                                const Flags& local, const Flags& five, const Flags& spline,
                                const Eigen::MatrixXd& fit_values, const Eigen::MatrixXd& fit_rates,
                                const NoiseProfile& noise) {
  std::vector<LocalRun> runs;
  const Eigen::Index d = z.cols();
  const Eigen::VectorXd h = t.segment(first + 1, n - 1) - t.segment(first, n - 1);
  Eigen::MatrixXd slopes = Eigen::MatrixXd::Zero(n - 1, d);
  for (Eigen::Index j = 0; j + 1 < n; ++j) {
    if (h[j] > 0.0) slopes.row(j) = (z.row(first + j + 1) - z.row(first + j)) / h[j];
  }
  const auto usable = UsableSlopes(h, slopes, noise, first);
  // The derivative at sample i of the quadratic through it and its neighbours, from usable slopes.
  auto rate = [&](Eigen::Index i, Eigen::Index c) {
    if (five(i, c) && i >= 2 && i + 2 < n && usable(i - 2, c) && usable(i - 1, c) && usable(i, c) && usable(i + 1, c)) {
      return LagrangeRate(t, z, first + i, c, first + i - 2, first + i + 2);
    }
    const bool left = i >= 1 && usable(i - 1, c), right = i + 1 < n && usable(i, c);
    if (left && right) return CentredRate(h[i - 1], slopes(i - 1, c), h[i], slopes(i, c));
    // Beside a close step (Close), the quadratic through the sample, its other neighbour and the
    // sample past its close partner.
    if (left && i + 2 < n && Close(h, i) && usable(i + 1, c)) {
      return CentredRate(h[i - 1], slopes(i - 1, c), h[i] + h[i + 1], (z(first + i + 2, c) - z(first + i, c)) / (h[i] + h[i + 1]));
    }
    if (right && i >= 2 && Close(h, i - 1) && usable(i - 2, c)) {
      return CentredRate(h[i - 2] + h[i - 1], (z(first + i, c) - z(first + i - 2, c)) / (h[i - 2] + h[i - 1]), h[i],
                         slopes(i, c));
    }
    // At a segment's end, where the window's stencil is of higher order than the quadratic's, the
    // quintic's through the end sample and the next five: a one-sided stencil's error constant is
    // several times the centred one's of the same order, and one order more makes up for it. Only
    // over evenly spaced samples (steps within kOneSidedSpread of each other): across a gap the
    // quintic carries the far samples' curvature back to the end sample (a TUM fr2/desk ground
    // truth's samples beside holes of 20–300 ms: 9.5, 5.0 and 16.8 m/s against a motion under 1 m/s).
    const bool higher = five(i, c) || spline(i, c);
    auto even = [&](Eigen::Index from) {
      const auto steps = h.segment(from, kOneSided);
      return steps.maxCoeff() <= kOneSidedSpread * steps.minCoeff() + kStampResolution;
    };
    if (higher && i == 0 && n > kOneSided && usable.col(c).head(kOneSided).all() && even(0)) {
      return LagrangeRate(t, z, first, c, first, first + kOneSided);
    }
    if (higher && i == n - 1 && n > kOneSided && usable.col(c).segment(n - 1 - kOneSided, kOneSided).all() &&
        even(n - 1 - kOneSided)) {
      return LagrangeRate(t, z, first + i, c, first + n - 1 - kOneSided, first + n - 1);
    }
    if (right) {
      if (i + 2 < n && usable(i + 1, c)) return EndRate(h[i], slopes(i, c), h[i + 1], slopes(i + 1, c));
      return slopes(i, c);
    }
    if (left) {
      if (i >= 2 && usable(i - 2, c)) return EndRate(h[i - 1], slopes(i - 1, c), h[i - 2], slopes(i - 2, c));
      return slopes(i - 1, c);
    }
    // A displaced sample (both of its slopes left out): the secant across it.
    if (i >= 1 && i + 1 < n && h[i - 1] > 0.0 && h[i] > 0.0 && !Close(h, i - 1) && !Close(h, i)) {
      return (z(first + i + 1, c) - z(first + i - 1, c)) / (h[i - 1] + h[i]);
    }
    return fit_rates(first + i, c);
  };

  for (Eigen::Index i = 0; i < n;) {
    if (!local.row(i).any()) {
      ++i;
      continue;
    }
    Eigen::Index end = i;
    while (end < n && local.row(end).any()) ++end;
    // Samples [begin, stop): the local ones and a sample of the fit on either side.
    const Eigen::Index begin = std::max<Eigen::Index>(0, i - 1), stop = std::min(n, end + 1);
    LocalRun run;
    run.values.resize(stop - begin, d);
    run.rates.resize(stop - begin, d);
    std::vector<Eigen::Index> index;  // the sample of each row
    for (Eigen::Index k = begin; k < stop; ++k) {
      // A sample at the stamp of the one before it adds no interval (the first one stays).
      if (!run.times.empty() && !(t[first + k] > run.times.back())) continue;
      const auto r = static_cast<Eigen::Index>(run.times.size());
      run.times.push_back(t[first + k]);
      index.push_back(k);
      for (Eigen::Index c = 0; c < d; ++c) {
        if (local(k, c)) {
          run.values(r, c) = z(first + k, c);
          run.rates(r, c) = rate(k, c);
        } else {
          run.values(r, c) = fit_values(first + k, c);
          run.rates(r, c) = fit_rates(first + k, c);
        }
      }
    }
    // Where the spline's slopes were chosen: maximal stretches of inner rows whose slopes on either
    // side are usable, clamped at the rates of the rows around them.
    const auto rows = static_cast<Eigen::Index>(run.times.size());
    for (Eigen::Index c = 0; c < d; ++c) {
      auto splined = [&](Eigen::Index r) {
        const Eigen::Index k = index[static_cast<size_t>(r)];
        return r >= 1 && r + 1 < rows && spline(k, c) && local(k, c) && k >= 1 && usable(k - 1, c) && k + 1 < n &&
               usable(k, c) && index[static_cast<size_t>(r - 1)] == k - 1 && index[static_cast<size_t>(r + 1)] == k + 1;
      };
      for (Eigen::Index r = 1; r + 1 < rows;) {
        if (!splined(r)) {
          ++r;
          continue;
        }
        Eigen::Index b = r;
        while (b + 1 < rows - 1 && splined(b + 1)) ++b;
        SplineSlopes(run.times, run.values.col(c).head(rows), r, b, run.rates.col(c).head(rows));
        r = b + 1;
      }
    }
    i = end;
    if (run.times.size() < 2) continue;  // no interval to interpolate over
    run.values.conservativeResize(static_cast<Eigen::Index>(run.times.size()), d);
    run.rates.conservativeResize(static_cast<Eigen::Index>(run.times.size()), d);
    runs.push_back(std::move(run));
  }
  return runs;
}

}  // namespace

LocalSamples ChooseLocalSamples(const Eigen::VectorXd& t, Eigen::Index first, Eigen::Index last,
                                const CurveSegment& segment, const LocalRates& rates, const Eigen::MatrixXd& fit_rates,
                                const NoiseProfile& noise, double lack_of_fit_limit) {
  const Eigen::Index n = last - first, d = fit_rates.cols();
  // Local samples and coordinates: in the core of a window that clearly missed motion there; and
  // those whose rate is the 5-point one, and the spline's (UnderResolvedRates).
  LocalSamples chosen{Flags::Constant(n, d, false), Flags::Constant(n, d, false), Flags::Constant(n, d, false),
                      Flags::Constant(n, d, false)};
  if (n < 3 || segment.windows.empty()) return chosen;
  Flags& local = chosen.local;
  Flags& five = chosen.five;
  Flags& spline = chosen.spline;
  const std::vector<CurveWindow>& windows = segment.windows;
  const std::vector<bool> departs = DepartsFromSpline(t, first, n, segment, rates, fit_rates, noise);
  const std::vector<Eigen::Index> owner = SampleWindows(t, first, n, windows);
  const std::vector<Eigen::Index> starts = WindowStarts(owner, static_cast<Eigen::Index>(windows.size()));
  Eigen::MatrixXd window_sigma(static_cast<Eigen::Index>(windows.size()), d);
  for (Eigen::Index k = 0; k < window_sigma.rows(); ++k) window_sigma.row(k) = NoiseOver(noise, first, starts, k, k).transpose();
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto w = static_cast<size_t>(owner[static_cast<size_t>(i)]);
    const CurveWindow& window = JudgingWindow(windows, w, d);
    if (window.lack_of_fit.size() != d) continue;
    const bool unresolved = window.verdict == WindowVerdict::kUnresolved;
    for (Eigen::Index c = 0; c < d; ++c) {
      const auto k = static_cast<Eigen::Index>(w);
      // An unresolved window that interpolates its samples (no freedom left for the residual test)
      // shows nothing better than the samples' own interpolant, whose rate is far better conditioned.
      const double dof = window.samples - window.degrees[static_cast<size_t>(c)] - 1.0;
      const bool interpolates = dof <= 0.0;
      const double variance = window.residual_rms[c] * window.residual_rms[c] * window.samples / std::max(dof, 1.0);
      const double sigma = window_sigma(static_cast<Eigen::Index>(w), c);
      const bool misses_motion = window.lack_of_fit[c] > lack_of_fit_limit && variance >= 2.0 * sigma * sigma;
      local(i, c) = (unresolved && (interpolates || misses_motion || departs[static_cast<size_t>(k * d + c)])) ||
                    rates.under_resolved(k, c);
      five(i, c) = rates.stencil(k, c) == 5;
      spline(i, c) = rates.stencil(k, c) == kSpline;
      // At the segment's ends these say whether the end sample takes the one-sided quintic
      // (BuildLocalRuns).
      if ((i == 0 || i == n - 1) && !rates.one_sided_quintic(k, c)) five(i, c) = spline(i, c) = false;
      chosen.modelled(i, c) = local(i, c) && rates.modelled(k, c);
    }
  }
  return chosen;
}

std::vector<LocalRun> BuildLocalRuns(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, Eigen::Index first,
                                     Eigen::Index last, const LocalSamples& chosen, const Eigen::MatrixXd& fit_values,
                                     const Eigen::MatrixXd& fit_rates, const NoiseProfile& noise) {
  if (last - first < 3 || !chosen.local.any()) return {};
  return BuildRuns(t, z, first, last - first, chosen.local, chosen.five, chosen.spline, fit_values, fit_rates, noise);
}

bool ReviseLocalSamples(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, Eigen::Index first, Eigen::Index last,
                        const CurveSegment& segment, const LocalRates& rates, const Eigen::MatrixXd& fit_rates,
                        const NoiseProfile& noise, const std::vector<LocalRun>& regression, double level_dof,
                        LocalSamples* chosen) {
  const Eigen::Index n = last - first, d = z.cols();
  // σ² at the end of its range that counts against a change: a level read low makes the fit's rate
  // noise, which the gain credits to it, look smaller than the local rates' (a 1 s clip whose σ
  // read 27 % low went to the 3-point rate and followed its noise).
  const double raised = level_dof > 0.0 ? 1.0 + kGainSignificance * std::sqrt(2.0 / level_dof) : 1.0;
  const std::vector<CurveWindow>& windows = segment.windows;
  const auto count = static_cast<Eigen::Index>(windows.size());
  if (n < 5 || count == 0 || rates.spline_slopes.rows() != n || rates.three_rates.rows() != n) return false;
  // The samples and coordinates open to a new rate: those the local regression left, except local
  // ones whose stencil the held-out errors' model chose knowing the motion's frequency
  // (LocalSamples::modelled: their orders fell; without noise the spline's bias is what the
  // comparison below would see) and samples whose 5-point stencil holds a close step (Close: their
  // local rate is another).
  const std::vector<Eigen::Index> owner = SampleWindows(t, first, n, windows);
  const Eigen::VectorXd steps = t.segment(first + 1, n - 1) - t.segment(first, n - 1);
  Flags open = Flags::Constant(n, d, false);
  for (Eigen::Index i = 1; i + 1 < n; ++i) {
    bool close = false;
    for (Eigen::Index j = std::max<Eigen::Index>(0, i - 2); j <= std::min(n - 2, i + 1); ++j) close = close || Close(steps, j);
    if (close || !(steps[i - 1] > 0.0) || !(steps[i] > 0.0)) continue;
    for (Eigen::Index c = 0; c < d; ++c) {
      open(i, c) = !chosen->modelled(i, c);
    }
  }
  for (const LocalRun& run : regression) {
    const auto [from, to] = SamplesOf(t, first, n, run);
    if (to > from) open.middleRows(from, to - from).setConstant(false);
  }
  const std::vector<Eigen::Index> starts = WindowStarts(owner, count);
  Eigen::MatrixXd window_sigma(count, d);
  for (Eigen::Index k = 0; k < count; ++k) window_sigma.row(k) = NoiseOver(noise, first, starts, k, k).transpose();
  // The fit's rate noise |w|² per window near an unresolved one (RateNoiseGains).
  std::vector<char> near(static_cast<size_t>(count), 0);
  for (Eigen::Index k = 0; k < count; ++k) {
    if (JudgingWindow(windows, static_cast<size_t>(k), d).verdict != WindowVerdict::kUnresolved) continue;
    for (Eigen::Index j = std::max<Eigen::Index>(0, k - kPooledGainWindows); j <= std::min(count - 1, k + kPooledGainWindows); ++j) {
      near[static_cast<size_t>(j)] = 1;
    }
  }
  Eigen::MatrixXd fit_noise = Eigen::MatrixXd::Zero(count, d);
  for (Eigen::Index j = 0; j < count; ++j) {
    if (!near[static_cast<size_t>(j)]) continue;
    const Eigen::VectorXd rate_noise = RateNoiseGains(t, z, windows[static_cast<size_t>(j)]);
    if (rate_noise.size() == d) fit_noise.row(j) = rate_noise.transpose();
  }
  // Per window and coordinate, over its core's open samples: per candidate rate r_x, Σ (r_s − r_x)²,
  // Σ σ²(2w_x·w_s − |w_s|²) (the rest of its squared error) and its gain over the samples' present
  // rate r (the fit's, or the local stencil's), Σ (r_s − r)² − (r_s − r_x)² + 2σ²(w·w_s − w_x·w_s)
  // (w·w_s ≈ |w|² for the fit: the spline's slopes follow the window's smooth weights);
  // Σ σ²|w_s − w₅|²; at the fit's samples Σ (r_s − r)², Σ σ²|w_s|² and their count; the open
  // samples' count;
  // and over all its interior samples, their count and Σ 1/h² (h half the span of a sample's
  // neighbours).
  std::array<Eigen::MatrixXd, kCandidates> squares, noises, gains;
  for (Eigen::Index x = 0; x < kCandidates; ++x) squares[x] = noises[x] = gains[x] = Eigen::MatrixXd::Zero(count, d);
  Eigen::MatrixXd counted = Eigen::MatrixXd::Zero(count, d), five_noise = counted;
  Eigen::MatrixXd fit_departures = counted, fit_spline_noise = counted, fit_counted = counted;
  Eigen::VectorXd samples = Eigen::VectorXd::Zero(count), inverse_h2 = samples;
  for (Eigen::Index i = 1; i + 1 < n; ++i) {
    const Eigen::Index w = owner[static_cast<size_t>(i)];
    samples[w] += 1.0;
    const double h = 0.5 * (t[first + i + 1] - t[first + i - 1]);
    inverse_h2[w] += 1.0 / (h * h);
    if (!open.row(i).any()) continue;
    const RateWeights weights(t, first, n, i);
    for (Eigen::Index c = 0; c < d; ++c) {
      if (!open(i, c)) continue;
      counted(w, c) += 1.0;
      // The candidates' rates: the 3-point one, the 5-point one (the 3-point one beside the
      // ends), the spline's slopes.
      const double spline = rates.spline_slopes(i, c), three = rates.three_rates(i, c);
      const double five = weights.has_five ? LagrangeRate(t, z, first + i, c, first + i - 2, first + i + 2) : three;
      std::array<double, kCandidates> candidates{};
      candidates[kThree] = three, candidates[kFive] = five, candidates[kSplineSlopes] = spline;
      const Eigen::Index present = !chosen->local(i, c)   ? -1
                                   : chosen->five(i, c)   ? kFive
                                   : chosen->spline(i, c) ? kSplineSlopes
                                                          : kThree;
      const double rate = present < 0 ? fit_rates(first + i, c) : candidates[static_cast<size_t>(present)];
      const double variance = window_sigma(w, c) * window_sigma(w, c);
      const double shared = present < 0 ? fit_noise(w, c) : weights.spline_products[static_cast<size_t>(present)];
      const double departure = std::pow(spline - rate, 2);
      for (Eigen::Index x = 0; x < kCandidates; ++x) {
        const double square = std::pow(spline - candidates[static_cast<size_t>(x)], 2);
        const double product = weights.spline_products[static_cast<size_t>(x)];
        squares[x](w, c) += square;
        noises[x](w, c) += variance * (2.0 * product - weights.spline_norm);
        gains[x](w, c) += departure - square + 2.0 * variance * (shared < product ? raised : 1.0) * (shared - product);
      }
      five_noise(w, c) += variance * weights.five_departure;
      if (present < 0) {
        fit_departures(w, c) += departure;
        fit_spline_noise(w, c) += variance * weights.spline_norm;
        fit_counted(w, c) += 1.0;
      }
    }
  }
  bool changed = false;
  for (Eigen::Index k = 0; k < count; ++k) {
    const CurveWindow& window = JudgingWindow(windows, static_cast<size_t>(k), d);
    if (window.verdict != WindowVerdict::kUnresolved || window.residual_rms.size() != d || !(samples[k] > 0.0)) continue;
    const Eigen::Index a = std::max<Eigen::Index>(0, k - kPooledGainWindows);
    const Eigen::Index b = std::min(count - 1, k + kPooledGainWindows), pooled_count = b - a + 1;
    const double mean_inverse_h2 = inverse_h2.segment(a, pooled_count).sum() / samples.segment(a, pooled_count).sum();
    const Eigen::Index core_begin = std::max<Eigen::Index>(1, starts[static_cast<size_t>(k)]);
    const Eigen::Index core_end = std::min(n - 1, starts[static_cast<size_t>(k + 1)]);
    for (Eigen::Index c = 0; c < d; ++c) {
      const double open_pooled = counted.col(c).segment(a, pooled_count).sum();
      if (!(counted(k, c) > 0.0) || open_pooled < kMinHeldOut) continue;
      if (!(window.samples > window.degrees[static_cast<size_t>(c)] + 1)) continue;
      auto pooled = [&](const Eigen::MatrixXd& sums) { return sums.col(c).segment(a, pooled_count).sum(); };
      // The spline's slopes are a reference of little bias where the 5-point rate, whose bias
      // exceeds theirs at every frequency (15 % of a tone's rate at a quarter of the rate, against
      // 4.5 %), departs from them by little more than their noise, σ²|w₅ − w_s|² (0.079·σ²/h² at
      // even spacing): up to kReferenceNoise times that. Where it departs by more, the biases
      // decide the comparison and the spline's own could (noise-free motion).
      if (pooled(squares[kFive]) > kReferenceNoise * pooled(five_noise)) continue;
      // With the spline's slopes as the reference, a candidate's squared rate error is its mean
      // departure from them plus σ²(2·w_x·w_s − |w_s|²). The candidate of least error replaces the
      // present rate where its gain stands out by two standard errors.
      Eigen::Index best = 0;
      double least = std::numeric_limits<double>::infinity();
      for (Eigen::Index x = 0; x < kCandidates; ++x) {
        const double error = pooled(squares[x]) + pooled(noises[x]);
        if (error < least) least = error, best = x;
      }
      if (!GainStandsOut(gains[best].col(c), counted.col(c), a, b, 0.0)) continue;
      // A fit's samples also need the window's missed motion to be able to hold its departure
      // from the spline's slopes less their noise (DepartsFromSpline).
      if (fit_counted(k, c) > 0.0) {
        const double missed = MissedMotion(window, c, window_sigma(k, c) * window_sigma(k, c));
        const double bias = (fit_departures(k, c) - fit_spline_noise(k, c)) / fit_counted(k, c);
        if (missed * std::numbers::pi * std::numbers::pi * mean_inverse_h2 < bias) continue;
      }
      for (Eigen::Index i = core_begin; i < core_end; ++i) {
        if (!open(i, c)) continue;
        changed = changed || !chosen->local(i, c) || chosen->five(i, c) != (best == kFive) ||
                  chosen->spline(i, c) != (best == kSplineSlopes);
        chosen->local(i, c) = true;
        chosen->five(i, c) = best == kFive;
        chosen->spline(i, c) = best == kSplineSlopes;
      }
    }
  }
  return changed;
}

std::vector<char> NoisyLocalSamples(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, Eigen::Index first, Eigen::Index n,
                                    const LocalSamples& chosen, const NoiseProfile& noise) {
  const Eigen::Index d = z.cols();
  Eigen::VectorXd differences = Eigen::VectorXd::Zero(d), noise_share = Eigen::VectorXd::Zero(d);
  for (Eigen::Index i = 2; i + 2 < n; ++i) {
    if (!chosen.local.row(i).any()) continue;
    const Eigen::VectorXd three = LagrangeWeights(t, first + i, first + i - 1, first + i + 1);
    Eigen::VectorXd difference = LagrangeWeights(t, first + i, first + i - 2, first + i + 2);
    difference.segment(1, 3) -= three;
    const Eigen::VectorXd sigma = noise.Over(first + i, 1);
    for (Eigen::Index c = 0; c < d; ++c) {
      if (!chosen.local(i, c)) continue;
      const double rate = difference.dot(z.col(c).segment(first + i - 2, 5));
      differences[c] += rate * rate;
      noise_share[c] += sigma[c] * sigma[c] * difference.squaredNorm();
    }
  }
  std::vector<char> noisy(static_cast<size_t>(d), 0);
  for (Eigen::Index c = 0; c < d; ++c) noisy[static_cast<size_t>(c)] = differences[c] > 0.0 && differences[c] <= kNoisyLocalRates * noise_share[c];
  return noisy;
}

std::pair<Eigen::Index, Eigen::VectorXd> LocalRateWeights(const Eigen::VectorXd& t, Eigen::Index first, Eigen::Index n,
                                                          const LocalSamples& chosen, Eigen::Index i, Eigen::Index c) {
  if (chosen.spline(i, c) && i >= 1 && i + 2 <= n - 1) {
    return {std::max<Eigen::Index>(1, i - kSplineReach) - 1, SplineWeights(t, first, n, i)};
  }
  const Eigen::Index half = chosen.five(i, c) && i >= 2 && i + 2 < n ? 2 : 1;
  const Eigen::Index lo = std::max<Eigen::Index>(0, std::min(i - half, n - 1 - 2 * half));
  return {lo, LagrangeWeights(t, first + i, first + lo, first + lo + 2 * half)};
}

}  // namespace cheval::cheb::internal

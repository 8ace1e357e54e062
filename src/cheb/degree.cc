#include "cheval/cheb/degree.h"

#include "noise_profile.h"
#include "work_queue.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <vector>

namespace cheval::cheb {

int StandardChop(const Eigen::Ref<const Eigen::VectorXd>& coefficients, double tol) {
  const int n = static_cast<int>(coefficients.size());
  if (tol >= 1.0) return 1;
  if (n < 17) return n;
  // Step 1: the monotone envelope m_j = max_{k >= j} |c_k|, normalised by m_0.
  std::vector<double> envelope(n);
  envelope[n - 1] = std::abs(coefficients[n - 1]);
  for (int j = n - 2; j >= 0; --j) envelope[j] = std::max(std::abs(coefficients[j]), envelope[j + 1]);
  const double largest = envelope[0];
  if (largest == 0.0) return 1;
  for (double& e : envelope) e /= largest;

  // Step 2: the first plateau point j (1-based as in the paper): the envelope at j2 = round(1.25 j + 5)
  // has not dropped much below its value at j, measured against log(tol).
  int plateau_point = 0, j2 = 0;
  for (int j = 2; j <= n; ++j) {
    j2 = static_cast<int>(std::lround(1.25 * j + 5.0));
    if (j2 > n) return n;  // no plateau: not resolved
    const double e1 = envelope[j - 1], e2 = envelope[j2 - 1];
    const double r = 3.0 * (1.0 - std::log(e1) / std::log(tol));
    if (e1 == 0.0 || e2 / e1 > r) {
      plateau_point = j - 1;
      break;
    }
  }
  if (plateau_point == 0) return n;
  if (envelope[plateau_point - 1] == 0.0) return plateau_point;

  // Step 3: cut at the minimum of log10(envelope) plus a linear tilt, before the plateau.
  const double floor = std::pow(tol, 7.0 / 6.0);
  int j3 = 0;
  for (double e : envelope) j3 += e >= floor ? 1 : 0;
  if (j3 < j2) {
    j2 = j3 + 1;
    envelope[j2 - 1] = floor;
  }
  int best = 1;
  double best_value = std::numeric_limits<double>::infinity();
  for (int i = 1; i <= j2; ++i) {
    const double tilt = j2 > 1 ? (-1.0 / 3.0) * std::log10(tol) * (i - 1) / (j2 - 1) : 0.0;
    const double value = std::log10(envelope[i - 1]) + tilt;
    if (value < best_value) best_value = value, best = i;
  }
  return std::max(best - 1, 1);
}

Eigen::VectorXd EstimateNoiseSigma(const Eigen::Ref<const Eigen::MatrixXd>& z, int order) {
  const Eigen::Index m = z.rows();
  Eigen::VectorXd sigma = Eigen::VectorXd::Zero(z.cols());
  if (m <= order) return sigma;
  // C(2k, k): the variance gain of the k-th difference of white noise.
  double gain = 1.0;
  for (int i = 1; i <= order; ++i) gain = gain * (order + i) / i;
  for (Eigen::Index c = 0; c < z.cols(); ++c) {
    Eigen::VectorXd d = z.col(c);
    for (int k = 0; k < order; ++k) {
      for (Eigen::Index i = 0; i + 1 < d.size() - k; ++i) d[i] = d[i + 1] - d[i];
    }
    std::vector<double> magnitudes(static_cast<size_t>(m - order));
    for (size_t i = 0; i < magnitudes.size(); ++i) magnitudes[i] = std::abs(d[static_cast<Eigen::Index>(i)]);
    auto middle = magnitudes.begin() + static_cast<std::ptrdiff_t>(magnitudes.size() / 2);
    std::nth_element(magnitudes.begin(), middle, magnitudes.end());
    sigma[c] = 1.4826 * *middle / std::sqrt(gain);
  }
  return sigma;
}

namespace {

// A higher order's estimate replaces the 4th differences' when it is below it by more than white
// noise's scatter allows: the ratio of the 6th's (8th's) estimate to the 4th's has a standard
// deviation of kRatioSpread6 (kRatioSpread8) / sqrt(m) for white noise of m samples (simulated,
// 400 draws each of m = 100..10,000), and the drop must exceed kDropDeviations of them. Six: a
// higher order may drop by 3.5 of them on pure noise (the sweep's 200 Hz noise at 50 µm, whose
// 8th differences read 10 % below its σ), and a σ read low makes the residual test fail windows
// on noise alone. The drop needed is never more than kMaxMotionDrop (short segments).
constexpr double kRatioSpread6 = 0.67;
constexpr double kRatioSpread8 = 0.90;
constexpr double kDropDeviations = 6.0;
constexpr double kMaxMotionDrop = 0.2;

// A drop is motion in the 4th differences, not chance, only where the orders together say so.
// Motion enough to raise the 4th's estimate raises the 2nd's more (a tone of θ radians per sample
// puts (2 sin(θ/2))^k / sqrt(C(2k, k)) of its amplitude into the k-th; the 2nd's share is the
// larger below θ ≈ 2.4) and the 6th's and 8th's less. The ratio of the 2nd's estimate to the
// 4th's has a standard deviation of kRatioSpread2 / sqrt(n) over n runs of white noise; the
// three ratios' deviations from 1, in those units and signed towards motion, sum to a spread of
// 2.2–2.6 (the 6th's and 8th's correlate at 0.8), and above kMotionEvidence (3 of them; 0.1–0.4 %
// of draws) they are motion (simulated, 2,000–4,000 draws of 17–3,000 samples). Below it the 4th are
// noise, and a higher order's drop is chance: few runs of 6th differences between the dropouts of
// a short recording (a car at 50 Hz under 2 mm read σ 0.3 mm from one run at 0.2x the 4th's).
constexpr double kRatioSpread2 = 0.85;
constexpr double kMotionEvidence = 7.0;

// The magnitudes |Σ w_j z_j| / sqrt(Σ w_j²) of the divided differences of order kRun − 1 of runs
// of kRun consecutive samples (`cut` marks the boundaries a run may not cross), by the run's first
// sample and coordinate, written into `*out` (m x d, already sized; NaN where no usable run starts).
template <int kRun>
void DividedDifferenceMagnitudes(const Eigen::Ref<const Eigen::VectorXd>& t, const Eigen::Ref<const Eigen::MatrixXd>& z,
                                 const std::vector<char>& cut, Eigen::MatrixXd* out) {
  const Eigen::Index m = z.rows(), d = z.cols();
  Eigen::MatrixXd& magnitudes = *out;
  magnitudes.setConstant(std::numeric_limits<double>::quiet_NaN());
  // Weights in a unit time scale (the run's span): only their ratio to their norm matters. A run
  // placed like the one before (to 1e-9 of its span: even sampling) keeps its weights.
  std::array<double, kRun> u{}, placed{}, w{};
  double norm = 0.0;
  bool known = false;
  for (Eigen::Index i = 0; i + kRun <= m; ++i) {
    bool usable = true;
    for (Eigen::Index j = i; j + 1 < i + kRun && usable; ++j) usable = !cut[static_cast<size_t>(j)] && t[j + 1] > t[j];
    if (!usable) continue;
    const double span = t[i + kRun - 1] - t[i];
    bool same = known;
    for (int j = 0; j < kRun; ++j) {
      u[j] = (t[i + j] - t[i]) / span;
      same = same && std::abs(u[j] - placed[j]) <= 1e-9;
    }
    if (!same) {
      norm = 0.0;
      for (int j = 0; j < kRun; ++j) {
        double product = 1.0;
        for (int k = 0; k < kRun; ++k) {
          if (k != j) product *= u[j] - u[k];
        }
        w[j] = 1.0 / product;
        norm += w[j] * w[j];
      }
      norm = std::sqrt(norm);
      placed = u;
      known = true;
    }
    for (Eigen::Index c = 0; c < d; ++c) {
      double sum = 0.0;
      for (int j = 1; j < kRun; ++j) sum += w[j] * (z(i + j, c) - z(i, c));  // Σ w_j = 0
      magnitudes(i, c) = std::abs(sum) / norm;
    }
  }
}

using internal::kMadScale;

// The winsorized scale's cut, in scales: at 2, on white noise's 4th differences of 100 samples the
// scale scatters by 12 % against the median's 16 %, and one sample off by any amount (it spoils 5
// differences) raises it by 13 % at most against the median's 7 % (simulated, 400–4,000 draws;
// EstimateNoiseSigma.AShortRecordingsLevelScattersLessThanTheMedians). At 3 it scatters as little
// but a glitch raises it by 23 %.
constexpr double kWinsorCut = 2.0;

// Huber's scale with a known centre (Huber & Ronchetti 2009, "Robust Statistics", §5.4): the s
// with mean(min(x², (c·s)²)) = β(c)·s², β(c) = E min(X², c²) for X ~ N(0, 1), so that s is σ for
// normal x. Fixed-point iteration from the median's scale `s`, which it converges to monotonically.
double WinsorizedScale(const std::vector<double>& magnitudes, double s) {
  constexpr double c = kWinsorCut;
  const double tail = 0.5 * std::erfc(c / std::sqrt(2.0));                  // P(X > c)
  const double density = std::exp(-0.5 * c * c) / std::sqrt(2.0 * std::numbers::pi);  // φ(c)
  const double beta = (1.0 - 2.0 * tail) - 2.0 * c * density + 2.0 * c * c * tail;
  const double n = static_cast<double>(magnitudes.size());
  for (int iteration = 0; iteration < 100 && s > 0.0; ++iteration) {
    const double cap = c * c * s * s;
    double sum = 0.0;
    for (const double x : magnitudes) sum += std::min(x * x, cap);
    const double next = std::sqrt(sum / (beta * n));
    const bool converged = std::abs(next - s) <= 1e-12 * s;
    s = next;
    if (converged) break;
  }
  return s;
}

// Over n differences of white noise the winsorized scale over the median's has a standard
// deviation of about 1/sqrt(n) (0.19 at n = 30, 0.058 at 290; simulated, 3,000 draws each): above
// 1 + kTailDeviations of them the differences' tails are heavier than white noise's, and they are
// motion, which the median discounts. Short stretches of EuRoC's ground truth (µm of noise,
// vibration in the differences' tails) read 2.3–3x.
constexpr double kTailDeviations = 3.0;

// One order's σ over a stretch of one coordinate: kMadScale · the median of its magnitudes, and
// where asked Huber's scale started from it (zero where no run is usable).
struct OrderScale {
  double median = 0.0, winsorized = 0.0;
  size_t runs = 0;

  // Whether its tails are like white noise's: the winsorized scale within kTailDeviations of the
  // median's.
  bool TailsLikeWhiteNoise() const {
    const double agreement = 1.0 + kTailDeviations / std::sqrt(static_cast<double>(std::max<size_t>(runs, 1)));
    return winsorized <= agreement * median;
  }
};

// The scales of the magnitudes of rows [begin, end) of column c that are not NaN; the winsorized one
// only `with_winsorized`. `scratch` is reused.
OrderScale ScaleOf(const Eigen::MatrixXd& magnitudes, Eigen::Index begin, Eigen::Index end, Eigen::Index c,
                   bool with_winsorized, std::vector<double>* scratch) {
  scratch->clear();
  scratch->reserve(static_cast<size_t>(end - begin));
  for (Eigen::Index i = begin; i < end; ++i) {
    if (!std::isnan(magnitudes(i, c))) scratch->push_back(magnitudes(i, c));
  }
  OrderScale scale;
  scale.runs = scratch->size();
  if (scratch->empty()) return scale;
  scale.median = kMadScale * internal::SelectNonNegative(scratch, scratch->size() / 2);
  if (with_winsorized) scale.winsorized = WinsorizedScale(*scratch, scale.median);
  return scale;
}

}  // namespace

namespace internal {

// Many values are narrowed down by their bits first: those of a non-negative double order as its
// value does, so a count of the values per top 16 bits names the bucket the k-th lies in, and only
// that bucket's values are kept and counted on the next 16 bits; nth_element finishes among the
// few left. A few linear passes instead of nth_element's partitioning, which took most of the
// noise estimate's time on long recordings.
double SelectNonNegative(std::vector<double>* values, size_t k) {
  std::vector<double>& v = *values;
  if (k >= v.size()) throw std::invalid_argument("SelectNonNegative: k beyond the values");
  constexpr size_t kFew = size_t{1} << 14;
  if (v.size() > kFew) {
    std::vector<uint32_t> counts(size_t{1} << 16);
    for (int shift = 48; v.size() > kFew && shift >= 0; shift -= 16) {
      auto digit = [shift](double x) { return static_cast<size_t>((std::bit_cast<uint64_t>(x) >> shift) & 0xffff); };
      std::fill(counts.begin(), counts.end(), 0u);
      for (const double x : v) ++counts[digit(x)];
      size_t bucket = 0, below = 0;
      while (below + counts[bucket] <= k) below += counts[bucket++];
      size_t kept = 0;
      for (const double x : v) {
        if (digit(x) == bucket) v[kept++] = x;
      }
      v.resize(kept);
      k -= below;
    }
  }
  const auto kth = v.begin() + static_cast<std::ptrdiff_t>(k);
  std::nth_element(v.begin(), kth, v.end());
  return *kth;
}

DifferenceMagnitudes::DifferenceMagnitudes(const Eigen::Ref<const Eigen::VectorXd>& t,
                                           const Eigen::Ref<const Eigen::MatrixXd>& z,
                                           const std::vector<Eigen::Index>& breaks, int threads) {
  const Eigen::Index m = z.rows();
  std::vector<char> cut(static_cast<size_t>(std::max<Eigen::Index>(m, 1)), 0);
  for (const Eigen::Index b : breaks) {
    if (b >= 0 && b < m) cut[static_cast<size_t>(b)] = 1;
  }
  // Allocated here, on the caller's thread, so that what they free serves its later allocations
  // (glibc keeps another thread's freed memory for that thread), and first written on the threads
  // (docs/velocity.md, "Speed").
  eighth_.resize(m, z.cols());
  sixth_.resize(m, z.cols());
  fourth_.resize(m, z.cols());
  second_.resize(m, z.cols());
  ParallelFor(4, threads, [&](int order) {
    if (order == 0) DividedDifferenceMagnitudes<9>(t, z, cut, &eighth_);  // the longest first
    if (order == 1) DividedDifferenceMagnitudes<7>(t, z, cut, &sixth_);
    if (order == 2) DividedDifferenceMagnitudes<5>(t, z, cut, &fourth_);
    if (order == 3) DividedDifferenceMagnitudes<3>(t, z, cut, &second_);
  });
  rates_ = Eigen::MatrixXd::Zero(m, z.cols());
  for (Eigen::Index i = 0; i < m; ++i) {
    Eigen::Index a = i, b = i;
    while (a > std::max<Eigen::Index>(0, i - 2) && !cut[static_cast<size_t>(a - 1)]) --a;
    while (b < std::min(m - 1, i + 2) && !cut[static_cast<size_t>(b)]) ++b;
    if (t[b] > t[a]) rates_.row(i) = (z.row(b) - z.row(a)) / (t[b] - t[a]);
    if (!rates_.row(i).allFinite()) rates_.row(i).setZero();  // non-finite values tell no rate
  }
}

Eigen::VectorXd DifferenceMagnitudes::Sigma(Eigen::Index begin, Eigen::Index end) const {
  const Eigen::VectorXd none = Eigen::VectorXd::Constant(fourth_.cols(), -1.0);
  return Estimate(begin, end, none, end - begin < kWinsorizedBelow, /*drops_need_evidence=*/true);
}

Eigen::VectorXd DifferenceMagnitudes::SigmaIfAbove(Eigen::Index begin, Eigen::Index end,
                                                   const Eigen::VectorXd& threshold) const {
  return Estimate(begin, end, threshold, false, /*drops_need_evidence=*/false);
}

Eigen::VectorXd DifferenceMagnitudes::Estimate(Eigen::Index begin, Eigen::Index end, const Eigen::VectorXd& threshold,
                                               bool winsorized, bool drops_need_evidence) const {
  const Eigen::Index d = fourth_.cols();
  const double root_m = std::sqrt(static_cast<double>(std::max<Eigen::Index>(end - begin, 1)));
  const double keep6 = 1.0 - std::min(kMaxMotionDrop, kDropDeviations * kRatioSpread6 / root_m);
  const double keep8 = 1.0 - std::min(kMaxMotionDrop, kDropDeviations * kRatioSpread8 / root_m);
  Eigen::VectorXd sigma(d);
  std::vector<double> scratch;
  for (Eigen::Index c = 0; c < d; ++c) {
    auto scale_of = [&](const Eigen::MatrixXd& magnitudes) {
      return ScaleOf(magnitudes, begin, end, c, winsorized, &scratch);
    };
    // The same scale for the three orders, which are compared: the winsorized where the tails of
    // all three are white noise's. Without it, the higher orders only where the 4th's exceeds the
    // threshold (they only ever lower it).
    const OrderScale fourth_scale = scale_of(fourth_);
    std::optional<OrderScale> sixth_scale, eighth_scale;
    if (winsorized) sixth_scale = scale_of(sixth_), eighth_scale = scale_of(eighth_);
    const bool efficient = winsorized && fourth_scale.TailsLikeWhiteNoise() && sixth_scale->TailsLikeWhiteNoise() &&
                           eighth_scale->TailsLikeWhiteNoise();
    auto chosen = [efficient](const OrderScale& scale) { return efficient ? scale.winsorized : scale.median; };
    const double fourth = chosen(fourth_scale);
    sigma[c] = fourth;
    if (!(fourth > threshold[c])) continue;
    if (!sixth_scale) sixth_scale = scale_of(sixth_), eighth_scale = scale_of(eighth_);
    const double sixth = chosen(*sixth_scale), eighth = chosen(*eighth_scale);
    if (drops_need_evidence) {
      // The evidence that the 4th differences hold motion, in white noise's deviations: the 2nd's
      // estimate above theirs, the 6th's and 8th's below. An order without a usable run adds none.
      auto deviations = [](double change, double spread, size_t runs) {
        return runs == 0 ? 0.0 : change * std::sqrt(static_cast<double>(runs)) / spread;
      };
      const double second = ScaleOf(second_, begin, end, c, /*with_winsorized=*/false, &scratch).median;
      const double rise = second / fourth_scale.median - 1.0;
      const double evidence = deviations(rise, kRatioSpread2, fourth_scale.runs) +
                              deviations(1.0 - sixth / fourth, kRatioSpread6, sixth_scale->runs) +
                              deviations(1.0 - eighth / fourth, kRatioSpread8, eighth_scale->runs);
      if (!(evidence > kMotionEvidence)) continue;  // noise: a higher order below is chance
    }
    // An order without a usable run has no scale, not a scale of 0: between the dropouts of a short
    // recording (segments of 4–7 samples) the 8th differences have none, and σ read 0.
    if (sixth_scale->runs > 0 && sixth < keep6 * fourth) sigma[c] = sixth;
    if (eighth_scale->runs > 0 && eighth < keep8 * fourth) sigma[c] = std::min(sigma[c], eighth);
  }
  return sigma;
}

Eigen::MatrixXi DifferenceMagnitudes::CountsAbove(const Eigen::VectorXd& threshold, Eigen::Index stride) const {
  if (stride < 1) throw std::invalid_argument("DifferenceMagnitudes::CountsAbove: stride below 1");
  const Eigen::Index m = fourth_.rows(), d = fourth_.cols(), rows = (m + stride - 1) / stride + 1;
  Eigen::MatrixXi counts = Eigen::MatrixXi::Zero(rows, 2 * d);
  for (Eigen::Index c = 0; c < d; ++c) {
    int usable = 0, above = 0;
    for (Eigen::Index i = 0; i < m; ++i) {
      const double v = fourth_(i, c);
      if (!std::isnan(v)) {
        ++usable;
        if (kMadScale * v > threshold[c]) ++above;
      }
      if ((i + 1) % stride == 0 || i + 1 == m) {
        const Eigen::Index row = (i + stride) / stride;  // ⌈(i + 1) / stride⌉
        counts(row, 2 * c) = usable;
        counts(row, 2 * c + 1) = above;
      }
    }
  }
  return counts;
}

}  // namespace internal

Eigen::VectorXd EstimateNoiseSigma(const Eigen::Ref<const Eigen::VectorXd>& t, const Eigen::Ref<const Eigen::MatrixXd>& z,
                                   const std::vector<Eigen::Index>& breaks) {
  return internal::DifferenceMagnitudes(t, z, breaks).Sigma(0, z.rows());
}

}  // namespace cheval::cheb

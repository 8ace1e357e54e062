#include "end_caps.h"
#include "local_rates.h"
#include "residual_test.h"
#include "work_queue.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "cheval/cheb/chebyshev.h"
#include "cheval/cheb/fit.h"
#include "cheval/common/error.h"

namespace cheval::cheb::internal {
namespace {

// Candidate caps: samples m from the end, degree p (at most m/4 - 1 from kLongCap samples on),
// and the blending boundary z (in samples from the end: the cap alone up to z/2, blended into the
// end window up to 1.5 z).
constexpr std::array<int, 11> kCapSamples{8, 11, 16, 23, 32, 45, 64, 91, 128, 181, 256};
// Caps of fewer samples may keep only two samples more than their coefficients (m ≥ p + 3, up to
// degree 5 over 8 samples): mid-band motion at 20–50 Hz, whose best Savitzky–Golay window is a
// cubic over 9 samples, and at 20 Hz, 12 samples a period, which only a degree close to the
// samples follows from one side (the pooled artificial ends judge its noise). The samples
// next to a real end can be unlike the artificial ends that choose the cap, and a short cap
// follows them: at a jump they carry its onset, and short caps are not tried there; at a
// recording's end (a landing) one is taken only when its pooled gain is kShortCapMargin times the
// best longer cap's.
constexpr int kLongCap = 16;
constexpr double kShortCapMargin = 2.0;
constexpr std::array<int, 8> kCapDegrees{1, 2, 3, 4, 5, 6, 8, 10};
constexpr std::array<int, 11> kCapBoundaries{4, 6, 8, 11, 16, 23, 32, 45, 64, 91, 128};
// A real end unlike the artificial ends that choose its cap: a candidate's change of the rate there
// is more than this many times its root mean square at them. Over EuRoC MH_05's 272 segments 99.9 %
// of the candidates are below 5.4 (median 0.57), TUM-VI room1's at most 10.5; a stop-and-go segment
// that starts mid-move and then rests gave 50–370 for the low-degree caps its rests chose. Such a
// candidate is refused only where it also fits the real end's samples worse than the end window
// (CapMisfit): at TUM-VI's segment ends, next to noise bursts, the end window's rate is what is off.
// In a short segment the misfit alone refuses a candidate (ChooseCap).
constexpr double kEndLikeness = 5.0;
// Artificial ends per direction (pooled: 2 x 32 one-sided fits per candidate and end; 64 gave the
// same errors on the benchmark within ±0.2 % in geometric mean, at twice the cost).
constexpr int kArtificialEnds = 32;
// Inside a short segment's end window (its middle half, a few dozen samples), 16 gave the same
// errors as 32 on clips of 0.3–2 s (docs/decisions.md) at less cost.
constexpr int kArtificialEndsInWindow = 16;

// Samples read from an end inward as if they were a segment's first ones: τ ≥ 0 (s from the end),
// the values, and the reference velocity d/dτ at the first `offsets` of them (negated when read
// backwards in time).
struct Block {
  Eigen::VectorXd tau;
  Eigen::MatrixXd z, v;
};

Block ReadBlock(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, const VelocityAt& velocity, Eigen::Index start,
                Eigen::Index count, Eigen::Index offsets, bool backwards) {
  Block block{Eigen::VectorXd(count), Eigen::MatrixXd(count, z.cols()), Eigen::MatrixXd(offsets, z.cols())};
  for (Eigen::Index i = 0; i < count; ++i) {
    const Eigen::Index k = backwards ? start - i : start + i;
    block.tau[i] = backwards ? t[start] - t[k] : t[k] - t[start];
    block.z.row(i) = z.row(k);
  }
  const Eigen::MatrixXd v = velocity(backwards ? start - offsets + 1 : start, offsets);
  block.v = backwards ? Eigen::MatrixXd(-v.colwise().reverse()) : v;
  return block;
}

// The least-squares fits of every degree up to `top` to a block's first m samples (one Cholesky),
// and their velocities at the block's first `count` samples.
class OneSidedFits {
 public:
  OneSidedFits(const Block& block, Eigen::Index m, int top, Eigen::Index count)
      : normal_(m * top > kMomentLoopLimit
                    ? BuildNormalEquations(block.tau.head(m), block.z.topRows(m), top, Interval{0.0, block.tau[m - 1]})
                    : SmallNormalEquations(block, m, top)),
        cholesky_(normal_, top),
        derivative_basis_(count, top + 1) {
    const Interval interval{0.0, block.tau[m - 1]};
    Eigen::VectorXd slopes(top + 1);
    for (Eigen::Index j = 0; j < count; ++j) {
      ChebyshevSlopes(interval.ToUnit(block.tau[j]), interval.DerivativeScale(), slopes);
      derivative_basis_.row(j) = slopes.transpose();
    }
  }

  // Velocities at the first `count` samples; coordinate c from the fit of degree degrees[c].
  Eigen::MatrixXd Velocity(const std::vector<int>& degrees, Eigen::Index count) const {
    Eigen::MatrixXd out(count, static_cast<Eigen::Index>(degrees.size()));
    for (Eigen::Index c = 0; c < out.cols(); ++c) {
      const int n = degrees[c] + 1;
      out.col(c).noalias() =
          derivative_basis_.topLeftCorner(count, n).lazyProduct(cholesky_.Solve(degrees[c], normal_.rhs.col(c)));
    }
    return out;
  }
  // The same with every coordinate at one degree.
  Eigen::MatrixXd Velocity(int degree, Eigen::Index count) const {
    return derivative_basis_.topLeftCorner(count, degree + 1).lazyProduct(cholesky_.Solve(degree, normal_.rhs));
  }
 private:
  // Above this many sample-degree products the library's vectorised accumulation is faster.
  static constexpr Eigen::Index kMomentLoopLimit = 2048;
  // The normal equations from Chebyshev moments, G_ij = (S_{i+j} + S_{|i-j|}) / 2 with
  // S_n = Σ T_n(x_i) (fit.h), accumulated directly: for these short fits this beats
  // BuildNormalEquations, whose vectorised accumulation is made for long windows.
  static NormalEquations SmallNormalEquations(const Block& block, Eigen::Index m, int top) {
    NormalEquations normal;
    normal.interval = {0.0, block.tau[m - 1]};
    normal.samples = m;
    const Eigen::Index d = block.z.cols();
    Eigen::VectorXd moments = Eigen::VectorXd::Zero(2 * top + 1), basis(2 * top + 1);
    normal.rhs = Eigen::MatrixXd::Zero(top + 1, d);
    for (Eigen::Index i = 0; i < m; ++i) {
      const double x = normal.interval.ToUnit(block.tau[i]);
      basis[0] = 1.0;
      if (top >= 1) basis[1] = x;
      for (int k = 2; k <= 2 * top; ++k) basis[k] = 2.0 * x * basis[k - 1] - basis[k - 2];
      moments += basis;
      for (Eigen::Index c = 0; c < d; ++c) {
        const double value = block.z(i, c);
        for (int k = 0; k <= top; ++k) normal.rhs(k, c) += basis[k] * value;
      }
    }
    normal.gram.resize(top + 1, top + 1);
    for (int i = 0; i <= top; ++i) {
      for (int j = 0; j <= top; ++j) normal.gram(i, j) = 0.5 * (moments[i + j] + moments[std::abs(i - j)]);
    }
    return normal;
  }

  NormalEquations normal_;
  NestedCholesky cholesky_;
  Eigen::MatrixXd derivative_basis_;  // count x (top + 1)
};

// Weight of the cap at offset j (samples from the end) for boundary z: the curve's blend,
// 1 − s((j − z/2)/z) with s the quintic smoothstep (Curve::Locate with half-width z/2).
double CapWeight(Eigen::Index j, int z) {
  double s = 0, ds = 0, dds = 0;
  Smoothstep((static_cast<double>(j) - 0.5 * z) / z, &s, &ds, &dds);
  return 1.0 - s;
}
Eigen::Index BlendEnd(int z) { return static_cast<Eigen::Index>(std::ceil(1.5 * z)) + 1; }

// A cap candidate and its pooled statistics over the artificial ends, per offset and coordinate:
// a = Σ Δ², b = Σ Δ·e with Δ = v_cap − v_end and e = v_end − v_reference. The blended velocity
// v_end + wΔ has the error e + wΔ, so the cap changes the summed squared error by Σ w²a + 2w·b.
// Where the end window's rate is the reference itself (a segment of one or two windows), e = 0
// and a is the cap's squared error.
struct Candidate {
  int samples = 0, degree = 0;
  Eigen::Index offsets = 0;  // velocities compared at offsets 0..offsets-1
  Eigen::MatrixXd a, b;
  Eigen::ArrayXd misfit;  // per coordinate: CapMisfit's score at the real end
};

struct Choice {
  double gain = 0;  // pooled change of the summed squared velocity error (< 0: the cap helps)
  int samples = 0, boundary = 0;
  std::vector<int> degrees;  // per coordinate; -1 keeps the end window's polynomial
  // False where the artificial ends had too little room to judge the candidates (too short for
  // their one-sided fits, or fewer than 8 of them): no cap was chosen for want of a judgement.
  bool judged = true;
};

// Where the artificial ends of a segment lie: the velocities are compared at samples [lo, hi), where
// the curve's velocity is an interior one, and the one-sided fits read samples [block_lo, block_hi).
struct ArtificialEnds {
  Eigen::Index lo = 0, hi = 0, block_lo = 0, block_hi = 0;
};

// Adds one artificial end's block to the candidates' statistics, with the end window's velocity
// at its offsets.
void Pool(const Block& block, const Eigen::MatrixXd& end_velocity, std::vector<Candidate>& candidates) {
  const Eigen::MatrixXd end_error = end_velocity - block.v;
  std::vector<Eigen::MatrixXd> deltas;
  for (size_t i = 0; i < candidates.size();) {
    const int m = candidates[i].samples;
    size_t j = i;
    while (j < candidates.size() && candidates[j].samples == m) ++j;
    const OneSidedFits fits(block, m, candidates[j - 1].degree, candidates[i].offsets);
    for (; i < j; ++i) {
      const Eigen::Index n = candidates[i].offsets;
      deltas.push_back(fits.Velocity(candidates[i].degree, n) - end_velocity.topRows(n));
    }
  }
  for (size_t i = 0; i < candidates.size(); ++i) {
    const Eigen::Index n = candidates[i].offsets;
    candidates[i].a += deltas[i].cwiseAbs2();
    candidates[i].b += deltas[i].cwiseProduct(end_error.topRows(n));
  }
}

// How much worse than the end window each cap of `degrees` (rows) fits the real end, per coordinate
// (columns): the residual test's score (LackOfFitScore) of the cap's residual over the n samples
// nearest the end, n = min(m, the end window's samples), against the end window's own residual
// there as the level, with the degrees of freedom each spends on them. The cap is fitted to the m
// samples from `begin`, nearest the end at its `front` (or back). Missed motion leaves the cap's
// residual far above the end window's; noise, however large (a burst at the end), leaves both alike.
// Scores of 0 where the samples do not determine the fits.
Eigen::ArrayXXd CapMisfit(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, Eigen::Index begin, Eigen::Index m,
                          bool front, const std::vector<int>& degrees, const CurveWindow& end,
                          Eigen::Index end_samples) {
  const Eigen::Index d = z.cols();
  Eigen::ArrayXXd scores = Eigen::ArrayXXd::Zero(static_cast<Eigen::Index>(degrees.size()), d);
  if (degrees.empty() || static_cast<Eigen::Index>(end.degrees.size()) != d) return scores;
  const int top = degrees.back();
  const Interval interval{t[begin], t[begin + m - 1]};
  const Eigen::Index n = std::min(m, end_samples), near = front ? 0 : m - n;
  // About their mean, so that values far from the origin leave the residuals their precision.
  const Eigen::RowVectorXd mean = z.middleRows(begin, m).colwise().mean();
  const Eigen::MatrixXd values = z.middleRows(begin, m).rowwise() - mean;
  const Eigen::MatrixXd end_residual =
      z.middleRows(begin + near, n) - WindowSeriesAt(end, t.segment(begin + near, n), 0);
  try {
    const NormalEquations normal = BuildNormalEquations(t.segment(begin, m), values, top, interval);
    const NestedCholesky cholesky(normal, top);
    Eigen::VectorXd x(n);
    for (Eigen::Index i = 0; i < n; ++i) x[i] = interval.ToUnit(t[begin + near + i]);
    const auto share = static_cast<double>(n);
    for (size_t k = 0; k < degrees.size(); ++k) {
      const int p = degrees[k];
      const Eigen::MatrixXd residual = values.middleRows(near, n) - EvaluateSeries(cholesky.Solve(p, normal.rhs), x);
      const double cap_dof = share * (1.0 - (p + 1.0) / static_cast<double>(m));
      for (Eigen::Index c = 0; c < d; ++c) {
        const double end_dof = share * (1.0 - (end.degrees[c] + 1.0) / static_cast<double>(end_samples));
        if (!(cap_dof >= 1.0 && end_dof >= 1.0)) continue;
        const double level =
            std::max(std::sqrt(end_residual.col(c).squaredNorm() / end_dof), RoundingFloor(z.col(c).segment(begin, m)));
        scores(static_cast<Eigen::Index>(k), c) =
            LackOfFitScore(residual.col(c).squaredNorm(), level, static_cast<Eigen::Index>(cap_dof), end_dof);
      }
    }
  } catch (const ComputeError&) {
    // Repeated stamps: the cap is not built either (BuildCap).
  }
  return scores;
}

// Chooses the cap of one end (front: the segment's start) at the artificial ends `ends`. A cap is
// compared with the end window's own configuration, fitted one-sidedly at the artificial ends
// too. An end window whose rate is the reference there cannot be, and `end_variance` (offsets x d)
// gives its rate's variance at the real end's samples instead: its error there, but for a bias.
// The real end is the start (`front`) or the end of the segment's samples [segment_first,
// segment_last).
Choice ChooseCap(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, const VelocityAt& velocity,
                 const ArtificialEnds& ends, Eigen::Index segment_samples, const CurveWindow& end,
                 Eigen::Index end_samples, Eigen::Index core_samples, int shortest,
                 const Eigen::MatrixXd* end_variance, bool front, Eigen::Index segment_first,
                 Eigen::Index segment_last) {
  const Eigen::Index d = z.cols(), room = ends.hi - ends.lo, block_room = ends.block_hi - ends.block_lo;
  auto boundary_allowed = [&](int m, int boundary) {
    return 1.5 * boundary <= m - 1 && 2 * boundary <= core_samples &&
           (end_variance == nullptr || BlendEnd(boundary) <= end_variance->rows());
  };
  std::vector<Candidate> candidates;
  Choice unjudged;
  unjudged.judged = false;
  bool cramped = false;  // a candidate left out for the artificial ends' room
  Eigen::Index block_samples = end_variance == nullptr ? end_samples : 0, end_offsets = 0;
  for (const int m : kCapSamples) {
    if (m < shortest) continue;
    if (m > block_room || 2 * m > segment_samples) {
      cramped = cramped || m > block_room;
      break;
    }
    Eigen::Index offsets = 0;
    for (const int boundary : kCapBoundaries) {
      if (boundary_allowed(m, boundary)) offsets = BlendEnd(boundary);
    }
    if (offsets == 0) continue;
    if (offsets > room) {
      cramped = true;
      continue;
    }
    std::vector<int> degrees;
    for (const int p : kCapDegrees) {
      if (m >= kLongCap ? 4 * (p + 1) > m : p + 3 > m) break;
      degrees.push_back(p);
    }
    const Eigen::ArrayXXd misfit =
        CapMisfit(t, z, front ? segment_first : segment_last - m, m, front, degrees, end, end_samples);
    for (size_t k = 0; k < degrees.size(); ++k) {
      const Eigen::MatrixXd zero = Eigen::MatrixXd::Zero(offsets, d);
      candidates.push_back({m, degrees[k], offsets, zero, zero, misfit.row(static_cast<Eigen::Index>(k)).transpose()});
    }
    block_samples = std::max<Eigen::Index>(block_samples, m);
    end_offsets = std::max(end_offsets, offsets);
  }
  if (candidates.empty()) return cramped ? unjudged : Choice{};
  if (block_samples > block_room || end_offsets > room) return unjudged;
  if (end_variance == nullptr && end_offsets > end_samples) return {};

  const int end_top = *std::max_element(end.degrees.begin(), end.degrees.end());
  int pooled = 0;
  for (const bool backwards : {false, true}) {
    // An artificial end's offsets lie in [lo, hi), its block in [block_lo, block_hi).
    const Eigen::Index first = backwards ? std::max(ends.lo + end_offsets, ends.block_lo + block_samples) - 1 : ends.lo;
    const Eigen::Index last = backwards ? ends.hi - 1 : std::min(ends.hi - end_offsets, ends.block_hi - block_samples);
    if (last < first) continue;
    const Eigen::Index span = last - first;
    const Eigen::Index count = std::min<Eigen::Index>(end_variance ? kArtificialEndsInWindow : kArtificialEnds, span + 1);
    for (Eigen::Index k = 0; k < count; ++k) {
      const Eigen::Index start = first + (count > 1 ? k * span / (count - 1) : 0);
      const Block block = ReadBlock(t, z, velocity, start, block_samples, end_offsets, backwards);
      try {
        // Against the reference itself, the end window's error is none.
        const Eigen::MatrixXd end_velocity =
            end_variance != nullptr
                ? block.v
                : OneSidedFits(block, end_samples, end_top, end_offsets).Velocity(end.degrees, end_offsets);
        Pool(block, end_velocity, candidates);
        ++pooled;
      } catch (const ComputeError&) {
        // A singular one-sided fit (repeated stamps): this artificial end is left out for all.
      }
    }
  }
  if (pooled < 8) return unjudged;  // too few artificial ends for pooled errors to be trusted

  // Each candidate's change of the rate at the real end, against the curve's own rate there (a
  // only: Σ Δ² per offset and coordinate), for the test below. Not in a short segment: there the
  // reference is the end window's rate, whose error at the real end is what a cap is for.
  std::vector<Candidate> real;
  if (end_variance == nullptr) {
    try {
      const Block block =
          ReadBlock(t, z, velocity, front ? segment_first : segment_last - 1, block_samples, end_offsets, !front);
      real = candidates;
      for (Candidate& candidate : real) candidate.a.setZero(), candidate.b.setZero();
      Pool(block, block.v, real);
    } catch (const ComputeError&) {
      real.clear();  // a singular one-sided fit at the real end (repeated stamps): no cap is built there either
    }
  }

  Choice best, best_short;
  for (size_t i = 0; i < candidates.size();) {
    const int m = candidates[i].samples;
    size_t j = i;
    while (j < candidates.size() && candidates[j].samples == m) ++j;
    for (const int boundary : kCapBoundaries) {
      if (!boundary_allowed(m, boundary)) continue;
      const Eigen::Index n = BlendEnd(boundary);
      Eigen::VectorXd w(n);
      for (Eigen::Index o = 0; o < n; ++o) w[o] = CapWeight(o, boundary);
      Choice choice{0.0, m, boundary, std::vector<int>(d, -1)};
      // The change of the summed squared error over offsets 0..n-1 of candidate k's coordinate c.
      auto gain_of = [&](size_t k, Eigen::Index c) {
        if (end_variance == nullptr) {
          return w.cwiseAbs2().dot(candidates[k].a.col(c).head(n)) + 2.0 * w.dot(candidates[k].b.col(c).head(n));
        }
        // The cap's pooled squared error against the end window's variance at the real end. The
        // two errors at a sample are not independent, so the blend's is bounded by Cauchy–Schwarz.
        const Eigen::ArrayXd own = end_variance->col(c).head(n).array();
        const Eigen::ArrayXd cap = candidates[k].a.col(c).head(n).array() / pooled;
        const Eigen::ArrayXd blended = (1.0 - w.array()) * own.sqrt() + w.array() * cap.sqrt();
        return (blended.square() - own).sum();
      };
      for (Eigen::Index c = 0; c < d; ++c) {
        // Keeping the end window's polynomial changes nothing, but only a cap within the end
        // window's samples can keep it: re-expanded over a longer interval, the polynomial is
        // extrapolated there (degree 17 over 6 times its span: coefficients 1e13 times its values,
        // whose cancellation left the rate 3,000 m/s off on a 0.5 m/s sine).
        double lowest = m <= end_samples ? 0.0 : std::numeric_limits<double>::infinity();
        for (size_t k = i; k < j; ++k) {
          // A candidate that fits the real end's own samples clearly worse than the end window
          // (CapMisfit) is not taken in this coordinate where the artificial ends cannot vouch for
          // it: in a short segment, whose artificial ends measure it against the end window's own
          // rate, or where it changes the rate at the real end kEndLikeness times more than at them
          // (root mean square, blended).
          if (candidates[k].misfit[c] > kLackOfFitLimit) {
            if (end_variance != nullptr) continue;
            if (!real.empty()) {
              const double typical = w.cwiseAbs2().dot(candidates[k].a.col(c).head(n)) / pooled;
              const double here = w.cwiseAbs2().dot(real[k].a.col(c).head(n));
              if (here > kEndLikeness * kEndLikeness * typical) continue;
            }
          }
          const double gain = gain_of(k, c);
          if (gain < lowest) lowest = gain, choice.degrees[c] = candidates[k].degree;
        }
        choice.gain += lowest;
      }
      Choice& incumbent = m < kLongCap ? best_short : best;
      if (choice.gain < incumbent.gain) incumbent = std::move(choice);
    }
    i = j;
  }
  return best_short.gain < kShortCapMargin * best.gain ? best_short : best;
}

// The cap window of a choice over samples [begin, begin + m) of the segment.
CurveWindow BuildCap(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, Eigen::Index begin, const Choice& choice,
                     const CurveWindow& end) {
  const Eigen::Index m = choice.samples, d = z.cols();
  CurveWindow cap;
  cap.fit_begin = t[begin];
  cap.fit_end = t[begin + m - 1];
  cap.samples = m;
  cap.series.interval = {cap.fit_begin, cap.fit_end};
  const int top = *std::max_element(choice.degrees.begin(), choice.degrees.end());
  std::vector<Eigen::VectorXd> columns(d);
  if (top >= 0) {
    const NormalEquations normal =
        BuildNormalEquations(t.segment(begin, m), z.middleRows(begin, m), top, cap.series.interval);
    const NestedCholesky cholesky(normal, top);
    for (Eigen::Index c = 0; c < d; ++c) {
      if (choice.degrees[c] >= 0) columns[c] = cholesky.Solve(choice.degrees[c], normal.rhs.col(c));
    }
  }
  for (Eigen::Index c = 0; c < d; ++c) {
    if (choice.degrees[c] >= 0) {
      cap.degrees.push_back(choice.degrees[c]);
      continue;
    }
    // The end window's own polynomial, re-expanded exactly on the cap's interval.
    const int n = end.degrees[c];
    cap.degrees.push_back(n);
    columns[c] = Reexpand(end.series.coefficients.col(c).head(n + 1), end.series.interval, cap.series.interval);
  }
  const int rows = *std::max_element(cap.degrees.begin(), cap.degrees.end()) + 1;
  cap.series.coefficients = Eigen::MatrixXd::Zero(rows, d);
  for (Eigen::Index c = 0; c < d; ++c) cap.series.coefficients.col(c).head(columns[c].size()) = columns[c];
  cap.coefficient_magnitudes = cap.series.coefficients.cwiseAbs();
  cap.first_derivative = DerivativeCoefficients(cap.series.coefficients);
  cap.second_derivative = DerivativeCoefficients(cap.first_derivative);
  return cap;
}

// The variance of `window`'s rate at `count` samples from `at` on in direction `step` (±1), per
// coordinate: σ²·dᵀG⁻¹d with the window's σ (`cholesky` its FactorWindow); none without that σ.
std::optional<Eigen::MatrixXd> RateVariance(const Eigen::VectorXd& t, const CurveWindow& window,
                                            const NestedCholesky& cholesky, Eigen::Index at, int step, Eigen::Index count) {
  const auto d = static_cast<Eigen::Index>(window.degrees.size());
  if (window.noise_sigma.size() != d) return std::nullopt;
  Eigen::MatrixXd variance(count, d);
  for (Eigen::Index o = 0; o < count; ++o) {
    variance.row(o) = RateVarianceFactor(cholesky, window.series.interval, window.degrees, t[at + step * o])
                          .cwiseProduct(window.noise_sigma.cwiseAbs2())
                          .transpose();
  }
  return variance;
}

}  // namespace

void AddEndCaps(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, const VelocityAt& velocity, Eigen::Index first,
                Eigen::Index last, bool front_at_jump, bool short_segments, CurveSegment* segment, int threads) {
  std::vector<CurveWindow>& windows = segment->windows;
  if (windows.empty() || (windows.size() < 3 && !short_segments)) return;
  const double* begin = t.data() + first;
  const double* end = t.data() + last;
  auto samples_in = [&](double a, double b) {
    return std::upper_bound(begin, end, b) - std::lower_bound(begin, end, a);
  };
  // Artificial ends lie where the curve's velocity is an interior one: off both end windows. In a
  // segment of one or two windows there is no such place, and in a longer one whose end windows
  // overlap there may be too little of it to judge the candidates (ChooseCap's Choice::judged):
  // then each end's artificial ends lie in the middle half of its end window's samples, where that
  // window's rate varies least, and its rate is the reference there ("spanned").
  const bool spanned = windows.size() <= 2;
  const ArtificialEnds interior{std::upper_bound(begin, end, windows.front().fit_end) - t.data(),
                                std::lower_bound(begin, end, windows.back().fit_begin) - t.data(), 0, 0};
  if (!spanned && interior.hi <= interior.lo && !short_segments) return;
  // The end windows' factors: one when the segment is one window, whose two ends share it.
  std::array<std::optional<NestedCholesky>, 2> factors;
  if (spanned) {
    ParallelFor(static_cast<int>(windows.size()), threads, [&](int k) {
      factors[static_cast<size_t>(k)] = FactorWindow(t, z, k == 0 ? windows.front() : windows.back());
    });
  }
  std::array<Choice, 2> choices;
  ParallelFor(2, threads, [&](int side) {
    const bool front = side == 0;
    const CurveWindow& w = front ? windows.front() : windows.back();
    const Eigen::Index end_samples = samples_in(w.fit_begin, w.fit_end);
    const Eigen::Index core_samples = samples_in(w.core_begin, w.core_end);
    const int shortest = (front ? front_at_jump : segment->continues) ? kLongCap : 0;
    std::optional<NestedCholesky> own_factor;
    if (!spanned) {
      if (interior.hi > interior.lo) {
        choices[static_cast<size_t>(side)] =
            ChooseCap(t, z, velocity, {interior.lo, interior.hi, interior.lo, interior.hi}, last - first, w,
                      end_samples, core_samples, shortest, nullptr, front, first, last);
        if (choices[static_cast<size_t>(side)].judged) return;
      }
      if (!short_segments) return;
      own_factor = FactorWindow(t, z, w);
    }
    // The end window's rate at the real end's samples, and its variance there.
    const Eigen::Index offsets = std::min(end_samples / 2, BlendEnd(kCapBoundaries.back()));
    const std::optional<NestedCholesky>& factor =
        spanned ? factors[windows.size() == 1 ? 0 : static_cast<size_t>(side)] : own_factor;
    if (!factor) return;  // its samples no longer determine the window (repeated stamps)
    const std::optional<Eigen::MatrixXd> end_variance =
        RateVariance(t, w, *factor, front ? first : last - 1, front ? 1 : -1, offsets);
    if (!end_variance) return;
    const Eigen::Index wf = std::lower_bound(begin, end, w.fit_begin) - t.data(), wl = wf + end_samples;
    const ArtificialEnds ends{wf + end_samples / 4, wl - end_samples / 4, wf, wl};
    if (ends.hi <= ends.lo) return;
    const VelocityAt own_velocity = [&](Eigen::Index from, Eigen::Index count) {
      return WindowSeriesAt(w, t.segment(from, count), 1);
    };
    choices[static_cast<size_t>(side)] = ChooseCap(t, z, own_velocity, ends, end_samples, w, end_samples,
                                                   core_samples, shortest, &*end_variance, front, first, last);
  });
  // The back first, so that inserting at the front leaves nothing to re-find.
  for (const bool front : {false, true}) {
    const Choice& choice = choices[front ? 0 : 1];
    if (choice.samples == 0) continue;
    CurveWindow& end_window = front ? windows.front() : windows.back();
    const double boundary = front ? t[first + choice.boundary] : t[last - 1 - choice.boundary];
    if (!(boundary > end_window.core_begin && boundary < end_window.core_end)) continue;  // repeated stamps
    CurveWindow cap;
    try {
      cap = BuildCap(t, z, front ? first : last - choice.samples, choice, end_window);
    } catch (const ComputeError&) {
      continue;  // the end's own samples do not determine the cap (repeated stamps): no cap
    }
    if (front) {
      cap.core_begin = end_window.core_begin;
      cap.core_end = boundary;
      end_window.core_begin = boundary;
      windows.insert(windows.begin(), std::move(cap));
    } else {
      cap.core_begin = boundary;
      cap.core_end = end_window.core_end;
      end_window.core_end = boundary;
      windows.push_back(std::move(cap));
    }
  }
}

}  // namespace cheval::cheb::internal

#include "bridges.h"
#include "local_rates.h"
#include "residual_test.h"
#include "work_queue.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <utility>

#include "cheval/cheb/chebyshev.h"
#include "cheval/cheb/fit.h"
#include "cheval/common/error.h"

namespace cheval::cheb::internal {
namespace {

// The samples within this many gap lengths on either side of a gap are fitted across it: of the
// reaches whose fits pass the residual test and agree (kAgreement), the one whose rates beside the
// gap have the least variance (the longest the motion allows, for it is smooth enough there).
constexpr std::array<double, 5> kReaches{2.0, 4.0, 8.0, 16.0, 32.0};
// The reaches' rates beside a gap agree while their intervals of this many standard deviations
// share a point, on both sides and in every coordinate: the intersection of confidence intervals
// (Goldenshluger & Nemirovski 1997). A longer reach buys its smaller variance with a bias that its
// residual test, over many samples, may not show; beside the gap it puts the rate outside the
// interval of a shorter reach, and the reaches stop there.
constexpr double kAgreement = 3.0;
// Each side of a gap keeps at least this many samples within reach to be fitted across it.
constexpr Eigen::Index kMinSide = 4;
// The slope of a fit's residuals where it takes over may reach this many of its standard deviations
// (as the residual test's limit, kLackOfFitLimit).
constexpr double kTrendLimit = 3.0;
// NestedResidualFloor: the floor lies this far below the top degree's residual sum of squares, and
// only where the evaluation's rounding is at most kRoundingShare of that margin.
constexpr double kNestedMargin = 1e-4;
constexpr double kRoundingShare = 0.01;
// N²/m of a fit across a gap at most, as the windows' (CurveOptions::max_conditioning's default).
constexpr double kMaxConditioning = 8.0;

// A least-squares fit of samples [first, first + count) with a degree per coordinate, and the
// factor of its normal matrix up to the highest of them.
struct SampleFit {
  Interval interval;
  std::vector<int> degrees;
  Eigen::MatrixXd coefficients;  // (top + 1) x d, zero above each coordinate's degree
  NestedCholesky cholesky;

  // The variance factor dᵀG⁻¹d of the rate at time `at` per coordinate (d the derivative's basis
  // there): times σ², the rate's variance.
  Eigen::VectorXd RateVarianceFactorAt(double at) const { return RateVarianceFactor(cholesky, interval, degrees, at); }
  // The rate at time `at` per coordinate.
  Eigen::VectorXd RateAt(double at) const {
    Eigen::VectorXd slopes(coefficients.rows());
    ChebyshevSlopes(interval.ToUnit(at), interval.DerivativeScale(), slopes);
    return coefficients.transpose() * slopes;
  }
};

SampleFit FitSamples(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, Eigen::Index first, Eigen::Index count,
                     const Interval& interval, const std::vector<int>& degrees) {
  const Eigen::Index d = z.cols();
  const int top = *std::max_element(degrees.begin(), degrees.end());
  const NormalEquations normal = BuildNormalEquations(t.segment(first, count), z.middleRows(first, count), top, interval);
  SampleFit fit{interval, degrees, Eigen::MatrixXd::Zero(top + 1, d), NestedCholesky(normal, top)};
  for (Eigen::Index c = 0; c < d; ++c) {
    const int n = degrees[static_cast<size_t>(c)];
    fit.coefficients.col(c).head(n + 1) = fit.cholesky.Solve(n, normal.rhs.col(c));
  }
  return fit;
}

// The fit across a gap: samples [first, first + count) of both sides, the degree per coordinate
// chosen by generalised cross-validation (m·RSS/(m − N − 1)², Craven & Wahba 1979) up to `top`,
// and whether its residual passes the residual test against σ (per coordinate).
struct Bridge {
  std::vector<int> degrees;
  Eigen::VectorXd residual_rms, lack_of_fit;
  bool passes = true;
};

Bridge FitBridge(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, Eigen::Index first, Eigen::Index count,
                 const Interval& interval, int top, const Eigen::VectorXd& sigma) {
  const Eigen::Index d = z.cols();
  const auto tw = t.segment(first, count);
  const auto zw = z.middleRows(first, count);
  const NormalEquations normal = BuildNormalEquations(tw, zw, top, interval);
  const NestedCholesky cholesky(normal, top);
  Eigen::VectorXd x(count);
  for (Eigen::Index i = 0; i < count; ++i) x[i] = interval.ToUnit(tw[i]);
  Bridge bridge{std::vector<int>(static_cast<size_t>(d), 1), Eigen::VectorXd(d), Eigen::VectorXd(d)};
  Eigen::VectorXd best = Eigen::VectorXd::Constant(d, std::numeric_limits<double>::infinity());
  Eigen::VectorXd rss = Eigen::VectorXd::Zero(d);
  // Residuals on the samples themselves: the sums of the normal equations lose nearly exact data's.
  // That costs m·n a degree, so the top degree's are taken first: no degree leaves less, and a
  // degree whose score could not beat any coordinate's best even at that floor is not evaluated. The
  // choice is the one every degree's evaluation gives.
  auto residual_squares = [&](int n) -> Eigen::VectorXd {
    return (zw - EvaluateSeries(cholesky.Solve(n, normal.rhs), x)).colwise().squaredNorm().transpose();
  };
  const Eigen::VectorXd top_squares = residual_squares(top);
  const Eigen::VectorXd floor = NestedResidualFloor(zw, top_squares, top);
  for (int n = 1; n <= top; ++n) {
    const double free = static_cast<double>(count - n - 1);
    const Eigen::ArrayXd least = static_cast<double>(count) * floor.array() / (free * free);
    if ((least >= best.array()).all()) continue;
    const Eigen::VectorXd squares = n == top ? top_squares : residual_squares(n);
    for (Eigen::Index c = 0; c < d; ++c) {
      const double score = static_cast<double>(count) * squares[c] / (free * free);
      if (score < best[c]) best[c] = score, bridge.degrees[static_cast<size_t>(c)] = n, rss[c] = squares[c];
    }
  }
  for (Eigen::Index c = 0; c < d; ++c) {
    const int n = bridge.degrees[static_cast<size_t>(c)];
    bridge.residual_rms[c] = std::sqrt(rss[c] / static_cast<double>(count));
    bridge.lack_of_fit[c] = LackOfFitScore(rss[c], sigma[c], count - n - 1);
    bridge.passes = bridge.passes && std::isfinite(best[c]) && bridge.lack_of_fit[c] <= kLackOfFitLimit;
  }
  return bridge;
}

// The window of a side: the bridge's polynomial re-expanded exactly on a segment's samples
// [first, first + count) (inside the bridge's interval: no extrapolation).
CurveWindow SideWindow(const Eigen::VectorXd& t, const SampleFit& fit, const Bridge& bridge, Eigen::Index first,
                       Eigen::Index count, const Eigen::VectorXd& sigma) {
  const Eigen::Index d = fit.coefficients.cols();
  CurveWindow window;
  window.fit_begin = t[first];
  window.fit_end = t[first + count - 1];
  window.samples = count;
  window.degrees = bridge.degrees;
  window.series.interval = {window.fit_begin, window.fit_end};
  const int top = *std::max_element(bridge.degrees.begin(), bridge.degrees.end());
  window.series.coefficients = Eigen::MatrixXd::Zero(top + 1, d);
  for (Eigen::Index c = 0; c < d; ++c) {
    const int n = bridge.degrees[static_cast<size_t>(c)];
    window.series.coefficients.col(c).head(n + 1) =
        Reexpand(fit.coefficients.col(c).head(n + 1), fit.interval, window.series.interval);
  }
  window.coefficient_magnitudes = window.series.coefficients.cwiseAbs();
  window.first_derivative = DerivativeCoefficients(window.series.coefficients);
  window.second_derivative = DerivativeCoefficients(window.first_derivative);
  window.residual_rms = bridge.residual_rms;
  window.lack_of_fit = bridge.lack_of_fit;
  window.noise_sigma = sigma;
  window.verdict = WindowVerdict::kBridge;
  return window;
}

// A gap's fit, which serves its two sides: the back of the segment before (side 0) and the front
// of the one after (side 1).
struct GapFit {
  Bridge bridge;
  Eigen::Index first = 0, count = 0, gap = 0;  // the fit's samples; the first sample after the gap
  Eigen::VectorXd sigma;
  std::optional<SampleFit> across;  // the fit at the bridge's degrees
  // Its rate's variance factors beside the gap: at the last sample before it (side 0) and the
  // first after it (side 1).
  std::array<Eigen::VectorXd, 2> beside;
};

// The intersection of the intervals of kAgreement standard deviations around the rates beside a
// gap (rows: the last sample before it and the first after it; columns: coordinates) of the fits
// across it admitted so far.
class RateAgreement {
 public:
  explicit RateAgreement(Eigen::Index d)
      : low_(Eigen::ArrayXXd::Constant(2, d, -std::numeric_limits<double>::infinity())), high_(-low_) {}

  // Narrows the intersection by the intervals of `fit`: false when that leaves it empty.
  bool Admit(const Eigen::VectorXd& t, const GapFit& fit) {
    for (int side = 0; side < 2; ++side) {
      const Eigen::ArrayXd rate = fit.across->RateAt(t[side == 0 ? fit.gap - 1 : fit.gap]).array();
      const Eigen::ArrayXd deviation = fit.sigma.cwiseAbs2().cwiseProduct(fit.beside[side]).cwiseSqrt().array();
      low_.row(side) = low_.row(side).max((rate - kAgreement * deviation).transpose());
      high_.row(side) = high_.row(side).min((rate + kAgreement * deviation).transpose());
    }
    return (low_ <= high_).all();
  }

 private:
  Eigen::ArrayXXd low_, high_;
};

// Fits across the gap before sample `gap` the samples within `reach` of it, across further gaps
// too (between dropouts the segments are short) but inside [before, after) (not across a jump).
std::optional<GapFit> FitGap(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, Eigen::Index before, Eigen::Index gap,
                             Eigen::Index after, double reach, const NoiseProfile& noise,
                             const Eigen::VectorXd& sigma_floor) {
  const double* data = t.data();
  GapFit fit;
  fit.gap = gap;
  fit.first = std::lower_bound(data + before, data + gap, t[gap - 1] - reach) - data;
  const Eigen::Index last = std::upper_bound(data + gap, data + after, t[gap] + reach) - data;
  fit.count = last - fit.first;
  const Eigen::Index left = gap - fit.first, right = last - gap;
  // A side with fewer samples is taken only where no reach gives it more (its run's end, a
  // recording's first or last samples after a dropout) and its samples give a rate to test the
  // fit's against (SideHelps: at least two).
  const bool left_ends = fit.first == before, right_ends = last == after;
  const bool short_side_ends =
      ((left < kMinSide && left >= 2 && left_ends && right >= kMinSide) ||
       (right < kMinSide && right >= 2 && right_ends && left >= kMinSide));
  if (std::min(left, right) < kMinSide && !short_side_ends) return std::nullopt;
  const Interval interval{t[fit.first], t[last - 1]};
  double length = 0.0;  // the longest hole inside
  for (Eigen::Index i = fit.first + 1; i < last; ++i) length = std::max(length, t[i] - t[i - 1]);
  // What the hole allows, the conditioning limit, and two samples a coefficient (a fit close to
  // interpolating its few samples passes any residual test).
  const int top = static_cast<int>(std::min<double>({std::floor(0.5 * std::numbers::pi * (interval.b - interval.a) / length),
                                                     std::floor(std::sqrt(kMaxConditioning * static_cast<double>(fit.count))),
                                                     static_cast<double>(fit.count / 2 - 1)}));
  if (top < 1) return std::nullopt;
  // As a window's (WindowSigma), and at least the floor (the values' rounding level).
  fit.sigma = WindowSigma(noise.Over(fit.first, fit.count), z.middleRows(fit.first, fit.count)).cwiseMax(sigma_floor);
  try {
    fit.bridge = FitBridge(t, z, fit.first, fit.count, interval, top, fit.sigma);
    if (!fit.bridge.passes) return std::nullopt;
    fit.across = FitSamples(t, z, fit.first, fit.count, interval, fit.bridge.degrees);
    fit.beside = {fit.across->RateVarianceFactorAt(t[gap - 1]), fit.across->RateVarianceFactorAt(t[gap])};
  } catch (const ComputeError&) {
    return std::nullopt;  // repeated stamps: the samples do not determine the fit
  }
  return fit;
}

// The slopes of the least-squares lines through the residuals of a side's fit over samples
// [first, first + count) (those where it takes over), per coordinate: its rate's bias averaged
// there plus the noise's slope, whose standard deviation is σ/sqrt(Σ(t − t̄)²). Under noise the
// slope is mostly the noise's; on nearly noise-free data it is the bias of a fit held to a hole's
// low degree, which the segment's own end (then exact) does not have.
struct ResidualTrend {
  Eigen::VectorXd slope, deviation;

  // Whether the slope is within kTrendLimit standard deviations in every coordinate.
  bool IsNoise() const { return (slope.array().abs() <= kTrendLimit * deviation.array()).all(); }
};

// None where the samples share one stamp.
std::optional<ResidualTrend> TrendOf(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, Eigen::Index first,
                                     Eigen::Index count, const SampleFit& fit, const Eigen::VectorXd& sigma) {
  const auto tw = t.segment(first, count);
  Eigen::VectorXd x(count);
  for (Eigen::Index i = 0; i < count; ++i) x[i] = fit.interval.ToUnit(tw[i]);
  const Eigen::MatrixXd residual = z.middleRows(first, count) - EvaluateSeries(fit.coefficients, x);
  const Eigen::VectorXd centred = tw.array() - tw.mean();
  const double spread = centred.squaredNorm();
  if (!(spread > 0.0)) return std::nullopt;
  return ResidualTrend{residual.transpose() * centred / spread, sigma / std::sqrt(spread)};
}

// The rate's variance factor of the segment [begin, end)'s own fit at its sample `at`: that of the
// window at that end, fitted again to its samples; none where they no longer determine it.
std::optional<Eigen::VectorXd> OwnVarianceFactor(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, Eigen::Index end,
                                                 const CurveSegment& segment, Eigen::Index at) {
  const CurveWindow& own = at + 1 == end ? segment.windows.back() : segment.windows.front();
  const std::optional<NestedCholesky> cholesky = FactorWindow(t, z, own);
  if (!cholesky) return std::nullopt;
  return RateVarianceFactor(*cholesky, own.series.interval, own.degrees, t[at]);
}

// Whether a gap's side may stand in for the segment [begin, end) it borders (`back`: at the
// segment's back) over its samples [from, from + count): its rate has the smaller variance than
// the segment's own at the sample beside the gap (and, for a whole segment, at its other end too),
// and its residuals there show no trend. A trend above the noise is taken as a bias of the side's
// rate, all of it (the noise's share is not known): the side still helps where that bias squared
// and its rate's variance together stay below the segment's own rate's variance (a few samples
// between dropouts under noise, whose own rate is far noisier than 3 standard deviations of their
// slope).
bool SideHelps(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, const GapFit& gap, bool back, Eigen::Index begin,
               Eigen::Index end, const CurveSegment& segment, Eigen::Index from, Eigen::Index count,
               const GapFit* incumbent = nullptr) {
  const SampleFit& fit = *gap.across;
  const std::optional<ResidualTrend> trend = TrendOf(t, z, from, count, fit, gap.sigma);
  if (!trend) return false;
  const double bias = trend->IsNoise() ? 0.0 : trend->slope.squaredNorm();
  const Eigen::VectorXd variance = gap.sigma.cwiseAbs2();
  const bool whole = from == begin && count == end - begin;
  for (const Eigen::Index at : {back ? end - 1 : begin, back ? begin : end - 1}) {
    // An end window its samples do not determine again (fewer distinct stamps than its degree
    // asks for: a few samples between dropouts) is no rival, but no measure of a bias either.
    const std::optional<Eigen::VectorXd> own = incumbent != nullptr ? incumbent->across->RateVarianceFactorAt(t[at])
                                                                    : OwnVarianceFactor(t, z, end, segment, at);
    const Eigen::VectorXd factor =
        at == (back ? end - 1 : begin) ? gap.beside[back ? 0 : 1] : fit.RateVarianceFactorAt(t[at]);
    if (own ? !(factor.dot(variance) + bias < own->dot(variance)) : bias > 0.0) return false;
    if (!whole) break;
  }
  return true;
}

// The samples of the segment [begin, end) that a gap's fit covers on its side (`back`: the gap
// follows the segment): [from, from + count).
std::pair<Eigen::Index, Eigen::Index> SideSamples(const GapFit& gap, bool back, Eigen::Index begin, Eigen::Index end) {
  if (back) {
    const Eigen::Index from = std::max(gap.first, begin);
    return {from, gap.gap - from};
  }
  return {gap.gap, std::min(gap.first + gap.count, end) - gap.gap};
}

// The window of a gap's side over the samples of the segment [begin, end) it covers.
CurveWindow SideWindow(const Eigen::VectorXd& t, const GapFit& gap, bool back, Eigen::Index begin, Eigen::Index end) {
  const auto [from, count] = SideSamples(gap, back, begin, end);
  return SideWindow(t, *gap.across, gap.bridge, from, count, gap.sigma);
}

// Puts `bridge` at the back (or front) of a segment, from `boundary` on (up to it): windows whose
// core lies past the boundary go, the one holding it is cut there. Nothing changes where no
// window's core holds the boundary strictly inside (repeated stamps beside the gap).
void Insert(CurveWindow bridge, double boundary, bool back, CurveSegment* segment) {
  std::vector<CurveWindow>& windows = segment->windows;
  auto holds = [&](const CurveWindow& w) { return boundary > w.core_begin && boundary < w.core_end; };
  if (back) {
    auto kept = windows.end();
    while (kept != windows.begin() + 1 && std::prev(kept)->core_begin >= boundary) --kept;
    if (!holds(*std::prev(kept))) return;
    bridge.core_begin = boundary;
    bridge.core_end = windows.back().core_end;
    windows.erase(kept, windows.end());
    windows.back().core_end = boundary;
    windows.push_back(std::move(bridge));
  } else {
    auto kept = windows.begin();
    while (kept + 1 != windows.end() && kept->core_end <= boundary) ++kept;
    if (!holds(*kept)) return;
    bridge.core_begin = windows.front().core_begin;
    bridge.core_end = boundary;
    windows.erase(windows.begin(), kept);
    windows.front().core_begin = boundary;
    windows.insert(windows.begin(), std::move(bridge));
  }
}

}  // namespace

Eigen::VectorXd NestedResidualFloor(const Eigen::Ref<const Eigen::MatrixXd>& z, const Eigen::VectorXd& top_squares,
                                    int top) {
  const double m = static_cast<double>(z.rows());
  // A residual evaluated by Clenshaw's recurrence is off by up to ~ε·(N + 1)² times the values'
  // size; relative to the residual sum of squares that is 2·that·sqrt(m / RSS).
  const double rounding = std::numeric_limits<double>::epsilon() * (top + 1.0) * (top + 1.0);
  Eigen::VectorXd floor = Eigen::VectorXd::Zero(z.cols());
  for (Eigen::Index c = 0; c < z.cols(); ++c) {
    const double relative = 2.0 * rounding * z.col(c).cwiseAbs().maxCoeff() * std::sqrt(m / top_squares[c]);
    if (std::isfinite(relative) && relative <= kRoundingShare * kNestedMargin) {
      floor[c] = (1.0 - kNestedMargin) * top_squares[c];
    }
  }
  return floor;
}

void BridgeGaps(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, const std::vector<Eigen::Index>& starts,
                const NoiseProfile& noise, const Eigen::VectorXd& sigma_floor, std::vector<CurveSegment>* segments,
                int threads) {
  const size_t count = segments->size();
  // The first (and one past the last) segment of the run of segments joined by gaps, not jumps,
  // that segment k lies in.
  std::vector<size_t> run_begin(count), run_end(count);
  for (size_t k = 0; k < count; ++k) run_begin[k] = k > 0 && !(*segments)[k - 1].continues ? run_begin[k - 1] : k;
  for (size_t k = count; k-- > 0;) run_end[k] = k + 1 < count && !(*segments)[k].continues ? run_end[k + 1] : k + 1;
  // fits[k]: across the gap after segment k.
  std::vector<std::optional<GapFit>> fits(count);
  ParallelFor(static_cast<int>(count) - 1, threads, [&](int gap_index) {
    const auto k = static_cast<size_t>(gap_index);
    if ((*segments)[k].continues) return;  // a jump, not a gap
    const Eigen::Index gap = starts[k + 1];
    double least = std::numeric_limits<double>::infinity();
    RateAgreement agreement(z.cols());
    for (const double reach : kReaches) {
      std::optional<GapFit> fit = FitGap(t, z, starts[run_begin[k]], gap, starts[run_end[k + 1]],
                                         reach * (t[gap] - t[gap - 1]), noise, sigma_floor);
      if (!fit) continue;
      if (!agreement.Admit(t, *fit)) break;  // a longer reach would not agree either
      const Eigen::VectorXd variance = fit->sigma.cwiseAbs2();
      const double spread = variance.dot(fit->beside[0]) + variance.dot(fit->beside[1]);
      const bool same = fits[k] && fits[k]->first == fit->first && fits[k]->count == fit->count;
      if (spread < least && !same) least = spread, fits[k] = std::move(fit);
    }
  });
  for (size_t k = 0; k < count; ++k) {
    CurveSegment& segment = (*segments)[k];
    const Eigen::Index begin = starts[k], end = starts[k + 1], n = end - begin;
    const GapFit* front = k > 0 && fits[k - 1] ? &*fits[k - 1] : nullptr;
    const GapFit* back = fits[k] ? &*fits[k] : nullptr;
    // A segment the fits of its gaps cover whole (one or both ends at a gap; a short segment
    // between dropouts): those of them that help over all of it replace its windows.
    const bool front_covers = front != nullptr && front->first + front->count >= end;
    const bool back_covers = back != nullptr && back->first <= begin;
    const bool front_whole = front_covers && SideHelps(t, z, *front, false, begin, end, segment, begin, n);
    const bool back_whole = back_covers && SideHelps(t, z, *back, true, begin, end, segment, begin, n);
    if (front_whole || back_whole) {
      // Where both help, the one whose rate has the smaller variance at the segment's two ends. Two
      // meeting inside it would blend over a fraction of its span, and the difference between
      // their positions, small as it is, would enter the rate divided by that fraction: between
      // dropouts a tenth of a second apart, tens of mm/s under 2 mm of noise.
      auto end_variance = [&](const GapFit& gap) {
        const SampleFit& fit = *gap.across;
        return gap.sigma.cwiseAbs2().dot(fit.RateVarianceFactorAt(t[begin]) + fit.RateVarianceFactorAt(t[end - 1]));
      };
      const bool keep_front = front_whole && (!back_whole || end_variance(*front) <= end_variance(*back));
      CurveWindow window = SideWindow(t, keep_front ? *front : *back, !keep_front, begin, end);
      window.core_begin = segment.windows.front().core_begin;
      window.core_end = segment.windows.back().core_end;
      segment.windows = {std::move(window)};
    }
    // Otherwise each end's own: alone over z/2 samples from the gap, blended up to 1.5z, z a third
    // of its side's samples and of the segment's (room for both ends' blends). Not a fit whose
    // residuals over a segment it covers show a trend: it is biased somewhere there.
    const GapFit* whole = front_whole ? front : back_whole ? back : nullptr;
    for (const bool at_back : {true, false}) {
      const GapFit* gap = at_back ? back : front;
      if (gap == nullptr || (at_back ? back_whole : front_whole)) continue;
      if (at_back ? back_covers : front_covers) {
        const std::optional<ResidualTrend> trend = TrendOf(t, z, begin, n, *gap->across, gap->sigma);
        if (!trend || !trend->IsNoise()) continue;
      }
      const Eigen::Index side = SideSamples(*gap, at_back, begin, end).second;
      const Eigen::Index zone = std::min(side - 1, n - 1) / 3;
      if (zone < 1) continue;
      const Eigen::Index reached = std::min<Eigen::Index>(side, static_cast<Eigen::Index>(std::ceil(1.5 * zone)) + 1);
      if (!SideHelps(t, z, *gap, at_back, begin, end, segment, at_back ? end - reached : begin, reached, whole)) continue;
      Insert(SideWindow(t, *gap, at_back, begin, end), at_back ? t[end - 1 - zone] : t[begin + zone], at_back, &segment);
    }
  }
}

}  // namespace cheval::cheb::internal

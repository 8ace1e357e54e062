#include "jumps.h"
#include "work_queue.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>

#include <Eigen/LU>
#include <Eigen/QR>

#include "noise_profile.h"
#include "residual_test.h"

namespace cheval::cheb::internal {
namespace {

// Slopes on each side that predict a slope (by a straight line through them), skipping the
// adjacent one so that a single bad slope does not spoil its neighbours' predictions.
constexpr int kSide = 8;
constexpr int kSkip = 1;
// A slope departs from its neighbours when it is this many local scales away from their lines:
// far beyond Gaussian noise (a false alarm per coordinate has probability ~2e-9), so on clean data
// next to nothing is found (12 missed the 0.1–0.3 mm steps of EuRoC's ground truth).
constexpr double kThreshold = 6.0;
// Slopes per block of the local scale (robust: the median of a block).
constexpr Eigen::Index kBlock = 64;
// The block's scale is at most this many times the median of the slopes' departures from their
// nearer side's line (min(|d_j − left|, |d_j − right|)): 1.50 times the two-sided departure's
// median under white noise (measured, 12 % scatter between blocks of 64), with a margin of 2, so
// that noise leaves the two-sided scale alone. Every slope within kSide of a jump of the rate
// departs from the lines across it; where jumps come every few dozen slopes (a bouncing ball, a
// gait's impacts), their neighbours are the block's median and hid all but the largest, while a
// slope's nearer side is clean.
constexpr double kNearerSide = 3.0;
// Samples on either side of a step that estimate it (RefineSteps).
constexpr Eigen::Index kStepSamples = 8;
// A step whose fit finds a jump of the rate this many standard errors away from none is a break.
constexpr double kRateJumpScore = 3.0;
// A break or step stays only where it explains the samples beside it better than a quintic by this
// many variances (BreakBeatsSmoothMotion). Under noise alone the two fits' sums differ by about a
// difference of two χ²(2)·σ², of standard deviation 2.8σ²: 9σ² is more than 3 of them.
constexpr double kSmoothMargin = 9.0;
// Passes over the slopes, each with the local scale taken again.
constexpr int kPasses = 8;
// The most consecutive samples an excursion (a burst of displaced samples, each displaced its own
// way) may hold; longer ones take a good part of the 8 slopes a side that judge them.
constexpr Eigen::Index kBurst = 5;
// The bridge across an excursion, the slope from the sample before it to the sample after it, must
// stay within this many local scales of the lines on either side: the motion goes on across it.
constexpr double kBridgeScore = 3.0;

// Up to 4 coordinates (FitCurve's), on the stack: the per-slope predictions allocate nothing.
using Point = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 4, 1>;

class SlopeScan {
 public:
  SlopeScan(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, const std::vector<Eigen::Index>& gaps,
            const Eigen::VectorXd& noise, const NoiseProfile* profile)
      : n_(t.size() - 1), d_(z.cols()), slopes_(std::max<Eigen::Index>(n_, 0), z.cols()), mid_(std::max<Eigen::Index>(n_, 0)),
        dt_(std::max<Eigen::Index>(n_, 0)), cut_(static_cast<size_t>(std::max<Eigen::Index>(n_, 0)), 0),
        masked_(static_cast<size_t>(std::max<Eigen::Index>(n_, 0)), 0), profile_(profile) {
    for (Eigen::Index j = 0; j < n_; ++j) {
      dt_[j] = t[j + 1] - t[j];
      mid_[j] = 0.5 * (t[j] + t[j + 1]);
      if (dt_[j] > 0.0) {
        slopes_.row(j) = (z.row(j + 1) - z.row(j)) / dt_[j];
      } else {
        masked_[static_cast<size_t>(j)] = 1;  // equal stamps: no slope
        slopes_.row(j).setZero();
      }
    }
    for (const Eigen::Index b : gaps) {
      if (b >= 0 && b < n_) cut_[static_cast<size_t>(b)] = 1;
    }
    // Floor of the local scale: the slope noise of white position noise σ (sqrt(2)·σ/dt), and the
    // values' rounding level (RoundingFloor) so that exact data do not make every departure infinite.
    noise_floor_ = Eigen::VectorXd(d_);
    for (Eigen::Index c = 0; c < d_; ++c) {
      noise_floor_[c] = std::max(std::sqrt(2.0) * noise[c], RoundingFloor(z.col(c)));
    }
    // Where the noise profile is raised (over a burst, the blocks beside it too) or follows stamp
    // noise, its slope noise floors the scale instead.
    if (profile != nullptr && profile->varies()) {
      const Eigen::Index m = t.size(), block = NoiseProfile::kBlock, blocks = (m + block - 1) / block;
      block_floor_.resize(blocks, d_);
      for (Eigen::Index b = 0; b < blocks; ++b) {
        const Eigen::VectorXd sigma = profile->Over(b * block, std::min(block, m - b * block));
        block_floor_.row(b) = (std::sqrt(2.0) * sigma).cwiseMax(noise_floor_).transpose();
      }
    }
  }

  Eigen::Index size() const { return n_; }
  // The samples' noise σ in coordinate c (never below a rounding level of the values).
  double SampleNoise(Eigen::Index c) const { return noise_floor_[c] / std::sqrt(2.0); }
  // The local scale of slope j's departures in coordinate c (never below the slope noise).
  double LocalScale(Eigen::Index j, Eigen::Index c, const Eigen::MatrixXd& scale) const {
    return std::max(scale(j / kBlock, c), SlopeNoise(j, c));
  }
  // The slope noise of slope j in coordinate c: sqrt(2)·σ/dt, σ the profile's near it.
  double SlopeNoise(Eigen::Index j, Eigen::Index c) const {
    const double floor = block_floor_.size() > 0 ? block_floor_(j / NoiseProfile::kBlock, c) : noise_floor_[c];
    return floor / dt_[j];
  }
  // Whether the noise profile raises the floor of slope j's scale above the recording's by a raised
  // block (a burst of noise), not by stamp noise alone.
  bool Raised(Eigen::Index j) const {
    if (block_floor_.size() == 0 || !profile_->BlockRaised(j / NoiseProfile::kBlock)) return false;
    return (block_floor_.row(j / NoiseProfile::kBlock).transpose().array() > noise_floor_.array()).any();
  }
  bool Usable(Eigen::Index j) const { return !cut_[static_cast<size_t>(j)] && !masked_[static_cast<size_t>(j)]; }
  void Cut(Eigen::Index j) { cut_[static_cast<size_t>(j)] = 1; }
  void Mask(Eigen::Index j) { masked_[static_cast<size_t>(j)] = 1; }
  double dt(Eigen::Index j) const { return dt_[j]; }

  // How far samples a..b (an excursion) are from being left out cleanly, in local scales (the
  // largest over the coordinates and these): the bridge across them, the slope from sample a − 1
  // to sample b + 1, against the mean of the straight lines through the slopes before slope a − 2
  // and after slope b + 1 at its middle; and slopes a − 2 and b + 1, the bridge's ends' own, each
  // against its side's line (its end samples are not displaced themselves: two displaced by the
  // same amount bridge cleanly). `disagreement`: the two lines' difference at the bridge's middle
  // (right − left). Infinity where the bridge crosses a cut or a slope left out of the lines for
  // anything but a sample already `left_out` (a glitch's, part of this excursion; a step's would
  // carry its offset into the bridge), or a side has too few slopes.
  double BridgeScore(Eigen::Index a, Eigen::Index b, const Eigen::MatrixXd& scale, const std::vector<char>& left_out,
                     Eigen::VectorXd* disagreement) const {
    constexpr double kNone = std::numeric_limits<double>::infinity();
    if (a < 2 || b + 1 >= n_) return kNone;
    Point bridge = Point::Zero(d_);
    double span = 0.0, moment = 0.0;
    for (Eigen::Index j = a - 1; j <= b; ++j) {
      const auto k = static_cast<size_t>(j);
      if (cut_[k] || (masked_[k] && dt_[j] > 0.0 && !left_out[k] && !left_out[k + 1])) return kNone;
      bridge += slopes_.row(j).transpose() * dt_[j];
      span += dt_[j];
      moment += mid_[j] * dt_[j];
    }
    if (cut_[static_cast<size_t>(a - 2)] || cut_[static_cast<size_t>(b + 1)] || !(span > 0.0)) return kNone;
    bridge /= span;
    const double middle = moment / span;
    Point left(d_), right(d_), left_end(d_), right_end(d_);
    if (!PredictFrom(a - 1, -1, &left, middle) || !PredictFrom(b, 1, &right, middle) ||
        !PredictFrom(a - 1, -1, &left_end, mid_[a - 2]) || !PredictFrom(b, 1, &right_end, mid_[b + 1])) {
      return kNone;
    }
    *disagreement = right - left;
    double score = 0.0;
    for (Eigen::Index c = 0; c < d_; ++c) {
      const double off = std::max({std::abs(bridge[c] - 0.5 * (left[c] + right[c])),
                                   std::abs(slopes_(a - 2, c) - left_end[c]), std::abs(slopes_(b + 1, c) - right_end[c])});
      score = std::max(score, off / LocalScale(a - 1, c, scale));
    }
    return score;
  }

  // d_j minus the mean of the straight-line predictions from either side; nullopt unless both
  // sides have slopes to predict from. Two-sided only: the curvature biases of the two
  // extrapolations cancel to first order, while one side's alone would exceed the local scale of
  // noise-free data and flag every slope next to a jump already found.
  // `disagreement`: how far apart the two sides' predictions are (right − left); `one_sided`: d_j's
  // distance from the nearer of the two predictions (for the local scale only).
  std::optional<Point> Departure(Eigen::Index j, Eigen::VectorXd* disagreement = nullptr,
                                 Point* one_sided = nullptr) const {
    Point left(d_), right(d_);
    if (!PredictFrom(j, -1, &left) || !PredictFrom(j, 1, &right)) return std::nullopt;
    if (disagreement != nullptr) *disagreement = right - left;
    if (one_sided != nullptr) {
      const Point slope = slopes_.row(j).transpose();
      *one_sided = (slope - left).cwiseAbs().cwiseMin((slope - right).cwiseAbs());
    }
    return Point(slopes_.row(j).transpose() - 0.5 * (left + right));
  }

  // Every slope's departure (rows; NaN where it cannot be told or the slope is not usable), as
  // Departure gives them now: one pass serves the local scale and the first scores; `one_sided`,
  // the same rows of Departure's `one_sided`. On up to `threads` threads, each taking a contiguous
  // part.
  Eigen::MatrixXd Departures(int threads, Eigen::MatrixXd* one_sided) const {
    Eigen::MatrixXd departures = Eigen::MatrixXd::Constant(n_, d_, std::numeric_limits<double>::quiet_NaN());
    *one_sided = departures;
    ParallelRanges(n_, threads, [&](Eigen::Index first, Eigen::Index last) {
      Point nearer(d_);
      for (Eigen::Index j = first; j < last; ++j) {
        if (!Usable(j)) continue;
        if (const std::optional<Point> e = Departure(j, nullptr, &nearer)) {
          departures.row(j) = e->transpose();
          one_sided->row(j) = nearer.transpose();
        }
      }
    });
    return departures;
  }

  // The largest departure of slope j in local scales (0 when it cannot be told).
  double Score(Eigen::Index j, const Eigen::MatrixXd& scale, Eigen::VectorXd* departure = nullptr,
               Eigen::VectorXd* disagreement = nullptr) const {
    if (!Usable(j)) return 0.0;
    const std::optional<Point> e = Departure(j, disagreement);
    if (!e) return 0.0;
    if (departure != nullptr) *departure = *e;
    return Score(j, *e, scale);
  }
  // The same for a departure `e` of slope j already at hand.
  template <typename Departure>
  double Score(Eigen::Index j, const Departure& e, const Eigen::MatrixXd& scale) const {
    double score = 0.0;
    for (Eigen::Index c = 0; c < d_; ++c) score = std::max(score, std::abs(e[c]) / LocalScale(j, c, scale));
    return score;
  }

  // The local scale per block of slopes and coordinate: 1.4826 · median |departure| over the block
  // (at most kNearerSide times the median of the departures from the nearer side's line, `one_sided`)
  // and its two neighbours' medians (the largest), from the pass's departures (Departures).
  // The medians on up to `threads` threads, each taking a contiguous part of the blocks.
  Eigen::MatrixXd Scales(const Eigen::MatrixXd& departures, const Eigen::MatrixXd& one_sided, int threads) const {
    const Eigen::Index blocks = (n_ + kBlock - 1) / kBlock;
    Eigen::MatrixXd median = Eigen::MatrixXd::Zero(blocks, d_);
    ParallelRanges(blocks, threads, [&](Eigen::Index first, Eigen::Index last) {
      std::vector<std::vector<double>> values(static_cast<size_t>(d_)), nearer(static_cast<size_t>(d_));
      auto median_of = [](std::vector<double>& v) {
        auto middle = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
        std::nth_element(v.begin(), middle, v.end());
        return *middle;
      };
      for (Eigen::Index b = first; b < last; ++b) {
        for (auto& v : values) v.clear();
        for (auto& v : nearer) v.clear();
        for (Eigen::Index j = b * kBlock; j < std::min(n_, (b + 1) * kBlock); ++j) {
          if (std::isnan(departures(j, 0))) continue;
          for (Eigen::Index c = 0; c < d_; ++c) {
            values[static_cast<size_t>(c)].push_back(std::abs(departures(j, c)));
            nearer[static_cast<size_t>(c)].push_back(one_sided(j, c));
          }
        }
        for (Eigen::Index c = 0; c < d_; ++c) {
          std::vector<double>& v = values[static_cast<size_t>(c)];
          if (v.empty()) continue;
          median(b, c) = 1.4826 * std::min(median_of(v), kNearerSide * median_of(nearer[static_cast<size_t>(c)]));
        }
      }
    });
    Eigen::MatrixXd scale = median;
    for (Eigen::Index b = 0; b < blocks; ++b) {
      if (b > 0) scale.row(b) = scale.row(b).cwiseMax(median.row(b - 1));
      if (b + 1 < blocks) scale.row(b) = scale.row(b).cwiseMax(median.row(b + 1));
    }
    return scale;
  }

  // Where exactly the motion jumps near slope j (a jump inside [t_b, t_{b+1}] makes slope b a
  // mix of the two sides, which its neighbours' lines may not single out): the boundary b among
  // j − 4 .. j + 4 whose removal leaves the straightest lines on either side (least squared
  // residuals of a line through kSide slopes on each side, in local scales). A boundary with fewer
  // than 3 slopes on a side cannot be judged and is not chosen: near the ends of the data it would
  // win by having no residual there, and cut off a piece of a few samples.
  Eigen::Index LocateBreak(Eigen::Index j, const Eigen::MatrixXd& scale) const {
    Eigen::Index best = j;
    double best_cost = std::numeric_limits<double>::infinity();
    for (Eigen::Index b = std::max<Eigen::Index>(0, j - 4); b <= std::min(n_ - 1, j + 4); ++b) {
      if (cut_[static_cast<size_t>(b)]) continue;
      double cost = 0.0;
      for (const int direction : {-1, 1}) cost += LineResidual(b, direction, scale, j);
      if (cost < best_cost) best_cost = cost, best = b;
    }
    return best;
  }

 private:
  // Σ over coordinates of the squared residuals (in local scales) of the least-squares line
  // through up to kSide usable slopes next to boundary b in `direction` (slope b itself excluded),
  // with the local scale at slope `at` (one scale for every b compared); infinity with fewer than
  // 3 such slopes.
  double LineResidual(Eigen::Index b, int direction, const Eigen::MatrixXd& scale, Eigen::Index at) const {
    std::vector<Eigen::Index> used;
    for (Eigen::Index i = b + direction; i >= 0 && i < n_ && static_cast<int>(used.size()) < kSide; i += direction) {
      if (cut_[static_cast<size_t>(i)]) break;
      if (!masked_[static_cast<size_t>(i)]) used.push_back(i);
    }
    if (used.size() < 3) return std::numeric_limits<double>::infinity();
    double s0 = 0, s1 = 0, s2 = 0;
    for (const Eigen::Index i : used) s0 += 1, s1 += mid_[i], s2 += mid_[i] * mid_[i];
    const double mean_u = s1 / s0, spread = s2 - s1 * mean_u;
    double cost = 0.0;
    for (Eigen::Index c = 0; c < d_; ++c) {
      double mean = 0, slope = 0;
      for (const Eigen::Index i : used) mean += slopes_(i, c);
      mean /= s0;
      for (const Eigen::Index i : used) slope += (mid_[i] - mean_u) * (slopes_(i, c) - mean);
      slope = spread > 0.0 ? slope / spread : 0.0;
      const double s = std::max(scale(at / kBlock, c), SlopeNoise(at, c));
      for (const Eigen::Index i : used) {
        const double r = (slopes_(i, c) - mean - slope * (mid_[i] - mean_u)) / s;
        cost += r * r;
      }
    }
    return cost;
  }

  // Least-squares line through up to kSide usable slopes beyond the adjacent one in `direction`,
  // not crossing a cut, evaluated at slope j's time (or at time `at`); false with fewer than
  // kSide / 2 slopes (a line from two or three slopes extrapolates their noise several times over:
  // next to the ends of the data it flagged plain noise as a jump and cut off the first few samples).
  bool PredictFrom(Eigen::Index j, int direction, Point* prediction,
                   double at = std::numeric_limits<double>::quiet_NaN()) const {
    if (std::isnan(at)) at = mid_[j];
    double s0 = 0, s1 = 0, s2 = 0;
    Point b0 = Point::Zero(d_), b1 = Point::Zero(d_);
    int count = 0;
    for (Eigen::Index i = j + direction, step = 1; i >= 0 && i < n_ && count < kSide && step <= 3 * kSide;
         i += direction, ++step) {
      if (cut_[static_cast<size_t>(i)]) break;
      if (step <= kSkip || masked_[static_cast<size_t>(i)]) continue;
      const double u = mid_[i] - at;
      s0 += 1.0, s1 += u, s2 += u * u;
      b0 += slopes_.row(i).transpose();
      b1 += u * slopes_.row(i).transpose();
      ++count;
    }
    if (count < kSide / 2) return false;
    const double determinant = s0 * s2 - s1 * s1;
    if (!(determinant > 1e-12 * s2 * s0)) {
      *prediction = b0 / s0;
      return true;
    }
    // Value at u = 0 of the line a + b·u: a = (s2·b0 − s1·b1) / det.
    *prediction = (s2 * b0 - s1 * b1) / determinant;
    return true;
  }

  Eigen::Index n_, d_;
  Eigen::MatrixXd slopes_;
  Eigen::VectorXd mid_, dt_;
  std::vector<char> cut_, masked_;
  Eigen::VectorXd noise_floor_;
  Eigen::MatrixXd block_floor_;  // per block of the noise profile; empty: noise_floor_ everywhere
  const NoiseProfile* profile_ = nullptr;  // the profile block_floor_ comes from
};

// The samples beside boundary b that estimate it: up to kStepSamples on either side, not across a
// cut, outliers left out (ascending).
std::vector<Eigen::Index> SamplesBeside(Eigen::Index b, Eigen::Index m, const std::vector<char>& cut,
                                        const std::vector<char>& left_out) {
  Eigen::Index first = b, last = b + 1;
  while (first > 0 && b - first + 1 < kStepSamples && !cut[static_cast<size_t>(first - 1)]) --first;
  while (last + 1 < m && last - b < kStepSamples && !cut[static_cast<size_t>(last)]) ++last;
  std::vector<Eigen::Index> used;
  for (Eigen::Index i = first; i <= last; ++i) {
    if (!left_out[static_cast<size_t>(i)]) used.push_back(i);
  }
  return used;
}

// The cubic with a jump of the value and of the rate at boundary b, as a design matrix over the
// samples `used` (SamplesBeside): columns 1, u, u², u³, [i > b], [i > b]·u, with u the time from
// the boundary's middle over half the samples' span.
Eigen::MatrixXd BrokenCubic(const Eigen::VectorXd& t, const std::vector<Eigen::Index>& used, Eigen::Index b) {
  const double centre = 0.5 * (t[b] + t[b + 1]), half = 0.5 * (t[used.back()] - t[used.front()]);
  Eigen::MatrixXd a(static_cast<Eigen::Index>(used.size()), 6);
  for (Eigen::Index r = 0; r < a.rows(); ++r) {
    const Eigen::Index i = used[static_cast<size_t>(r)];
    const double u = (t[i] - centre) / half, after = i > b ? 1.0 : 0.0;
    a.row(r) << 1.0, u, u * u, u * u * u, after, after * u;
  }
  return a;
}

// The residual variance of a 6-parameter fit to `rows` samples with residual sum of squares
// `rss`, never below the samples' noise variance in coordinate c: a noise-free fit's rounding is
// not evidence.
double FlooredVariance(double rss, Eigen::Index rows, const SlopeScan& scan, Eigen::Index c) {
  return std::max(rss / static_cast<double>(rows - 6), scan.SampleNoise(c) * scan.SampleNoise(c));
}

// Each step again, from the samples themselves: a cubic through kStepSamples samples on either
// side plus the step, least squares, the other steps in reach taken out first (the slope-based
// estimate carries its lines' prediction error). The same fit with a jump of the rate as well tells
// whether the rate goes on across: when that jump is significant in any coordinate
// (kRateJumpScore standard errors, with the residual variance never below the samples' noise
// variance: a noise-free fit's rounding is not evidence), the step is a break after all.
void RefineSteps(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, const std::vector<Eigen::Index>& gaps,
                 const SlopeScan& scan, Jumps& jumps) {
  const Eigen::Index m = t.size();
  std::vector<char> left_out(static_cast<size_t>(m), 0), cut(static_cast<size_t>(m), 0);
  for (const Eigen::Index i : jumps.outliers) left_out[static_cast<size_t>(i)] = 1;
  for (const Eigen::Index b : gaps) cut[static_cast<size_t>(b)] = 1;
  for (const Eigen::Index b : jumps.breaks) cut[static_cast<size_t>(b)] = 1;
  std::vector<char> rate_jumps(jumps.steps.size(), 0);
  for (size_t k = 0; k < jumps.steps.size(); ++k) {
    const Eigen::Index b = jumps.steps[k].first;
    const std::vector<Eigen::Index> used = SamplesBeside(b, m, cut, left_out);
    const auto rows = static_cast<Eigen::Index>(used.size());
    if (rows < 10) continue;
    const Eigen::MatrixXd a = BrokenCubic(t, used, b);
    Eigen::MatrixXd y(rows, z.cols());
    for (Eigen::Index r = 0; r < rows; ++r) {
      const Eigen::Index i = used[static_cast<size_t>(r)];
      y.row(r) = z.row(i);
      for (size_t o = 0; o < jumps.steps.size(); ++o) {  // the other steps between this one and sample i
        const Eigen::Index s = jumps.steps[o].first;
        if (o == k) continue;
        if (s < b && i <= s) y.row(r) += jumps.steps[o].second.transpose();
        if (s > b && i > s) y.row(r) -= jumps.steps[o].second.transpose();
      }
    }
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> with_rate(a);
    const Eigen::MatrixXd full = with_rate.solve(y);
    const Eigen::MatrixXd inverse = (a.transpose() * a).inverse();
    for (Eigen::Index c = 0; c < z.cols(); ++c) {
      const double variance = FlooredVariance((y.col(c) - a * full.col(c)).squaredNorm(), rows, scan, c);
      if (std::abs(full(5, c)) > kRateJumpScore * std::sqrt(variance * inverse(5, 5))) rate_jumps[k] = 1;
    }
    jumps.steps[k].second = a.leftCols(5).colPivHouseholderQr().solve(y).row(4).transpose();
  }
  std::vector<std::pair<Eigen::Index, Eigen::VectorXd>> steps;
  for (size_t k = 0; k < jumps.steps.size(); ++k) {
    if (rate_jumps[k]) {
      jumps.breaks.push_back(jumps.steps[k].first);
    } else {
      steps.push_back(std::move(jumps.steps[k]));
    }
  }
  jumps.steps = std::move(steps);
  std::sort(jumps.breaks.begin(), jumps.breaks.end());
}

// Whether the samples beside boundary b (kStepSamples a side, not across a gap, outliers left out)
// are told better by motion that breaks at b than by smooth motion of as many parameters: a cubic
// with a jump of the value and of the rate against a quintic, least squares, per coordinate. The
// break is kept when in some coordinate its residual sum of squares is below the quintic's by
// kSmoothMargin variances of the samples about it (its residual variance, never below the noise's:
// where neither fits, that is the misfit's). The slopes' lines judge departures against the noise;
// where the noise is far below what lines through smooth motion can follow (the nearly exact
// positions of a fast start or stop, whose rate's 3rd derivative jumps), smooth motion departs too
// and was cut into pieces whose one-sided ends were 0.3 m/s off (docs/velocity.md, "Jumps and
// glitches").
bool BreakBeatsSmoothMotion(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, const std::vector<char>& gap,
                            const std::vector<char>& left_out, const SlopeScan& scan, Eigen::Index b) {
  const std::vector<Eigen::Index> used = SamplesBeside(b, t.size(), gap, left_out);
  const auto rows = static_cast<Eigen::Index>(used.size());
  if (rows < 10) return true;  // too few to tell: the slopes' verdict stands
  const Eigen::MatrixXd broken = BrokenCubic(t, used, b);
  Eigen::MatrixXd smooth(rows, 6), y(rows, z.cols());
  for (Eigen::Index r = 0; r < rows; ++r) {
    const double u = broken(r, 1);
    smooth.row(r) << 1.0, u, u * u, u * u * u, u * u * u * u, u * u * u * u * u;
    // About the first sample: positions may lie far from the origin.
    y.row(r) = z.row(used[static_cast<size_t>(r)]) - z.row(used[0]);
  }
  const Eigen::MatrixXd broken_residual = y - broken * broken.colPivHouseholderQr().solve(y);
  const Eigen::MatrixXd smooth_residual = y - smooth * smooth.colPivHouseholderQr().solve(y);
  for (Eigen::Index c = 0; c < z.cols(); ++c) {
    const double with_break = broken_residual.col(c).squaredNorm();
    const double margin = kSmoothMargin * FlooredVariance(with_break, rows, scan, c);
    if (smooth_residual.col(c).squaredNorm() - with_break > margin) return true;
  }
  return false;
}

}  // namespace

Jumps FindJumps(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, const std::vector<Eigen::Index>& gaps,
                const Eigen::VectorXd& noise, const NoiseProfile* profile, int threads) {
  Jumps jumps;
  if (t.size() < 2 * (kSide + kSkip) + 2) return jumps;
  SlopeScan scan(t, z, gaps, noise, profile);
  const Eigen::Index n = scan.size();
  std::vector<char> left_out(static_cast<size_t>(t.size()), 0);  // the outliers found so far
  // Strongest first: a jump's own slope outranks the neighbours it disturbs. Each candidate is
  // scored again just before it is judged (earlier findings change its neighbours' lines).
  // The local scale is taken again each pass, without the slopes found so far: dense defects (a
  // correction every few samples) inflate the first pass's scale and hide all but the largest.
  for (int pass = 0; pass < kPasses; ++pass) {
    Eigen::MatrixXd one_sided;
    const Eigen::MatrixXd departures = scan.Departures(threads, &one_sided);
    const Eigen::MatrixXd scale = scan.Scales(departures, one_sided, threads);
    std::vector<std::pair<double, Eigen::Index>> candidates;
    for (Eigen::Index j = 0; j < n; ++j) {
      if (std::isnan(departures(j, 0))) continue;
      const double score = scan.Score(j, departures.row(j), scale);
      if (score > kThreshold) candidates.emplace_back(score, j);
    }
    if (candidates.empty()) break;
    std::sort(candidates.begin(), candidates.end(), std::greater<>());
    bool changed = false;
    for (const auto& [initial, j] : candidates) {
      Eigen::VectorXd e, disagreement;
      if (scan.Score(j, scale, &e, &disagreement) <= kThreshold) continue;
      // A displaced sample moves the slopes on both of its sides by opposite amounts while the
      // lines on either side agree (at a jump of the rate they do not): look for the neighbour
      // slope that undoes this one's displacement.
      const Eigen::VectorXd displacement = e * scan.dt(j);
      std::optional<Eigen::Index> partner;
      double best_mismatch = 0.5;
      for (const Eigen::Index k : {j - 1, j + 1}) {
        if (k < 0 || k >= n || disagreement.norm() > 0.5 * e.norm()) continue;
        Eigen::VectorXd ek;
        if (scan.Score(k, scale, &ek) <= 0.5 * kThreshold) continue;
        const Eigen::VectorXd dk = ek * scan.dt(k);
        const double mismatch = (displacement + dk).norm() / std::max(displacement.norm(), dk.norm());
        if (mismatch < best_mismatch) best_mismatch = mismatch, partner = k;
      }
      // Else an excursion: a few consecutive samples leave the motion, each its own way, and the
      // samples on either side connect as if they were not there. The shortest one through slope j
      // that can be left out cleanly (BridgeScore), across which both sides' lines agree (as for a
      // glitch) and whose first and last slopes both depart; its samples are left out. Taken for
      // jumps, a burst of two glitches of 0.5 m cut the data into pieces whose fits followed them,
      // 73 m/s off.
      Eigen::Index first = 0, last = -1;
      for (Eigen::Index length = 2; !partner && last < first && length <= kBurst; ++length) {
        double best = kBridgeScore;
        for (Eigen::Index a = j - length + 1; a <= j + 1; ++a) {
          const Eigen::Index b = a + length - 1;
          Eigen::VectorXd bridge_disagreement;
          if (scan.Raised(a - 1) || scan.Raised(b)) continue;
          const double bridge = scan.BridgeScore(a, b, scale, left_out, &bridge_disagreement);
          if (!(bridge <= best) || bridge_disagreement.norm() > 0.5 * e.norm()) continue;
          // Its edges are defects themselves (or were already left out as a glitch's, part of this
          // excursion). At half the threshold, as for a glitch's partner (whose displacement must
          // also match), corrections of EuRoC's ground truth that change the rate too were taken
          // for excursions of two samples (MH_05 1.2 -> 3.1 mm/s against its own velocity); with
          // 8 samples, one of a correction of 2 mm whose bridge held it (1.2 -> 1.6).
          auto departs = [&](Eigen::Index k) { return !scan.Usable(k) || scan.Score(k, scale) > kThreshold; };
          if (!departs(a - 1) || !departs(b)) continue;
          best = bridge, first = a, last = b;
        }
      }
      if (partner) {
        jumps.outliers.push_back(std::max(j, *partner));  // the sample the two slopes share
        left_out[static_cast<size_t>(std::max(j, *partner))] = 1;
        scan.Mask(j);
        scan.Mask(*partner);
      } else if (last >= first) {
        for (Eigen::Index i = first; i <= last; ++i) jumps.outliers.push_back(i), left_out[static_cast<size_t>(i)] = 1;
        for (Eigen::Index k = first - 1; k <= last; ++k) scan.Mask(k);
      } else {
        // The motion jumps between samples b and b + 1. When slope b alone departs while both
        // sides' lines agree, the rate goes on across: a step of the values, taken out (slope b is
        // left out of its neighbours' lines). Otherwise the rate jumps too: split there.
        const Eigen::Index b = scan.LocateBreak(j, scale);
        Eigen::VectorXd eb, disagreement_b;
        if (scan.Score(b, scale, &eb, &disagreement_b) > kThreshold && disagreement_b.norm() <= 0.5 * eb.norm()) {
          jumps.steps.emplace_back(b, eb * scan.dt(b));
          scan.Mask(b);
        } else {
          jumps.breaks.push_back(b);
          scan.Cut(b);
        }
      }
      changed = true;
    }
    if (!changed) break;
  }
  // Breaks and steps that smooth motion explains as well are not defects (BreakBeatsSmoothMotion).
  std::vector<char> gap(static_cast<size_t>(t.size()), 0);
  for (const Eigen::Index b : gaps) gap[static_cast<size_t>(b)] = 1;
  auto smooth = [&](Eigen::Index b) { return !BreakBeatsSmoothMotion(t, z, gap, left_out, scan, b); };
  jumps.breaks.erase(std::remove_if(jumps.breaks.begin(), jumps.breaks.end(), smooth), jumps.breaks.end());
  jumps.steps.erase(std::remove_if(jumps.steps.begin(), jumps.steps.end(),
                                   [&](const auto& step) { return smooth(step.first); }),
                    jumps.steps.end());
  std::sort(jumps.outliers.begin(), jumps.outliers.end());
  jumps.outliers.erase(std::unique(jumps.outliers.begin(), jumps.outliers.end()), jumps.outliers.end());
  std::sort(jumps.breaks.begin(), jumps.breaks.end());
  std::sort(jumps.steps.begin(), jumps.steps.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  RefineSteps(t, z, gaps, scan, jumps);
  return jumps;
}

}  // namespace cheval::cheb::internal

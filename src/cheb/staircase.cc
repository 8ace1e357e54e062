#include "staircase.h"

#include "noise_profile.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace cheval::cheb::internal {
namespace {

// What makes a clean staircase (docs/velocity.md, "Rounded positions"; docs/decisions.md):
// - kZeroShare of the differences zero at least: four samples a step on average. Without it, tones
//   rounded to 1 mm at 200 Hz slowed 3x, two to three samples a step, came 45 % worse placed than
//   as read.
// - kSingleShare of the others one step at least (a glitch, or motion faster than a step a
//   sample, fixes no edge).
// - kUndoneShare at most of the one-step crossings cross the same edge back as the one before
//   (the motion's turns inside a step do it too: 17 % of the crossings of the slow hand-held
//   motion's least-moving axis).
// - kQuickShare at most of them do so within kQuickSamples samples. Noise at a step's edge flips
//   the values back and forth, and the instants of those flips are the noise's: with noise of
//   1/100, 1/50 and 1/20 of the step on the slow hand-held motion 0–4 %, 2–22 % and 16–57 % of
//   the crossings, and the fit of the values placed at 1/20 was 2x worse than as read; the
//   motion's own turns, 0–3 %.
// - kMinCrossings one-step crossings at least.
// - The noise of the values placed (from how well the crossings predict each other) at most
//   kPlacedShare of the rounding's q/sqrt(12). Its errors run smoothly from crossing to crossing,
//   and the fit follows them more readily than the rounding's: placed wherever the floor was
//   below the rounding's, tones rounded to 1 mm at 100 and 200 Hz slowed 10x came 10–12 % worse
//   than as read.
constexpr double kZeroShare = 0.75;
constexpr double kSingleShare = 0.95;
constexpr double kUndoneShare = 0.25;
constexpr double kQuickShare = 0.05;
constexpr Eigen::Index kQuickSamples = 3;
constexpr Eigen::Index kMinCrossings = 16;
constexpr double kPlacedShare = 0.5;

// A crossing: the values pass from one step to the next between two samples, at the middle of
// whose interval the motion is taken to be at the edge between the steps.
struct Crossing {
  double time = 0.0, level = 0.0, slope = 0.0;  // level and slope in steps
};

// Slopes of a C¹ cubic through the crossings (Bessel's): the derivative of the parabola through a
// crossing and its two neighbours, at the ends through the last three (a turn inside the last
// step leaves two crossings of one edge there, whose secant is level), with two crossings their
// secant.
void SetSlopes(std::vector<Crossing>& crossings) {
  const size_t n = crossings.size();
  auto secant = [&](size_t j) {
    return (crossings[j + 1].level - crossings[j].level) / (crossings[j + 1].time - crossings[j].time);
  };
  auto spacing = [&](size_t j) { return crossings[j + 1].time - crossings[j].time; };
  if (n == 2) {
    crossings[0].slope = crossings[1].slope = secant(0);
    return;
  }
  for (size_t j = 1; j + 1 < n; ++j) {
    crossings[j].slope = (secant(j - 1) * spacing(j) + secant(j) * spacing(j - 1)) / (spacing(j - 1) + spacing(j));
  }
  crossings.front().slope = secant(0) - (secant(1) - secant(0)) * spacing(0) / (spacing(0) + spacing(1));
  crossings.back().slope = secant(n - 2) + (secant(n - 2) - secant(n - 3)) * spacing(n - 2) / (spacing(n - 3) + spacing(n - 2));
}

// The cubic Hermite interpolant between crossings a and b at time x.
double Hermite(const Crossing& a, const Crossing& b, double x) {
  const double h = b.time - a.time, u = (x - a.time) / h, u2 = u * u, u3 = u2 * u;
  return (2.0 * u3 - 3.0 * u2 + 1.0) * a.level + (u3 - 2.0 * u2 + u) * h * a.slope + (3.0 * u2 - 2.0 * u3) * b.level +
         (u3 - u2) * h * b.slope;
}

// Beyond the first or last crossing `edge`, up to the stretch's end sample at time `end` in step
// `step`: the line of the edge's slope where it stays inside that step up to the end; where it
// would leave it, the motion has slowed, and the cubic from the edge reaches the step's boundary
// at the end with slope 0 instead of running along it.
Crossing EndOf(const Crossing& edge, double end, double step) {
  const double line = edge.level + edge.slope * (end - edge.time);
  const double held = std::clamp(line, step - 0.5, step + 0.5);
  return {end, held, held == line ? edge.slope : 0.0};
}

}  // namespace

std::optional<double> PlaceBetweenSteps(const Eigen::Ref<const Eigen::VectorXd>& t, Eigen::Ref<Eigen::VectorXd> z,
                                        const Eigen::VectorXd& steps, double q,
                                        const std::vector<Eigen::Index>& breaks) {
  const Eigen::Index m = z.size();
  if (m < 5 || !(q > 0.0)) return std::nullopt;
  const double origin = z[0];

  // Stretches [begin, end] between the breaks.
  std::vector<std::pair<Eigen::Index, Eigen::Index>> stretches;
  Eigen::Index begin = 0;
  for (const Eigen::Index b : breaks) {
    stretches.emplace_back(begin, b);
    begin = b + 1;
  }
  stretches.emplace_back(begin, m - 1);

  Eigen::Index zero = 0, single = 0, other = 0, undone = 0, quick = 0;
  for (const auto& [first, last] : stretches) {
    double before = 0.0;  // the last one-step difference, 0 after a larger one
    Eigen::Index at = first;  // and the sample it ended at
    for (Eigen::Index i = first + 1; i <= last; ++i) {
      const double d = steps[i] - steps[i - 1];
      if (d == 0.0) {
        ++zero;
      } else if (std::abs(d) == 1.0) {
        ++single;
        if (before == -d) {
          ++undone;
          quick += i - at <= kQuickSamples;
        }
        before = d;
        at = i;
      } else {
        ++other;
        before = 0.0;
      }
    }
  }
  const auto share = [](Eigen::Index part, Eigen::Index whole) {
    return static_cast<double>(part) / static_cast<double>(std::max<Eigen::Index>(whole, 1));
  };
  if (single < kMinCrossings || share(zero, zero + single + other) < kZeroShare ||
      share(single, single + other) < kSingleShare || share(undone, single) > kUndoneShare ||
      share(quick, single) > kQuickShare) {
    return std::nullopt;
  }

  // The crossings of each stretch.
  std::vector<std::vector<Crossing>> crossings(stretches.size());
  for (size_t k = 0; k < stretches.size(); ++k) {
    const auto [first, last] = stretches[k];
    for (Eigen::Index i = first + 1; i <= last; ++i) {
      const double d = steps[i] - steps[i - 1];
      const double time = 0.5 * (t[i - 1] + t[i]);
      // Larger differences (a glitch, or motion faster than a step a sample) fix no edge; a
      // crossing at the instant of the one before (repeated stamps) adds nothing.
      if (std::abs(d) != 1.0 || (!crossings[k].empty() && time <= crossings[k].back().time)) continue;
      crossings[k].push_back({time, std::min(steps[i - 1], steps[i]) + 0.5, 0.0});
    }
  }
  // How well the crossings tell each other: each predicted by the cubic through its two neighbours
  // on either side. Its error is the crossings' own (the motion over their intervals) and the
  // motion between crossings that no crossing shows (a turn inside a step), over twice their
  // spacing; divided by 1 + Σw² (w the cubic's weights), it is one crossing's where the former
  // dominates, and more than the placed values' where the latter does.
  double squares = 0.0;
  Eigen::Index count = 0;
  for (const std::vector<Crossing>& stretch : crossings) {
    for (size_t j = 2; j + 2 < stretch.size(); ++j) {
      const std::array<size_t, 4> others{j - 2, j - 1, j + 1, j + 2};
      double predicted = 0.0, weights = 0.0;
      for (const size_t a : others) {
        double w = 1.0;
        for (const size_t b : others) {
          if (b != a) w *= (stretch[j].time - stretch[b].time) / (stretch[a].time - stretch[b].time);
        }
        predicted += w * stretch[a].level;
        weights += w * w;
      }
      const double error = stretch[j].level - predicted;
      squares += error * error / (1.0 + weights);
      ++count;
    }
  }
  if (count < kMinCrossings) return std::nullopt;
  const double sigma = q * std::sqrt(squares / static_cast<double>(count));
  // Placed not clearly better than rounded: the values stay as read.
  if (!(sigma < kPlacedShare * q / std::sqrt(12.0))) return std::nullopt;

  for (size_t k = 0; k < stretches.size(); ++k) {
    std::vector<Crossing>& stretch = crossings[k];
    if (stretch.size() < 2) continue;  // nothing to draw a curve through: the values stay
    SetSlopes(stretch);
    const auto [first, last] = stretches[k];
    const Crossing start = EndOf(stretch.front(), t[first], steps[first]);
    const Crossing end = EndOf(stretch.back(), t[last], steps[last]);
    size_t j = 0;
    for (Eigen::Index i = first; i <= last; ++i) {
      while (j + 1 < stretch.size() && stretch[j + 1].time <= t[i]) ++j;
      const double x = t[i];
      const double cubic = x < stretch.front().time ? (x == start.time ? start.level : Hermite(start, stretch.front(), x))
                           : j + 1 < stretch.size() ? Hermite(stretch[j], stretch[j + 1], x)
                           : x == end.time          ? end.level
                                                    : Hermite(stretch.back(), end, x);
      z[i] = origin + q * std::clamp(cubic, steps[i] - 0.5, steps[i] + 0.5);
    }
  }
  return sigma;
}

}  // namespace cheval::cheb::internal

#include "local_rates.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace cheval::cheb::internal {
namespace {

// A slope departing from the mean of its two neighbours by more than this many local scales (and
// more than they do) is an isolated spike: a small step of the values (docs/velocity.md).
constexpr double kSpikeScales = 4.0;
// Slopes per block of the local scale.
constexpr Eigen::Index kBlock = 64;

// Which slopes (between samples j and j + 1 of the segment, per coordinate) are not spikes.
Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic> UsableSlopes(const Eigen::VectorXd& h, const Eigen::MatrixXd& slopes,
                                                                const Eigen::VectorXd& sigma) {
  const Eigen::Index n = slopes.rows(), d = slopes.cols();
  Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic> usable =
      Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic>::Constant(n, d, true);
  if (n < 3) return usable;
  // Samples with equal stamps have no slope between them.
  for (Eigen::Index j = 0; j < n; ++j) usable.row(j).setConstant(h[j] > 0.0);
  // Departures of the interior slopes (where all three exist), in units of the local scale.
  Eigen::MatrixXd departure = Eigen::MatrixXd::Zero(n, d);
  for (Eigen::Index j = 1; j + 1 < n; ++j) {
    if (h[j - 1] > 0.0 && h[j] > 0.0 && h[j + 1] > 0.0) {
      departure.row(j) = slopes.row(j) - 0.5 * (slopes.row(j - 1) + slopes.row(j + 1));
    }
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
        const double floor = std::sqrt(5.0) * sigma[c] / h[j];
        const double s = std::max(scale, floor);
        score[j] = s > 0.0 ? std::abs(departure(j, c)) / s : 0.0;
      }
    }
    for (Eigen::Index j = 1; j + 1 < n; ++j) {
      if (score[j] > kSpikeScales && score[j] >= score[j - 1] && score[j] >= score[j + 1]) usable(j, c) = false;
    }
  }
  return usable;
}

}  // namespace

std::vector<LocalRun> LocalRuns(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, Eigen::Index first,
                                Eigen::Index last, const CurveSegment& segment, const Eigen::MatrixXd& fit_values,
                                const Eigen::MatrixXd& fit_rates, const Eigen::VectorXd& sigma, double lack_of_fit_limit) {
  std::vector<LocalRun> runs;
  const Eigen::Index n = last - first, d = z.cols();
  if (n < 3 || segment.windows.empty()) return runs;
  // Local samples and coordinates: in the core of a window that clearly missed motion there.
  Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic> local =
      Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic>::Constant(n, d, false);
  const std::vector<CurveWindow>& windows = segment.windows;
  size_t w = 0;
  bool any = false;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double ti = t[first + i];
    while (w + 1 < windows.size() && ti >= windows[w + 1].core_begin) ++w;
    const CurveWindow& window = windows[w];
    if (window.verdict != WindowVerdict::kUnresolved || window.lack_of_fit.size() != d) continue;
    for (Eigen::Index c = 0; c < d; ++c) {
      local(i, c) = window.lack_of_fit[c] > lack_of_fit_limit && window.residual_rms[c] >= std::sqrt(2.0) * sigma[c];
      any = any || local(i, c);
    }
  }
  if (!any) return runs;

  const Eigen::VectorXd h = t.segment(first + 1, n - 1) - t.segment(first, n - 1);
  Eigen::MatrixXd slopes = Eigen::MatrixXd::Zero(n - 1, d);
  for (Eigen::Index j = 0; j + 1 < n; ++j) {
    if (h[j] > 0.0) slopes.row(j) = (z.row(first + j + 1) - z.row(first + j)) / h[j];
  }
  const auto usable = UsableSlopes(h, slopes, sigma);
  // The derivative at sample i of the quadratic through it and its neighbours, from usable slopes.
  auto rate = [&](Eigen::Index i, Eigen::Index c) {
    const bool left = i >= 1 && usable(i - 1, c), right = i + 1 < n && usable(i, c);
    if (left && right) return (h[i] * slopes(i - 1, c) + h[i - 1] * slopes(i, c)) / (h[i - 1] + h[i]);
    if (right) {
      if (i + 2 < n && usable(i + 1, c)) {
        return slopes(i, c) - h[i] * (slopes(i + 1, c) - slopes(i, c)) / (h[i] + h[i + 1]);
      }
      return slopes(i, c);
    }
    if (left) {
      if (i >= 2 && usable(i - 2, c)) {
        return slopes(i - 1, c) + h[i - 1] * (slopes(i - 1, c) - slopes(i - 2, c)) / (h[i - 2] + h[i - 1]);
      }
      return slopes(i - 1, c);
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
    for (Eigen::Index k = begin; k < stop; ++k) {
      // A sample at the stamp of the one before it adds no interval (the first one stays).
      if (!run.times.empty() && !(t[first + k] > run.times.back())) continue;
      const auto r = static_cast<Eigen::Index>(run.times.size());
      run.times.push_back(t[first + k]);
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
    i = end;
    if (run.times.size() < 2) continue;  // no interval to interpolate over
    run.values.conservativeResize(static_cast<Eigen::Index>(run.times.size()), d);
    run.rates.conservativeResize(static_cast<Eigen::Index>(run.times.size()), d);
    runs.push_back(std::move(run));
  }
  return runs;
}

}  // namespace cheval::cheb::internal

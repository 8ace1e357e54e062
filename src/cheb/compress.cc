#include "cheval/cheb/compress.h"

#include "conditioning.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <optional>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cheval/cheb/chebyshev.h"
#include "cheval/cheb/fit.h"
#include "cheval/common/error.h"
#include "cheval/common/options.h"
#include "cheval/traj/stamp.h"

namespace cheval::cheb {
namespace {

using internal::kMaxGramCondition;
// A candidate fit is first checked on about this many of its samples: one beyond the tolerance
// there rejects it without evaluating the rest (the common case for too-low degrees).
constexpr Eigen::Index kProbeSamples = 1024;

// The samples in time order (as FitCurve orders them), with times in seconds from the origin.
struct SortedSamples {
  std::vector<int64_t> stamps;
  Eigen::VectorXd t;
  Eigen::MatrixXd z;

  SortedSamples(std::span<const int64_t> stamps_ns, const Eigen::Ref<const Eigen::MatrixXd>& values,
                int64_t origin_ns) {
    const auto m = static_cast<Eigen::Index>(stamps_ns.size());
    std::vector<Eigen::Index> order(static_cast<size_t>(m));
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(),
                     [&](Eigen::Index i, Eigen::Index j) { return stamps_ns[i] < stamps_ns[j]; });
    t.resize(m);
    z.resize(m, values.cols());
    for (Eigen::Index i = 0; i < m; ++i) {
      stamps.push_back(stamps_ns[order[i]]);
      t[i] = static_cast<double>(stamps.back() - origin_ns) * 1e-9;
      z.row(i) = values.row(order[i]);
    }
  }

  // Indices [first, last) of the samples with time in [a, b].
  std::pair<Eigen::Index, Eigen::Index> Range(double a, double b) const {
    const double* begin = t.data();
    const double* end = t.data() + t.size();
    return {std::lower_bound(begin, end, a) - begin, std::upper_bound(begin, end, b) - begin};
  }
};

// The least-squares fits of one window at every degree up to its cap, from one factorisation of
// its normal equations, each stored through its values (exactly as CurveFromModel rebuilds it) and
// judged at the samples where the curve may use the window.
class WindowFits {
 public:
  WindowFits(const SortedSamples& s, const ModelWindow& window, const CurveOptions& options, double tolerance)
      : window_(window), tolerance_(tolerance) {
    const auto [first, last] = s.Range(window.fit_begin, window.fit_end);
    const Eigen::Index m = last - first;
    Eigen::Index distinct = m > 0 ? 1 : 0;
    for (Eigen::Index i = first + 1; i < last; ++i) distinct += s.t[i] != s.t[i - 1] ? 1 : 0;
    cap_ = static_cast<int>(std::min<double>({static_cast<double>(options.max_degree),
                                              std::floor(std::sqrt(options.max_conditioning * static_cast<double>(m))),
                                              static_cast<double>(distinct - 1)}));
    if (cap_ < 0) return;
    const Interval interval{window.fit_begin, window.fit_end};
    normal_ = BuildNormalEquations(s.t.segment(first, m), s.z.middleRows(first, m), cap_, interval);
    // Uneven sampling can make the top degrees ill-posed: lower the cap until they are not.
    while (cap_ >= 0) {
      try {
        cholesky_.emplace(normal_, cap_);
        if (cholesky_->Condition(cap_) <= kMaxGramCondition) break;
      } catch (const ComputeError&) {
      }
      cholesky_.reset();
      cap_ = cap_ > 1 ? static_cast<int>(0.7 * cap_) : cap_ - 1;
    }
    // The curve uses a window on its core and, in a blending zone, at most half of its overlap
    // beyond it on either side (Curve blends over half the overlap two neighbours share).
    const auto [c0, c1] = s.Range(window.core_begin - 0.5 * (window.core_begin - window.fit_begin),
                                  window.core_end + 0.5 * (window.fit_end - window.core_end));
    x_.resize(c1 - c0);
    for (Eigen::Index i = c0; i < c1; ++i) x_[i - c0] = interval.ToUnit(s.t[i]);
    z_ = s.z.middleRows(c0, c1 - c0);
    const Eigen::Index stride = std::max<Eigen::Index>(1, x_.size() / kProbeSamples);
    for (Eigen::Index i = 0; i < x_.size(); i += stride) probe_.push_back(i);
  }

  /// Highest degree allowed (-1: the window has no sample to fit).
  int cap() const { return cap_; }
  int dimension() const { return static_cast<int>(z_.cols()); }

  /// Whether coordinate c at degree n is within the tolerance at every judged sample.
  bool Within(int c, int n) { return Within(std::vector<std::pair<int, int>>{{c, n}}); }
  /// Whether the fit at `degrees` (one per coordinate) is within it in the Euclidean norm.
  bool Within(const std::vector<int>& degrees) { return Within(Pairs(degrees)); }

  /// The coordinate below the cap whose residual is largest at the judged sample of largest error
  /// norm at `degrees` (-1 when all are at the cap).
  int DominantCoordinate(const std::vector<int>& degrees) {
    const Eigen::VectorXd squares = SquaredNorms(Pairs(degrees), false);
    Eigen::Index worst = 0;
    squares.maxCoeff(&worst);
    int best = -1;
    for (int c = 0; c < dimension(); ++c) {
      const int n = degrees[static_cast<size_t>(c)];
      if (n < cap_ && (best < 0 || std::abs(Residuals(c, n, false)[worst]) >
                                       std::abs(Residuals(best, degrees[static_cast<size_t>(best)], false)[worst]))) {
        best = c;
      }
    }
    return best;
  }

  ModelWindow Window(const std::vector<int>& degrees) {
    ModelWindow w{window_.core_begin, window_.core_end, window_.fit_begin, window_.fit_end, {}};
    for (int c = 0; c < dimension(); ++c) w.values.push_back(Get(c, degrees[static_cast<size_t>(c)]).values);
    return w;
  }

 private:
  struct Fit {
    Eigen::VectorXd values, coefficients;        // through the values
    Eigen::VectorXd probe_residuals, residuals;  // fit - sample (empty until needed)
  };

  static std::vector<std::pair<int, int>> Pairs(const std::vector<int>& degrees) {
    std::vector<std::pair<int, int>> pairs;
    for (size_t c = 0; c < degrees.size(); ++c) pairs.emplace_back(static_cast<int>(c), degrees[c]);
    return pairs;
  }

  bool Within(const std::vector<std::pair<int, int>>& fits) {
    const double limit = tolerance_ * tolerance_;
    if (x_.size() == 0) return true;
    return SquaredNorms(fits, true).maxCoeff() <= limit && SquaredNorms(fits, false).maxCoeff() <= limit;
  }

  Eigen::VectorXd SquaredNorms(const std::vector<std::pair<int, int>>& fits, bool probe) {
    Eigen::VectorXd squares = Eigen::VectorXd::Zero(probe ? probe_.size() : x_.size());
    for (const auto& [c, n] : fits) squares += Residuals(c, n, probe).cwiseAbs2();
    return squares;
  }

  const Eigen::VectorXd& Residuals(int c, int n, bool probe) {
    Fit& fit = Get(c, n);
    Eigen::VectorXd& r = probe ? fit.probe_residuals : fit.residuals;
    if (r.size() == 0 && x_.size() > 0) {
      if (probe) {
        const Eigen::VectorXd x = x_(probe_);
        r = EvaluateSeries(fit.coefficients, x).col(0) - z_.col(c)(probe_);
      } else {
        r = EvaluateSeries(fit.coefficients, x_).col(0) - z_.col(c);
      }
    }
    return r;
  }

  Fit& Get(int c, int n) {
    auto [it, inserted] = cache_.try_emplace({c, n});
    if (inserted) {
      it->second.values = CoefficientsToValues(cholesky_->Solve(n, normal_.rhs.col(c)));
      it->second.coefficients = ValuesToCoefficients(it->second.values);
    }
    return it->second;
  }

  ModelWindow window_;
  double tolerance_;
  int cap_ = -1;
  NormalEquations normal_;
  std::optional<NestedCholesky> cholesky_;
  Eigen::VectorXd x_;
  Eigen::MatrixXd z_;
  std::vector<Eigen::Index> probe_;
  std::map<std::pair<int, int>, Fit> cache_;
};

// Covers one segment with windows that are each within the tolerance wherever the curve may use
// them (so the blended curve is too): a window is kept at the smallest degrees that meet it, or
// halved when even its cap does not.
class ToleranceFitter {
 public:
  ToleranceFitter(const SortedSamples& samples, double tolerance, const CurveOptions& options, double segment_begin,
                  double segment_end)
      : samples_(samples), tolerance_(tolerance), options_(options), begin_(segment_begin), end_(segment_end) {}

  // Appends the windows covering core [a, b] to `out`; returns whether they all meet the tolerance.
  bool Cover(double a, double b, std::vector<ModelWindow>* out) const {
    const double extension = options_.overlap * (b - a);
    const ModelWindow window{a, b, std::max(a - extension, begin_), std::min(b + extension, end_), {}};
    WindowFits fits(samples_, window, options_, tolerance_);
    const int d = fits.dimension(), cap = fits.cap();
    if (cap >= 0 && fits.Within(std::vector<int>(static_cast<size_t>(d), cap))) {
      out->push_back(fits.Window(SmallestDegrees(&fits)));
      return true;
    }
    // Halve when each half keeps at least min_window_samples samples in its core.
    const double middle = 0.5 * (a + b);
    const auto [first, mid] = samples_.Range(a, middle);
    const auto [after_mid, last] = samples_.Range(middle, b);
    const auto least = static_cast<Eigen::Index>(options_.min_window_samples);
    if (middle > a && middle < b && mid - first >= least && last - after_mid >= least) {
      const bool left = Cover(a, middle, out);
      const bool right = Cover(middle, b, out);
      return left && right;
    }
    // Nothing finer is allowed: keep the most accurate fit, every coordinate at the cap.
    if (cap < 0) throw ComputeError(fmt::format("cannot fit the window {:.6f} s..{:.6f} s: it has no samples", a, b));
    out->push_back(fits.Window(std::vector<int>(static_cast<size_t>(d), cap)));
    return false;
  }

 private:
  // The smallest degrees within the tolerance, given that the cap is: each coordinate alone to its
  // smallest degree within it (bisection), then the coordinate dominating the worst sample raised
  // until the Euclidean norm is within it too.
  static std::vector<int> SmallestDegrees(WindowFits* fits) {
    const int d = fits->dimension(), cap = fits->cap();
    std::vector<int> degrees(static_cast<size_t>(d), 0);
    for (int c = 0; c < d; ++c) {
      if (fits->Within(c, 0)) continue;
      int lo = 0, hi = cap;  // lo is beyond the tolerance, hi within it
      while (hi - lo > 1) {
        const int mid = lo + (hi - lo) / 2;
        (fits->Within(c, mid) ? hi : lo) = mid;
      }
      degrees[static_cast<size_t>(c)] = hi;
    }
    while (!fits->Within(degrees)) {
      const int c = fits->DominantCoordinate(degrees);
      if (c < 0) return std::vector<int>(static_cast<size_t>(d), cap);  // not reached: the cap is within
      int& n = degrees[static_cast<size_t>(c)];
      n = std::min(cap, n + std::max(1, n / 8));
    }
    return degrees;
  }

  const SortedSamples& samples_;
  double tolerance_;
  const CurveOptions& options_;
  double begin_, end_;
};

// The model within `tolerance` of every sample, on the segments of `automatic` (the same split at
// gaps), with its noise estimate. Throws ComputeError with the error of the most accurate model
// found when the tolerance cannot be met.
TrajectoryModel FitToTolerance(const TrajectoryModel& automatic, const SortedSamples& samples, double tolerance,
                               const CurveOptions& options) {
  TrajectoryModel model;
  model.origin_ns = automatic.origin_ns;
  model.dimension = automatic.dimension;
  model.noise_sigma = automatic.noise_sigma;
  bool met = true;
  for (const ModelSegment& segment : automatic.segments) {
    const double begin = static_cast<double>(segment.first_ns - model.origin_ns) * 1e-9;
    const double end = static_cast<double>(segment.last_ns - model.origin_ns) * 1e-9;
    ModelSegment covered{segment.first_ns, segment.last_ns, {}};
    met = ToleranceFitter(samples, tolerance, options, begin, end).Cover(begin, end, &covered.windows) && met;
    model.segments.push_back(std::move(covered));
  }
  Eigen::MatrixXd fitted;
  CurveFromModel(model).EvaluateMany(samples.stamps, 0, &fitted);
  const Eigen::MatrixXd residuals = fitted - samples.z;
  model.residual_rms =
      (residuals.colwise().squaredNorm() / static_cast<double>(residuals.rows())).cwiseSqrt().transpose();
  const Eigen::VectorXd norms = residuals.rowwise().norm();
  Eigen::Index worst = 0;
  const double max = norms.maxCoeff(&worst);
  if (met && max <= tolerance) return model;  // blending windows within the tolerance stays within it
  // The extreme of m Gaussian errors in 3-D is about 5σ at m = 1e5; beyond 8σ noise does not explain it.
  const double noise = model.noise_sigma.maxCoeff();
  const std::string why =
      max <= 8.0 * noise
          ? fmt::format(
                "the estimated noise of the samples is {:.3g} m per axis, and single samples lie a few times "
                "that from the true path: a smaller max error means following the noise",
                noise)
          : fmt::format(
                "the estimated noise of the samples is only {:.3g} m per axis, so the samples near {} s are "
                "not smooth at the scale of {} samples (a jump or an outlier?)",
                noise, traj::FormatSeconds(samples.stamps[static_cast<size_t>(worst)]), options.min_window_samples);
  throw ComputeError(fmt::format(
      "cannot meet the tolerance of {} m: the most accurate model cheval can build from these samples (N^2/m <= {} and "
      "degree <= {} per window, windows down to {} samples) has a max error of {:.3g} m at the input samples (at {} s; "
      "RMS {:.3g} m); {}",
      tolerance, options.max_conditioning, options.max_degree, options.min_window_samples, max,
      traj::FormatSeconds(samples.stamps[static_cast<size_t>(worst)]),
      std::sqrt(norms.squaredNorm() / static_cast<double>(norms.size())), why));
}

}  // namespace

void CompressOptions::Validate() const {
  const OptionCheck check("CompressOptions");
  check(!tolerance || (*tolerance > 0.0 && std::isfinite(*tolerance)), "tolerance",
        "must be a positive number of metres, got {}", tolerance.value_or(0.0));
  curve.Validate();
}

Compression Compress(std::span<const int64_t> stamps_ns, const Eigen::Ref<const Eigen::MatrixXd>& values,
                     const CompressOptions& options) {
  options.Validate();
  Compression result;
  result.model = ModelFromCurve(FitCurve(stamps_ns, values, options.curve));
  result.error = MeasureReconstruction(CurveFromModel(result.model), stamps_ns, values);
  if (options.tolerance) {
    const SortedSamples samples(stamps_ns, values, result.model.origin_ns);
    TrajectoryModel fitted = FitToTolerance(result.model, samples, *options.tolerance, options.curve);
    // The automatic model stays when it meets the tolerance with fewer numbers.
    if (result.error.max > *options.tolerance || ModelNumberCount(fitted) < ModelNumberCount(result.model)) {
      result.model = std::move(fitted);
      result.automatic = false;
      result.error = MeasureReconstruction(CurveFromModel(result.model), stamps_ns, values);
    }
  }
  result.model.reconstruction = result.error;
  result.model.tolerance = options.tolerance;
  result.input_numbers = values.size();
  result.model_numbers = ModelNumberCount(result.model);
  result.ratio = static_cast<double>(result.input_numbers) / static_cast<double>(result.model_numbers);
  return result;
}

std::string CompressionJson(const CompressionRun& run, const Compression& c) {
  const TrajectoryModel& model = c.model;
  std::vector<int> degrees;
  size_t windows = 0;
  for (const ModelSegment& segment : model.segments) {
    windows += segment.windows.size();
    for (const ModelWindow& w : segment.windows) {
      for (size_t k = 0; k < w.values.size(); ++k) degrees.push_back(w.degree(k));
    }
  }
  nlohmann::json j;
  j["command"] = "compress";
  j["input"] = {{"path", run.input_path}, {"poses", run.input_poses}, {"has_orientation", run.input_has_orientation}};
  j["model"] = {{"path", run.model_path}, {"bytes", run.model_bytes}};
  j["tolerance_m"] = run.tolerance_m ? nlohmann::json(*run.tolerance_m) : nlohmann::json(nullptr);
  j["segments"] = model.segments.size();
  j["windows"] = windows;
  j["degrees"] = degrees;
  j["input_numbers"] = c.input_numbers;
  j["model_values"] = ModelValueCount(model);
  j["model_numbers"] = c.model_numbers;
  j["compression_ratio"] = c.ratio;
  j["max_error_m"] = c.error.max;
  j["rms_error_m"] = c.error.rms;
  j["worst_stamp"] = traj::FormatSeconds(c.error.worst_stamp_ns);
  j["noise_sigma_m"] =
      std::vector<double>(model.noise_sigma.data(), model.noise_sigma.data() + model.noise_sigma.size());
  j["automatic"] = c.automatic;
  j["seconds"] = run.seconds;
  return j.dump(2) + "\n";
}

}  // namespace cheval::cheb

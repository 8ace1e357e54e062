#include "cheval/cheb/curve.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <fmt/format.h>

#include "cheval/cheb/degree.h"
#include "cheval/common/error.h"

namespace cheval::cheb {
namespace {

// The relative tolerance below which coefficients are rounding, not signal: the chop's floor when
// the data are noise-free.
constexpr double kRoundingTolerance = 1e-13;
// Largest condition number of the normal matrix accepted for the degree-choosing fit: 1e10 keeps
// its coefficients accurate to ~1e-6 relative, far below any noise plateau the chop looks for.
// Uneven sampling (holes inside a window) is what drives it up at a given N²/m.
constexpr double kMaxGramCondition = 1e10;

void ValidateOptions(const CurveOptions& o) {
  if (o.degree_method == DegreeMethod::kFixed && o.fixed_degree < 0) {
    throw UsageError(fmt::format("--degree must be a non-negative integer, got {}", o.fixed_degree));
  }
  if (o.window_s && !(*o.window_s > 0.0 && std::isfinite(*o.window_s))) {
    throw UsageError(fmt::format("--window must be a positive number of seconds, got {}", *o.window_s));
  }
  if (!(o.max_conditioning > 0.0)) throw UsageError("max_conditioning must be positive");
  if (o.max_degree < 1) throw UsageError("max_degree must be at least 1");
  if (!(o.overlap >= 0.0 && o.overlap <= 1.0)) throw UsageError("overlap must be in [0, 1]");
  if (!(o.gap_factor > 1.0)) throw UsageError("gap_factor must be greater than 1");
  if (!(o.min_gap_s >= 0.0)) throw UsageError("min_gap_s must be non-negative");
  if (o.noise_sigma && !(*o.noise_sigma >= 0.0 && std::isfinite(*o.noise_sigma))) {
    throw UsageError(fmt::format("--noise must be a non-negative number, got {}", *o.noise_sigma));
  }
  if (o.min_window_samples < 2) throw UsageError("min_window_samples must be at least 2");
}

// Fits one window and, for automatic degrees, says whether it should be split instead.
class WindowFitter {
 public:
  WindowFitter(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, const Eigen::VectorXd& sigma,
               const CurveOptions& options)
      : t_(t), z_(z), sigma_(sigma), options_(options) {}

  // Fits the window of core [a, b] inside segment [segment_begin, segment_end]. Returns nullopt
  // when the series is not resolved and splitting is allowed.
  std::optional<CurveWindow> Fit(double a, double b, double segment_begin, double segment_end, bool may_split) const {
    const double extension = options_.overlap * (b - a);
    CurveWindow window;
    window.core_begin = a;
    window.core_end = b;
    window.fit_begin = std::max(a - extension, segment_begin);
    window.fit_end = std::min(b + extension, segment_end);
    const auto first = std::lower_bound(t_.data(), t_.data() + t_.size(), window.fit_begin) - t_.data();
    const auto last = std::upper_bound(t_.data(), t_.data() + t_.size(), window.fit_end) - t_.data();
    const Eigen::Index m = last - first;
    window.samples = m;
    Eigen::Index distinct = m > 0 ? 1 : 0;
    for (Eigen::Index i = first + 1; i < last; ++i) distinct += t_[i] != t_[i - 1] ? 1 : 0;
    const Interval interval{window.fit_begin, window.fit_end};
    if (distinct < 2 || !(interval.b > interval.a)) {
      throw ComputeError(fmt::format("cannot fit a window at {:.6f} s..{:.6f} s: it has {} distinct stamps",
                                     window.fit_begin, window.fit_end, distinct));
    }
    const auto tw = t_.segment(first, m);
    const auto zw = z_.middleRows(first, m);
    const int d = static_cast<int>(z_.cols());
    window.degrees.assign(d, 0);

    if (options_.degree_method == DegreeMethod::kFixed) {
      if (options_.fixed_degree + 1 > distinct) {
        throw ComputeError(fmt::format(
            "degree {} needs at least {} distinct stamps per window, but the window {:.6f} s..{:.6f} s has {}; "
            "use a smaller --degree or a longer --window",
            options_.fixed_degree, options_.fixed_degree + 1, window.fit_begin, window.fit_end, distinct));
      }
      std::fill(window.degrees.begin(), window.degrees.end(), options_.fixed_degree);
      window.series = FitLeastSquares(tw, zw, options_.fixed_degree, interval);
      window.coefficient_magnitudes = window.series.coefficients.cwiseAbs();
      Finish(&window);
      return window;
    }

    int top = static_cast<int>(std::min<double>(
        {static_cast<double>(options_.max_degree), std::floor(std::sqrt(options_.max_conditioning * m)),
         static_cast<double>(distinct - 1)}));
    // The probe fit at the top degree; uneven sampling can make it ill-conditioned: then split the
    // window if allowed, else lower the degree until it is well posed.
    ChebyshevSeries high;
    Eigen::VectorXd variance_factors;
    NormalEquations probe = BuildNormalEquations(tw, zw, top, interval);
    while (true) {
      double condition = std::numeric_limits<double>::infinity();
      try {
        high = SolveNormalEquations(probe, top, &condition,
                                    options_.degree_method == DegreeMethod::kThreshold ? &variance_factors : nullptr);
      } catch (const ComputeError&) {
      }
      if (condition <= kMaxGramCondition) break;
      if (may_split) return std::nullopt;
      if (top <= 1) {
        throw ComputeError(fmt::format("cannot fit the window {:.6f} s..{:.6f} s: its {} samples do not determine "
                                       "even a line",
                                       window.fit_begin, window.fit_end, m));
      }
      top = std::max(1, static_cast<int>(0.7 * top));  // a leading block of the same normal equations
    }
    window.coefficient_magnitudes = high.coefficients.cwiseAbs();
    bool resolved = true;
    if (options_.degree_method == DegreeMethod::kThreshold) {
      const double universal = std::sqrt(2.0 * std::log(static_cast<double>(top + 1)));
      for (int c = 0; c < d; ++c) {
        int significant = 0;
        for (int k = 1; k <= top; ++k) {
          const double threshold = universal * sigma_[c] * std::sqrt(variance_factors[k]);
          if (std::abs(high.coefficients(k, c)) > threshold) significant = k;
        }
        window.degrees[c] = significant;
        // Significant coefficients up to the top: the motion is not resolved at this degree.
        if (top >= 8 && significant > (top * 9) / 10) resolved = false;
      }
    } else {
      // standardChop decides whether the window resolves the motion (its coefficients reach the
      // noise plateau); it also picks the degree for kChop. Cross-validation picks the degree of a
      // resolved window for kCrossValidation: held-out error alone cannot tell an unresolved window
      // (every candidate underfits) from a resolved one.
      for (int c = 0; c < d; ++c) {
        // The mean (c_0) says nothing about how well the motion is resolved, and a large offset
        // (positions far from the origin) would make every other coefficient look negligible:
        // the chop sees the series relative to the largest varying coefficient.
        Eigen::VectorXd coefficients = high.coefficients.col(c);
        coefficients[0] = top >= 1 ? coefficients.tail(top).cwiseAbs().maxCoeff() : 0.0;
        const double scale = coefficients.cwiseAbs().maxCoeff();
        if (scale == 0.0) continue;  // a constant coordinate: degree 0
        // Noise level of a coefficient of m equispaced samples: σ·sqrt(2/m) (CHEBYSHEV.md).
        const double noise = sigma_[c] * std::sqrt(2.0 / static_cast<double>(m));
        const double tol = std::clamp(noise / scale, kRoundingTolerance, 0.5);
        const int keep = StandardChop(coefficients, tol);
        // StandardChop needs 17 coefficients; below that, or without a plateau, it keeps all.
        if (keep == top + 1) resolved = false;
        window.degrees[c] = keep - 1;
      }
      if (options_.degree_method == DegreeMethod::kCrossValidation && (resolved || !may_split)) {
        window.degrees = CrossValidatedDegrees(tw, zw, top, interval);
      }
    }
    if (!resolved && may_split) return std::nullopt;

    // Each coordinate at its own degree, from one set of normal equations (leading blocks).
    const int degree = *std::max_element(window.degrees.begin(), window.degrees.end());
    // The probe's normal equations hold every lower degree in their leading blocks.
    NormalEquations& normal = probe;
    window.series.interval = interval;
    window.series.coefficients = Eigen::MatrixXd::Zero(degree + 1, d);
    const Eigen::MatrixXd rhs = normal.rhs;
    for (int c = 0; c < d; ++c) {
      normal.rhs = rhs.col(c);
      const ChebyshevSeries axis = SolveNormalEquations(normal, window.degrees[c]);
      window.series.coefficients.col(c).head(window.degrees[c] + 1) = axis.coefficients.col(0);
    }
    Finish(&window);
    return window;
  }

 private:
  static void Finish(CurveWindow* window) {
    window->first_derivative = DerivativeCoefficients(window->series.coefficients);
    window->second_derivative = DerivativeCoefficients(window->first_derivative);
  }

  // 5-fold cross-validation (folds interleaved: sample i in fold i mod 5) over a geometric grid
  // of degrees up to `top`, per coordinate: the degree of least held-out squared error.
  // Nothing is evaluated point by point: with F_f the normal equations (G_f, b_f) and Σz² of fold
  // f, the training system of fold f is Σ F - F_f, and the held-out error of coefficients c is
  // Σz²_f - 2 cᵀb_f + cᵀG_f c. So the samples are visited once, and each candidate costs one
  // solve of a leading block per fold. z is centred first so that Σz² does not swamp the error.
  static std::vector<int> CrossValidatedDegrees(const Eigen::Ref<const Eigen::VectorXd>& t,
                                                const Eigen::Ref<const Eigen::MatrixXd>& z, int top,
                                                const Interval& interval) {
    constexpr int kFolds = 5;
    std::vector<int> grid;
    for (double g = 2; g < top; g *= 1.25) {
      const int degree = static_cast<int>(std::lround(g));
      if (grid.empty() || degree != grid.back()) grid.push_back(degree);
    }
    grid.push_back(top);
    const Eigen::Index m = t.size(), d = z.cols();
    const Eigen::RowVectorXd mean = z.colwise().mean();
    std::vector<NormalEquations> folds;
    std::vector<Eigen::RowVectorXd> squares;
    NormalEquations total;
    for (int fold = 0; fold < kFolds; ++fold) {
      const Eigen::Index count = (m - fold + kFolds - 1) / kFolds;
      Eigen::VectorXd ft(count);
      Eigen::MatrixXd fz(count, d);
      for (Eigen::Index i = fold, k = 0; i < m; i += kFolds, ++k) {
        ft[k] = t[i];
        fz.row(k) = z.row(i) - mean;
      }
      // A fold may have fewer samples than top + 1: its own system is then singular, which is fine
      // (only sums and products of it are used), so build it without the sample-count check.
      NormalEquations normal = BuildNormalEquationsUnchecked(ft, fz, top, interval);
      squares.push_back(fz.colwise().squaredNorm());
      if (fold == 0) {
        total = normal;
      } else {
        total.gram += normal.gram;
        total.rhs += normal.rhs;
        total.samples += normal.samples;
      }
      folds.push_back(std::move(normal));
    }
    Eigen::MatrixXd error = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(grid.size()), d);
    for (int fold = 0; fold < kFolds; ++fold) {
      NormalEquations train = total;
      train.gram -= folds[fold].gram;
      train.rhs -= folds[fold].rhs;
      train.samples -= folds[fold].samples;
      for (size_t g = 0; g < grid.size(); ++g) {
        const auto row = static_cast<Eigen::Index>(g);
        const int n = grid[g] + 1;
        try {
          const Eigen::MatrixXd c = SolveNormalEquations(train, grid[g]).coefficients;  // n x d
          const auto gram = folds[fold].gram.topLeftCorner(n, n);
          const auto rhs = folds[fold].rhs.topRows(n);
          for (Eigen::Index k = 0; k < d; ++k) {
            error(row, k) += squares[fold][k] - 2.0 * c.col(k).dot(rhs.col(k)) + c.col(k).dot(gram * c.col(k));
          }
        } catch (const ComputeError&) {
          error.row(row).setConstant(std::numeric_limits<double>::infinity());
        }
      }
    }
    std::vector<int> degrees(static_cast<size_t>(d));
    for (Eigen::Index c = 0; c < d; ++c) {
      Eigen::Index best = 0;
      error.col(c).minCoeff(&best);
      degrees[static_cast<size_t>(c)] = grid[static_cast<size_t>(best)];
    }
    return degrees;
  }

  const Eigen::VectorXd& t_;
  const Eigen::MatrixXd& z_;
  const Eigen::VectorXd& sigma_;
  const CurveOptions& options_;
};

// Fits cores [a, b] of a segment adaptively: a core is halved until its series resolves or it
// gets too small to split. Windows come out in time order.
std::vector<CurveWindow> FitAdaptive(const WindowFitter& fitter, const Eigen::VectorXd& t, const CurveSegment& segment,
                                     double a0, double b0, const CurveOptions& options) {
  std::vector<CurveWindow> windows;
  std::vector<std::pair<double, double>> stack{{a0, b0}};
  while (!stack.empty()) {
    const auto [a, b] = stack.back();
    stack.pop_back();
    const auto inside =
        std::upper_bound(t.data(), t.data() + t.size(), b) - std::lower_bound(t.data(), t.data() + t.size(), a);
    const bool may_split = inside >= 2 * options.min_window_samples;
    std::optional<CurveWindow> window = fitter.Fit(a, b, segment.begin, segment.end, may_split);
    if (window) {
      windows.push_back(std::move(*window));
    } else {
      const double middle = 0.5 * (a + b);
      stack.emplace_back(middle, b);  // the left half is popped first: windows stay in time order
      stack.emplace_back(a, middle);
    }
  }
  return windows;
}

// Halves the first and the last window of a segment while their degree exceeds
// options.end_degree and they keep enough samples to be split; the inner half is refitted
// adaptively (it may need splitting itself).
void RefineEnds(const WindowFitter& fitter, const Eigen::VectorXd& t, CurveSegment& segment,
                const CurveOptions& options) {
  if (options.end_degree <= 0) return;
  auto max_degree = [](const CurveWindow& w) { return *std::max_element(w.degrees.begin(), w.degrees.end()); };
  auto samples_in = [&t](double a, double b) {
    return std::upper_bound(t.data(), t.data() + t.size(), b) - std::lower_bound(t.data(), t.data() + t.size(), a);
  };
  for (const bool front : {true, false}) {
    while (true) {
      auto& windows = segment.windows;
      const CurveWindow& end = front ? windows.front() : windows.back();
      if (max_degree(end) <= options.end_degree ||
          samples_in(end.core_begin, end.core_end) < 2 * options.min_window_samples) {
        break;
      }
      const double a = end.core_begin, b = end.core_end, middle = 0.5 * (a + b);
      if (front) {
        CurveWindow outer = *fitter.Fit(a, middle, segment.begin, segment.end, false);
        std::vector<CurveWindow> inner = FitAdaptive(fitter, t, segment, middle, b, options);
        windows.erase(windows.begin());
        windows.insert(windows.begin(), std::make_move_iterator(inner.begin()), std::make_move_iterator(inner.end()));
        windows.insert(windows.begin(), std::move(outer));
      } else {
        std::vector<CurveWindow> inner = FitAdaptive(fitter, t, segment, a, middle, options);
        CurveWindow outer = *fitter.Fit(middle, b, segment.begin, segment.end, false);
        windows.pop_back();
        windows.insert(windows.end(), std::make_move_iterator(inner.begin()), std::make_move_iterator(inner.end()));
        windows.push_back(std::move(outer));
      }
    }
  }
}

// Quintic smoothstep s(u) = 6u⁵ - 15u⁴ + 10u³ and its first two derivatives in u: C² blending.
void Smoothstep(double u, double* s, double* ds, double* dds) {
  u = std::clamp(u, 0.0, 1.0);
  *s = u * u * u * (u * (6.0 * u - 15.0) + 10.0);
  *ds = 30.0 * u * u * (1.0 - u) * (1.0 - u);
  *dds = 60.0 * u * (1.0 - u) * (1.0 - 2.0 * u);
}

// Up to 4 coordinates, on the stack: evaluation allocates nothing.
using Point = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 4, 1>;

// Σ_k c_k T_k(x) for each column of `coefficients`, times `scale`, into `out`.
void ClenshawInto(const Eigen::MatrixXd& coefficients, double x, double scale, Point* out) {
  const Eigen::Index n = coefficients.rows() - 1, d = coefficients.cols();
  out->resize(d);
  const double two_x = 2.0 * x;
  for (Eigen::Index c = 0; c < d; ++c) {
    const double* a = coefficients.col(c).data();
    double b1 = 0.0, b2 = 0.0;
    for (Eigen::Index k = n; k >= 1; --k) {
      const double b0 = two_x * b1 - b2 + a[k];
      b2 = b1;
      b1 = b0;
    }
    (*out)[c] = (x * b1 - b2 + a[0]) * scale;
  }
}

// Value, and the derivatives up to `order` (0, 1 or 2), of a window at time t.
void EvaluateWindow(const CurveWindow& w, double t, int order, Point* p, Point* v, Point* a) {
  const double x = w.series.interval.ToUnit(t);
  const double scale = w.series.interval.DerivativeScale();
  ClenshawInto(w.series.coefficients, x, 1.0, p);
  if (order >= 1) ClenshawInto(w.first_derivative, x, scale, v);
  if (order >= 2) ClenshawInto(w.second_derivative, x, scale * scale, a);
}

}  // namespace

Curve FitCurve(std::span<const int64_t> stamps_ns, const Eigen::Ref<const Eigen::MatrixXd>& values,
               const CurveOptions& options) {
  ValidateOptions(options);
  const auto m = static_cast<Eigen::Index>(stamps_ns.size());
  if (values.rows() != m) throw std::invalid_argument("FitCurve: stamps and values differ in length");
  if (values.cols() < 1 || values.cols() > 4) throw std::invalid_argument("FitCurve: 1..4 coordinates");
  if (m < 2) throw ComputeError(fmt::format("a fit needs at least 2 samples, got {}", m));

  std::vector<Eigen::Index> order(m);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](Eigen::Index i, Eigen::Index j) { return stamps_ns[i] < stamps_ns[j]; });
  Curve curve;
  curve.origin_ns_ = stamps_ns[order.front()];
  curve.dimension_ = static_cast<int>(values.cols());
  Eigen::VectorXd t(m);
  Eigen::MatrixXd z(m, values.cols());
  for (Eigen::Index i = 0; i < m; ++i) {
    t[i] = static_cast<double>(stamps_ns[order[i]] - curve.origin_ns_) * 1e-9;
    z.row(i) = values.row(order[i]);
  }
  if (t[m - 1] == 0.0) throw ComputeError(fmt::format("all {} stamps are equal: there is no time to fit over", m));

  std::vector<double> dts;
  for (Eigen::Index i = 1; i < m; ++i) {
    if (t[i] > t[i - 1]) dts.push_back(t[i] - t[i - 1]);
  }
  std::nth_element(dts.begin(), dts.begin() + static_cast<std::ptrdiff_t>(dts.size() / 2), dts.end());
  const double gap = std::max(options.gap_factor * dts[dts.size() / 2], options.min_gap_s);

  curve.noise_sigma_ = options.noise_sigma ? Eigen::VectorXd::Constant(values.cols(), *options.noise_sigma)
                                           : EstimateNoiseSigma(z);
  const WindowFitter fitter(t, z, curve.noise_sigma_, options);

  // Segment boundaries [starts[k], starts[k+1]); a segment with one distinct stamp joins the
  // neighbour across the shorter gap.
  std::vector<Eigen::Index> starts{0};
  for (Eigen::Index i = 1; i < m; ++i) {
    if (t[i] - t[i - 1] > gap) starts.push_back(i);
  }
  starts.push_back(m);
  for (size_t k = 0; k + 1 < starts.size() && starts.size() > 2;) {
    if (t[starts[k + 1] - 1] != t[starts[k]]) {
      ++k;
      continue;
    }
    const double left_gap = k > 0 ? t[starts[k]] - t[starts[k] - 1] : std::numeric_limits<double>::infinity();
    const double right_gap = k + 2 < starts.size() ? t[starts[k + 1]] - t[starts[k + 1] - 1]
                                                   : std::numeric_limits<double>::infinity();
    starts.erase(starts.begin() + static_cast<std::ptrdiff_t>(left_gap <= right_gap ? k : k + 1));
    if (k > 0) --k;
  }

  for (size_t k = 0; k + 1 < starts.size(); ++k) {
    CurveSegment segment;
    segment.begin = t[starts[k]];
    segment.end = t[starts[k + 1] - 1];
    if (options.single_window || options.window_s) {
      const int cores = options.single_window
                            ? 1
                            : std::max(1, static_cast<int>(std::lround((segment.end - segment.begin) / *options.window_s)));
      for (int c = 0; c < cores; ++c) {
        const double a = segment.begin + (segment.end - segment.begin) * c / cores;
        const double b = c + 1 == cores ? segment.end : segment.begin + (segment.end - segment.begin) * (c + 1) / cores;
        segment.windows.push_back(*fitter.Fit(a, b, segment.begin, segment.end, false));
      }
    } else {
      segment.windows = FitAdaptive(fitter, t, segment, segment.begin, segment.end, options);
      RefineEnds(fitter, t, segment, options);
    }
    curve.segments_.push_back(std::move(segment));
  }

  // Residuals at every sample.
  Eigen::VectorXd p(values.cols());
  Eigen::VectorXd squares = Eigen::VectorXd::Zero(values.cols());
  for (Eigen::Index i = 0; i < m; ++i) {
    curve.EvaluateValue(stamps_ns[order[i]], p);
    squares += (p - z.row(i).transpose()).cwiseAbs2();
  }
  curve.residual_rms_ = (squares / static_cast<double>(m)).cwiseSqrt();
  return curve;
}

void Curve::Evaluate(int64_t stamp_ns, Eigen::Ref<Eigen::VectorXd> value, Eigen::Ref<Eigen::VectorXd> derivative,
                     Eigen::Ref<Eigen::VectorXd> second_derivative, double tolerance_s) const {
  EvaluateUpTo(stamp_ns, 2, value, &derivative, &second_derivative, tolerance_s);
}

void Curve::EvaluateValue(int64_t stamp_ns, Eigen::Ref<Eigen::VectorXd> value, double tolerance_s) const {
  EvaluateUpTo(stamp_ns, 0, value, nullptr, nullptr, tolerance_s);
}

void Curve::EvaluateVelocity(int64_t stamp_ns, Eigen::Ref<Eigen::VectorXd> value, Eigen::Ref<Eigen::VectorXd> derivative,
                             double tolerance_s) const {
  EvaluateUpTo(stamp_ns, 1, value, &derivative, nullptr, tolerance_s);
}

void Curve::EvaluateUpTo(int64_t stamp_ns, int order, Eigen::Ref<Eigen::VectorXd> value,
                         Eigen::Ref<Eigen::VectorXd>* derivative, Eigen::Ref<Eigen::VectorXd>* second_derivative,
                         double tolerance_s) const {
  const double t = static_cast<double>(stamp_ns - origin_ns_) * 1e-9;
  // The segment containing t (or nearest within the tolerance).
  const CurveSegment* segment = nullptr;
  for (const CurveSegment& s : segments_) {
    if (t >= s.begin - tolerance_s && t <= s.end + tolerance_s) {
      segment = &s;
      break;
    }
  }
  if (segment == nullptr) {
    throw ComputeError(fmt::format("time {:.9f} s (from the first sample) is outside the fitted data or inside a gap",
                                   t));
  }
  const auto& windows = segment->windows;
  // The window whose core holds t.
  auto it = std::upper_bound(windows.begin(), windows.end(), t,
                             [](double time, const CurveWindow& w) { return time < w.core_begin; });
  size_t k = it == windows.begin() ? 0 : static_cast<size_t>(it - windows.begin()) - 1;
  Point p, v, a;
  EvaluateWindow(windows[k], t, order, &p, &v, &a);
  // Blend with the neighbour across the nearest core boundary when t is in the blending zone.
  auto blend = [&](size_t left, size_t right) {
    const double boundary = windows[right].core_begin;
    // Half the overlap both windows have across the boundary: each is then well inside its data.
    const double half = 0.5 * std::min(windows[left].fit_end - boundary, boundary - windows[right].fit_begin);
    if (!(half > 0.0) || t < boundary - half || t > boundary + half) return false;
    Point pl, vl, al, pr, vr, ar;
    // The blend's derivatives need the windows' values and lower derivatives.
    EvaluateWindow(windows[left], t, order, &pl, &vl, &al);
    EvaluateWindow(windows[right], t, order, &pr, &vr, &ar);
    double s, ds, dds;
    Smoothstep((t - (boundary - half)) / (2.0 * half), &s, &ds, &dds);
    ds /= 2.0 * half;
    dds /= 4.0 * half * half;
    p = (1.0 - s) * pl + s * pr;
    if (order >= 1) v = (1.0 - s) * vl + s * vr + ds * (pr - pl);
    if (order >= 2) a = (1.0 - s) * al + s * ar + 2.0 * ds * (vr - vl) + dds * (pr - pl);
    return true;
  };
  if (!(k > 0 && blend(k - 1, k)) && k + 1 < windows.size()) blend(k, k + 1);
  value = p;
  if (order >= 1) *derivative = v;
  if (order >= 2) *second_derivative = a;
}

Eigen::Index Curve::stored_values() const {
  Eigen::Index total = 0;
  for (const CurveSegment& s : segments_) {
    for (const CurveWindow& w : s.windows) {
      for (int degree : w.degrees) total += degree + 1;
    }
  }
  return total;
}

}  // namespace cheval::cheb

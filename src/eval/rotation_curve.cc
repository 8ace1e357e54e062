#include "cheval/eval/rotation_curve.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <fmt/format.h>

#include "cheval/common/error.h"
#include "cheval/lie/so3.h"

namespace cheval::eval {
namespace {

using SO3 = lie::SO3<double>;

// A chart never holds rotations further than this from its origin, whatever the sample count:
// Log is smooth up to π and J_r is well conditioned well before it.
constexpr double kMaxChartAngle = 2.5;
// A chart piece holds at least this many samples where kMaxChartAngle allows, and neighbours
// overlap by a quarter of it: enough for each to be fitted on its own and for a smooth blend (fewer
// made the drone's body rate 1.3–2x worse, docs/decisions.md).
constexpr Eigen::Index kMinPieceSamples = 24;

double Angle(const SO3& a, const SO3& b) { return (a.Inverse() * b).Log().norm(); }

// A piece of the sorted samples [begin, end) and its chart's origin (one of its samples).
struct Piece {
  Eigen::Index begin, end;
  SO3 origin;
};

// Cuts the sorted rotations into pieces within max_angle of their origin (the piece's first
// sample), each with at least min_samples samples where kMaxChartAngle allows, consecutive pieces
// overlapping by a few samples and never three pieces at one sample.
std::vector<Piece> CutPieces(std::span<const int64_t> stamps, const std::vector<SO3>& rotations, double max_angle,
                             Eigen::Index min_samples) {
  const auto m = static_cast<Eigen::Index>(rotations.size());
  const Eigen::Index min_overlap = std::max<Eigen::Index>(2, min_samples / 4);
  std::vector<Piece> pieces;
  Eigen::Index start = 0, previous_end = 0;
  while (true) {
    const SO3& origin = rotations[start];
    Eigen::Index end = start + 1;
    for (; end < m; ++end) {
      const double angle = Angle(origin, rotations[end]);
      // Long enough to be fitted on its own and to reach past the previous piece (so that the
      // next one can start after it: only neighbours overlap).
      const bool enough = end - start >= min_samples && end >= previous_end + min_overlap;
      if (angle > kMaxChartAngle || (angle > max_angle && enough)) break;
    }
    if (end - start < 2) {
      throw ComputeError(fmt::format(
          "the rotations at stamps {} ns and {} ns differ by more than {} rad: too fast for the sample rate to "
          "give an angular velocity",
          stamps[start], stamps[end], kMaxChartAngle));
    }
    pieces.push_back({start, end, origin});
    if (end == m) break;
    // The next piece starts where this one is halfway to its limit, keeping an overlap to blend
    // in, and not before the previous piece ended (only neighbours overlap) unless the rotation is
    // so fast that the pieces must be short: it always starts inside this one (no hole).
    const Eigen::Index lowest = std::max(start + 1, previous_end);
    Eigen::Index next = lowest;
    while (next < end - 1 && Angle(origin, rotations[next]) <= 0.5 * max_angle) ++next;
    next = std::min(std::max(lowest, std::min(next, end - min_overlap)), end - 1);
    previous_end = end;
    start = next;
  }
  return pieces;
}

}  // namespace

RotationCurve FitRotationCurve(std::span<const int64_t> stamps_ns, std::span<const Eigen::Quaterniond> rotations,
                               const RotationCurveOptions& options) {
  if (stamps_ns.size() != rotations.size()) {
    throw std::invalid_argument("FitRotationCurve: stamps and rotations differ in length");
  }
  if (!(options.max_chart_angle > 0.0 && options.max_chart_angle <= kMaxChartAngle)) {
    throw UsageError(fmt::format("the chart angle must be in (0, {}] rad, got {}", kMaxChartAngle,
                                 options.max_chart_angle));
  }
  const auto m = static_cast<Eigen::Index>(stamps_ns.size());
  if (m < 2) throw ComputeError(fmt::format("a rotation fit needs at least 2 samples, got {}", m));
  std::vector<Eigen::Index> order(static_cast<size_t>(m));
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](Eigen::Index i, Eigen::Index j) { return stamps_ns[i] < stamps_ns[j]; });
  std::vector<int64_t> stamps(static_cast<size_t>(m));
  std::vector<SO3> sorted(static_cast<size_t>(m));
  for (Eigen::Index i = 0; i < m; ++i) {
    const Eigen::Quaterniond& q = rotations[order[i]];
    const double norm = q.coeffs().norm();
    if (!(norm > 0.0) || !std::isfinite(norm)) {
      throw ComputeError(fmt::format("the rotation at stamp {} ns is not a rotation (quaternion norm {})",
                                     stamps_ns[order[i]], norm));
    }
    stamps[i] = stamps_ns[order[i]];
    sorted[i] = SO3(q);
  }

  // Chart noise is the rotation noise stretched by J_r⁻¹(φ), which varies across a chart: windows
  // shorter than a piece's minimum would follow it (12-sample windows made the drone's and the
  // handheld's body rate 15–25 % worse).
  cheb::CurveOptions chart_options = options.curve;
  chart_options.min_window_samples = std::max<int>(chart_options.min_window_samples, kMinPieceSamples);
  // A piece's end lies where it is blended with the next, and its noise is largest there: the caps
  // of pieces of one or two windows, judged by one σ, made the drone's body rate 49 % worse
  // (docs/decisions.md).
  chart_options.short_segment_caps = false;
  RotationCurve curve;
  curve.origin_ns_ = stamps.front();
  for (const Piece& piece : CutPieces(stamps, sorted, options.max_chart_angle, kMinPieceSamples)) {
    const Eigen::Index n = piece.end - piece.begin;
    Eigen::MatrixXd chart(n, 3);
    const SO3 inverse = piece.origin.Inverse();
    for (Eigen::Index i = 0; i < n; ++i) chart.row(i) = (inverse * sorted[piece.begin + i]).Log().transpose();
    const std::span<const int64_t> piece_stamps(stamps.data() + piece.begin, static_cast<size_t>(n));
    curve.charts_.push_back({piece.origin.quaternion(), piece_stamps.front(), piece_stamps.back(),
                             cheb::FitCurve(piece_stamps, chart, chart_options)});
  }

  std::vector<Eigen::Quaterniond> fitted;
  Eigen::Matrix3Xd rates;
  curve.EvaluateMany(stamps, &fitted, &rates);
  double squares = 0.0;
  for (Eigen::Index i = 0; i < m; ++i) {
    const double angle = Angle(SO3(fitted[i]), sorted[i]);
    squares += angle * angle;
  }
  curve.residual_rms_rad_ = std::sqrt(squares / static_cast<double>(m));
  return curve;
}

void RotationCurve::EvaluateMany(std::span<const int64_t> stamps_ns, std::vector<Eigen::Quaterniond>* orientations,
                                 Eigen::Matrix3Xd* body_rates) const {
  const auto n = static_cast<Eigen::Index>(stamps_ns.size());
  // For each query: the first chart covering it, and the next one too when they overlap there.
  std::vector<int> first(static_cast<size_t>(n)), second(static_cast<size_t>(n), -1);
  for (Eigen::Index i = 0; i < n; ++i) {
    const int64_t t = stamps_ns[i];
    const auto after = std::upper_bound(charts_.begin(), charts_.end(), t,
                                        [](int64_t time, const RotationChart& c) { return time < c.begin_ns; });
    const int k = static_cast<int>(after - charts_.begin()) - 1;  // last chart beginning at or before t
    const bool in_k = k >= 0 && t <= charts_[k].end_ns;
    const bool in_previous = k >= 1 && t <= charts_[k - 1].end_ns;
    if (!in_k) {
      throw ComputeError(fmt::format("stamp {} ns is outside the fitted rotations ({} ns .. {} ns)", t,
                                     charts_.front().begin_ns, charts_.back().end_ns));
    }
    first[i] = in_previous ? k - 1 : k;
    if (in_previous) second[i] = k;
  }
  // Each chart evaluated at all the queries it serves at once: R = R_k Exp(φ), ω = J_r(φ) φ̇.
  std::vector<SO3> rotation_a(static_cast<size_t>(n)), rotation_b(static_cast<size_t>(n));
  Eigen::Matrix3Xd rate_a(3, n), rate_b(3, n);
  for (int k = 0; k < static_cast<int>(charts_.size()); ++k) {
    std::vector<Eigen::Index> served;
    std::vector<int64_t> served_stamps;
    for (Eigen::Index i = 0; i < n; ++i) {
      if (first[i] == k || second[i] == k) {
        served.push_back(i);
        served_stamps.push_back(stamps_ns[i]);
      }
    }
    if (served.empty()) continue;
    Eigen::MatrixXd phi, phi_dot;
    charts_[k].curve.EvaluateMany(served_stamps, 1, &phi, &phi_dot);
    const SO3 origin(charts_[k].origin);
    for (size_t j = 0; j < served.size(); ++j) {
      const Eigen::Index i = served[j];
      const Eigen::Vector3d tangent = phi.row(static_cast<Eigen::Index>(j)).transpose();
      const Eigen::Vector3d rate = SO3::RightJacobian(tangent) * phi_dot.row(static_cast<Eigen::Index>(j)).transpose();
      if (first[i] == k) {
        rotation_a[i] = origin * SO3::Exp(tangent);
        rate_a.col(i) = rate;
      } else {
        rotation_b[i] = origin * SO3::Exp(tangent);
        rate_b.col(i) = rate;
      }
    }
  }
  orientations->resize(static_cast<size_t>(n));
  body_rates->resize(3, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    if (second[i] < 0) {
      (*orientations)[i] = rotation_a[i].quaternion();
      body_rates->col(i) = rate_a.col(i);
      continue;
    }
    // Blend over the overlap [begin of the second chart, end of the first or begin of the third,
    // whichever is earlier — so the blend is complete before the next one starts]:
    // R = R_a Exp(u), u = s Δ, Δ = Log(R_aᵀ R_b), and
    // ω = Exp(u)ᵀ ω_a + J_r(u) u̇,  u̇ = ṡ Δ + s Δ̇,  Δ̇ = J_r⁻¹(Δ) (ω_b − Eᵀ ω_a), E = Exp(Δ).
    const RotationChart& a = charts_[first[i]];
    const RotationChart& b = charts_[second[i]];
    const size_t after = static_cast<size_t>(second[i]) + 1;
    const int64_t blend_end = after < charts_.size() ? std::min(a.end_ns, charts_[after].begin_ns) : a.end_ns;
    const double span = static_cast<double>(blend_end - b.begin_ns) * 1e-9;
    double s = 1.0, ds = 0.0, dds = 0.0;
    if (span > 0.0) {
      cheb::Smoothstep(static_cast<double>(stamps_ns[i] - b.begin_ns) * 1e-9 / span, &s, &ds, &dds);
      ds /= span;
    }
    const SO3 error = rotation_a[i].Inverse() * rotation_b[i];
    const Eigen::Vector3d delta = error.Log();
    const Eigen::Vector3d delta_dot =
        SO3::InverseRightJacobian(delta) * (rate_b.col(i) - error.Inverse().Act(rate_a.col(i)));
    const Eigen::Vector3d u = s * delta;
    const Eigen::Vector3d u_dot = ds * delta + s * delta_dot;
    const SO3 step = SO3::Exp(u);
    (*orientations)[i] = (rotation_a[i] * step).quaternion();
    body_rates->col(i) = step.Inverse().Act(rate_a.col(i)) + SO3::RightJacobian(u) * u_dot;
  }
}

}  // namespace cheval::eval

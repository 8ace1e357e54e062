// The motion model: kinds and their defaults, the position integral by Gauss–Legendre quadrature,
// the exact state at any time, and sampling on stamps (docs/sim.md).
#include "cheval/sim/motion.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "cheval/cheb/quadrature.h"
#include "cheval/common/options.h"
#include "internal/shape.h"

namespace cheval::sim {
namespace {

using internal::Jet;
using internal::kTerms;
using internal::Mat3;
using internal::Shape;
using internal::Vec3;

constexpr double kMaxDurationS = 1e6;  // keeps the quadrature knots (one per second) few
constexpr double kMaxSamples = 1e8;
constexpr int64_t kMaxAbsStartNs = 4'000'000'000'000'000'000;

// ---------------------------------------------------------------------------------------------
// Quadrature of u: 16-point Gauss–Legendre on pieces of at most kKnotSpacingS, with the cumulative
// integral cached at every knot. The integrands have frequencies below ~1 rad/s, so the error on a
// 1 s piece is ~ (ω h/2)^32 / 32!, far below rounding.
constexpr double kKnotSpacingS = 1.0;
constexpr int kGaussPoints = 16;

const cheb::QuadratureRule& Gauss() {
  static const cheb::QuadratureRule rule = cheb::GaussLegendre(kGaussPoints);
  return rule;
}

// ∫_a^b u, composite over ceil(|b − a| / kKnotSpacingS) equal pieces.
Eigen::Vector3d Integrate(const Shape& shape, double a, double b) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  if (a == b) return sum;
  const cheb::QuadratureRule& gauss = Gauss();
  const int pieces = std::max(1, static_cast<int>(std::ceil(std::abs(b - a) / kKnotSpacingS - 1e-9)));
  const double length = (b - a) / pieces;
  for (int piece = 0; piece < pieces; ++piece) {
    const double lo = a + piece * length;
    const double mid = lo + 0.5 * length, half = 0.5 * length;
    for (int i = 0; i < kGaussPoints; ++i) {
      const Vec3<double> u = shape.Integrand(mid + half * gauss.nodes[i]);
      sum += gauss.weights[i] * half * Eigen::Vector3d(u[0], u[1], u[2]);
    }
  }
  return sum;
}

// ∫_0^t u from the cumulative knots (knots[k] = ∫_0^{k h} u), then the last partial piece.
Eigen::Vector3d IntegralFromZero(const Shape& shape, const std::vector<Eigen::Vector3d>& knots, double t) {
  if (t <= 0.0 || knots.empty()) return Integrate(shape, 0.0, t);
  const auto last = static_cast<double>(knots.size() - 1);
  const double k = std::min(std::floor(t / kKnotSpacingS), last);
  return knots[static_cast<size_t>(k)] + Integrate(shape, k * kKnotSpacingS, t);
}

// The exact state at t: p = ∫_0^t u + q as a jet (the integral's derivatives are u's), R from the
// shape, ω = vee(Rᵀ Ṙ).
MotionState Evaluate(const Shape& shape, const std::vector<Eigen::Vector3d>& knots, double t) {
  const Jet time = Jet::Variable(t);
  Vec3<Jet> p = shape.Offset(time);
  if (shape.integrated()) {
    const Vec3<Jet> u = shape.Integrand(time);
    const Eigen::Vector3d integral = IntegralFromZero(shape, knots, t);
    for (int i = 0; i < 3; ++i) {
      p[i].c[0] += integral[i];
      for (int k = 1; k < kTerms; ++k) p[i].c[k] += u[i].c[k - 1] / k;
    }
  }
  const Mat3<Jet> R = shape.Attitude(p, time);
  Eigen::Matrix3d R0, R1;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      R0(i, j) = R[i][j].c[0];
      R1(i, j) = R[i][j].c[1];
    }
  }
  // Ṙ = R [ω]×, so [ω]× = Rᵀ Ṙ; its antisymmetric part removes rounding.
  const Eigen::Matrix3d W = R0.transpose() * R1;
  MotionState state;
  state.position = {p[0].c[0], p[1].c[0], p[2].c[0]};
  state.velocity = {p[0].c[1], p[1].c[1], p[2].c[1]};
  state.angular_velocity = 0.5 * Eigen::Vector3d(W(2, 1) - W(1, 2), W(0, 2) - W(2, 0), W(1, 0) - W(0, 1));
  state.orientation = Eigen::Quaterniond(R0).normalized();
  return state;
}

// Samples of the nominal grid, floor(duration · rate) + 1. The relative 1e-12 guards floor() against
// products such as 0.29 · 100 = 28.999999999999996.
double NominalGridSize(double duration_s, double rate_hz) {
  return std::floor(duration_s * rate_hz * (1.0 + 1e-12)) + 1.0;
}

constexpr MotionKind kAllKinds[] = {MotionKind::kCar, MotionKind::kLegged, MotionKind::kDrone, MotionKind::kHandheld};

}  // namespace

// ---------------------------------------------------------------------------------------------

std::string_view ToString(MotionKind kind) {
  switch (kind) {
    case MotionKind::kCar:
      return "car";
    case MotionKind::kLegged:
      return "legged";
    case MotionKind::kDrone:
      return "drone";
    case MotionKind::kHandheld:
      return "handheld";
  }
  return "?";
}

std::optional<MotionKind> MotionKindFromString(std::string_view name) {
  for (MotionKind kind : kAllKinds) {
    if (name == ToString(kind)) return kind;
  }
  return std::nullopt;
}

MotionDefaults DefaultsFor(MotionKind kind) {
  switch (kind) {
    case MotionKind::kCar:
      return {100.0, 50.0};
    case MotionKind::kLegged:
      return {10.0, 200.0};
    case MotionKind::kDrone:
      return {60.0, 200.0};
    case MotionKind::kHandheld:
      return {30.0, 100.0};
  }
  return {60.0, 100.0};
}

void MotionOptions::Validate() const {
  const OptionCheck check("MotionOptions");
  check(std::find(std::begin(kAllKinds), std::end(kAllKinds), kind) != std::end(kAllKinds), "kind",
        "must be one of car, legged, drone, handheld, got {}", static_cast<int>(kind));
  if (duration_s) {
    const double duration = *duration_s;
    check(duration > 0 && std::isfinite(duration), "duration_s", "must be a positive number of seconds, got {}",
          duration);
    check(duration <= kMaxDurationS, "duration_s", "must be at most 1e6 s, got {}", duration);
  }
  if (rate_hz) {
    const double rate = *rate_hz;
    check(rate > 0 && std::isfinite(rate), "rate_hz", "must be a positive number of Hz, got {}", rate);
    if (duration_s) {
      check(NominalGridSize(*duration_s, rate) <= kMaxSamples, "rate_hz",
            "must give at most 1e8 samples over the duration ({} s), got {} Hz", *duration_s, rate);
    }
  }
  check(start_stamp_ns <= kMaxAbsStartNs && start_stamp_ns >= -kMaxAbsStartNs, "start_stamp_ns",
        "must be within ±4e18 ns, got {}", start_stamp_ns);
}

struct MotionModel::Impl {
  MotionOptions options;
  std::unique_ptr<const Shape> shape;
  std::vector<Eigen::Vector3d> knots;  // ∫_0^{k h} u, k = 0 .. ceil(duration / h) + 1 (integrated kinds)
  int64_t samples = 0;                 // of the nominal grid
};

MotionModel::MotionModel(const MotionOptions& options) {
  MotionOptions resolved = options;
  const MotionDefaults defaults = DefaultsFor(options.kind);
  if (!resolved.duration_s) resolved.duration_s = defaults.duration_s;
  if (!resolved.rate_hz) resolved.rate_hz = defaults.rate_hz;
  resolved.Validate();
  const double duration = *resolved.duration_s, rate = *resolved.rate_hz;
  auto impl = std::make_shared<Impl>(Impl{resolved, internal::MakeShape(options.kind, options.seed), {}, 0});
  impl->samples = static_cast<int64_t>(NominalGridSize(duration, rate));
  if (impl->shape->integrated()) {
    const auto count = static_cast<size_t>(std::ceil(duration / kKnotSpacingS)) + 2;
    impl->knots.reserve(count);
    impl->knots.push_back(Eigen::Vector3d::Zero());
    for (size_t k = 1; k < count; ++k) {
      impl->knots.push_back(impl->knots.back() + Integrate(*impl->shape, (k - 1.0) * kKnotSpacingS, k * kKnotSpacingS));
    }
  }
  impl_ = std::move(impl);
}

const MotionOptions& MotionModel::options() const { return impl_->options; }

MotionState MotionModel::StateAtTime(double t_s) const { return Evaluate(*impl_->shape, impl_->knots, t_s); }

MotionState MotionModel::StateAt(int64_t stamp_ns) const {
  return StateAtTime(static_cast<double>(stamp_ns - impl_->options.start_stamp_ns) * 1e-9);
}

std::vector<int64_t> MotionModel::NominalStamps() const {
  std::vector<int64_t> stamps(static_cast<size_t>(impl_->samples));
  const double period_ns = 1e9 / *impl_->options.rate_hz;
  for (size_t i = 0; i < stamps.size(); ++i) {
    stamps[i] = impl_->options.start_stamp_ns + static_cast<int64_t>(std::llround(static_cast<double>(i) * period_ns));
  }
  return stamps;
}

traj::Trajectory SampleMotion(const MotionModel& model, std::span<const int64_t> stamps_ns) {
  traj::Trajectory trajectory(traj::Channels{traj::OrientationKind::kQuaternion, true, true, true});
  trajectory.Reserve(static_cast<Eigen::Index>(stamps_ns.size()));
  Eigen::Quaterniond previous(1.0, 0.0, 0.0, 0.0);
  for (const int64_t stamp : stamps_ns) {
    const MotionState state = model.StateAt(stamp);
    Eigen::Quaterniond q = state.orientation;
    if (q.coeffs().dot(previous.coeffs()) < 0.0) q.coeffs() = -q.coeffs();
    previous = q;
    const double quaternion[4] = {q.x(), q.y(), q.z(), q.w()};
    trajectory.Append(stamp, state.position.data(), quaternion, state.velocity.data(), state.angular_velocity.data());
  }
  return trajectory;
}

traj::Trajectory GenerateMotion(const MotionModel& model) {
  const std::vector<int64_t> stamps = model.NominalStamps();
  return SampleMotion(model, stamps);
}

traj::Trajectory GenerateMotion(const MotionOptions& options) { return GenerateMotion(MotionModel(options)); }

}  // namespace cheval::sim

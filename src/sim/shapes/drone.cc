// Multirotor on a figure-eight (docs/sim.md, "The kinds": drone).
#include <algorithm>
#include <cmath>
#include <memory>

#include "../internal/shape.h"
#include "cheval/common/random.h"

namespace cheval::sim::internal {
namespace {

constexpr double kGravity = 9.81;      // m/s², along the thrust direction's vertical
constexpr double kDronePeakSpeed = 8.0;  // m/s, by construction

Vec3<Jet> Cross(const Vec3<Jet>& a, const Vec3<Jet>& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

Vec3<Jet> Normalized(const Vec3<Jet>& a) {
  const Jet n = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
  return {a[0] / n, a[1] / n, a[2] / n};
}

// q = c + Rz(γ) (A sin(w t + φ), B sin(2 w t), D sin(3 w t + φ_z)) with no integral part, period
// 2π/w of 14–20 s, φ ∈ [-0.3, 0.3] (far from ±π/4, where the curve degenerates into a parabola flown
// back and forth with stops). Shape ratios A : B : D are drawn, then scaled so the peak speed over a
// period is 8 m/s. Yaw along the horizontal velocity; the body z axis along a + g e_z (thrust), body
// x the heading projected perpendicular to it (differential flatness, Mellinger & Kumar 2011).
class Drone final : public Shape {
 public:
  explicit Drone(Random& r) {
    A = r.Uniform(1.0, 1.4);
    B = r.Uniform(0.5, 0.7);
    D = r.Uniform(0.03, 0.06);
    w = kTwoPi / r.Uniform(14.0, 20.0);
    phase = r.Uniform(-0.3, 0.3);
    phase_z = r.Uniform(0.0, kTwoPi);
    gamma = r.Uniform(-kPi, kPi);
    cz = r.Uniform(1.5, 3.0);
    // Peak speed over one period, sampled densely: relative error ~ (3·2π/n)²/8 ≈ 1e-7 for n = 2e4.
    const int n = 20'000;
    double peak = 0.0;
    for (int i = 0; i < n; ++i) {
      const Vec3<Jet> p = Drone::Offset(Jet::Variable(kTwoPi / w * i / n));
      peak = std::max(peak, std::sqrt(p[0].c[1] * p[0].c[1] + p[1].c[1] * p[1].c[1] + p[2].c[1] * p[2].c[1]));
    }
    const double scale = kDronePeakSpeed / peak;
    A *= scale;
    B *= scale;
    D *= scale;
  }

  bool integrated() const override { return false; }
  Vec3<double> Integrand(double) const override { return {0.0, 0.0, 0.0}; }
  Vec3<Jet> Integrand(const Jet&) const override { return {Jet(0.0), Jet(0.0), Jet(0.0)}; }
  Vec3<Jet> Offset(const Jet& t) const override {
    const Jet x = A * sin(w * t + phase), y = B * sin(2.0 * w * t);
    const double cg = std::cos(gamma), sg = std::sin(gamma);
    return {cg * x - sg * y, sg * x + cg * y, cz + D * sin(3.0 * w * t + phase_z)};
  }
  Mat3<Jet> Attitude(const Vec3<Jet>& p, const Jet&) const override {
    const Vec3<Jet> v = {Derivative(p[0]), Derivative(p[1]), Derivative(p[2])};
    const Vec3<Jet> thrust = {Derivative(v[0]), Derivative(v[1]), Derivative(v[2]) + kGravity};
    const Jet horizontal = sqrt(v[0] * v[0] + v[1] * v[1]);
    const Vec3<Jet> heading = {v[0] / horizontal, v[1] / horizontal, Jet(0.0)};
    const Vec3<Jet> b3 = Normalized(thrust);
    const Vec3<Jet> b2 = Normalized(Cross(b3, heading));
    const Vec3<Jet> b1 = Cross(b2, b3);
    return {{{b1[0], b2[0], b3[0]}, {b1[1], b2[1], b3[1]}, {b1[2], b2[2], b3[2]}}};
  }

 private:
  double A, B, D, w, phase, phase_z, gamma, cz;
};

}  // namespace

std::unique_ptr<const Shape> MakeDrone(Random& random) { return std::make_unique<const Drone>(random); }

}  // namespace cheval::sim::internal

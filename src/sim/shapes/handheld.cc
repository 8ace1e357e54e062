// Camera carried by a walking person (docs/sim.md, "The kinds": handheld).
#include <cmath>
#include <memory>

#include "../internal/shape.h"
#include "../internal/streams.h"
#include "cheval/common/random.h"

namespace cheval::sim::internal {
namespace {

// Path speed s = s0 + s1 sin(ν t + φ), s0 ∈ [0.9, 1.1], s1 ∈ [0.15, 0.3] (period 15–25 s); path
// heading ψ = ψ0 + two sinusoids (yaw-rate amplitudes 0.15–0.25 and 0.1–0.2 rad/s, periods 20–40 and
// 8–15 s); u = s (cos ψ, sin ψ, 0). Step frequency f_s ∈ [1.5, 2] Hz: height 1.45 m +
// a_b sin(2π f_s t + ·), a_b ∈ [2, 4] cm, and sideways sway 1–2 cm at f_s/2 along (-sin ψ, cos ψ).
// Camera: yaw ψ + Y1 sin(2π f1 t + ·) + Y2 sin(2π f2 t + ·) (Y1 ∈ [0.6, 0.9] rad at 0.12–0.2 Hz,
// Y2 ∈ [0.12, 0.2] rad at 0.6–0.9 Hz), pitch 0.15 + P1 sin(2π g t + ·) + 0.02 sin(2π f_s t + ·)
// (P1 ∈ [0.25, 0.4] rad at 0.1–0.25 Hz), roll 0.04–0.08 sin(2π h t + ·) (0.2–0.4 Hz) +
// 0.02 sin(π f_s t + ·).
class Handheld final : public IntegratedShape<Handheld> {
 public:
  explicit Handheld(Random& r) {
    s0 = r.Uniform(0.9, 1.1);
    s1 = r.Uniform(0.15, 0.3);
    nu = kTwoPi / r.Uniform(15.0, 25.0);
    phi = r.Uniform(0.0, kTwoPi);
    psi0 = r.Uniform(-kPi, kPi);
    m1 = kTwoPi / r.Uniform(20.0, 40.0);
    a1 = SignedUniform(r, 0.15, 0.25) / m1;
    t1 = r.Uniform(0.0, kTwoPi);
    m2 = kTwoPi / r.Uniform(8.0, 15.0);
    a2 = SignedUniform(r, 0.1, 0.2) / m2;
    t2 = r.Uniform(0.0, kTwoPi);
    ws = kTwoPi * r.Uniform(1.5, 2.0);
    bounce = r.Uniform(0.02, 0.04);
    chi_b = r.Uniform(0.0, kTwoPi);
    sway = r.Uniform(0.01, 0.02);
    chi_s = r.Uniform(0.0, kTwoPi);
    Y1 = r.Uniform(0.6, 0.9);
    y1 = kTwoPi * r.Uniform(0.12, 0.2);
    c1 = r.Uniform(0.0, kTwoPi);
    Y2 = r.Uniform(0.12, 0.2);
    y2 = kTwoPi * r.Uniform(0.6, 0.9);
    c2 = r.Uniform(0.0, kTwoPi);
    P1 = r.Uniform(0.25, 0.4);
    p1 = kTwoPi * r.Uniform(0.1, 0.25);
    cp1 = r.Uniform(0.0, kTwoPi);
    cpb = r.Uniform(0.0, kTwoPi);
    R1 = r.Uniform(0.04, 0.08);
    r1 = kTwoPi * r.Uniform(0.2, 0.4);
    cr1 = r.Uniform(0.0, kTwoPi);
    crs = r.Uniform(0.0, kTwoPi);
  }

  template <class T>
  Vec3<T> IntegrandAt(const T& t) const {
    using std::cos;
    using std::sin;
    const T s = s0 + s1 * sin(nu * t + phi), psi = Heading(t);
    return {s * cos(psi), s * sin(psi), T(0.0)};
  }
  Vec3<Jet> Offset(const Jet& t) const override {
    const Jet psi = Heading(t);
    const Jet side = sway * sin(0.5 * ws * t + chi_s);
    return {-sin(psi) * side, cos(psi) * side, z0 + bounce * sin(ws * t + chi_b)};
  }
  Mat3<Jet> Attitude(const Vec3<Jet>&, const Jet& t) const override {
    const Jet yaw = Heading(t) + Y1 * sin(y1 * t + c1) + Y2 * sin(y2 * t + c2);
    const Jet pitch = P0 + P1 * sin(p1 * t + cp1) + Pb * sin(ws * t + cpb);
    const Jet roll = R1 * sin(r1 * t + cr1) + Rs * sin(0.5 * ws * t + crs);
    return RotationZYX(yaw, pitch, roll);
  }

 private:
  template <class T>
  T Heading(const T& t) const {
    using std::sin;
    return psi0 + a1 * sin(m1 * t + t1) + a2 * sin(m2 * t + t2);
  }

  double s0, s1, nu, phi;
  double psi0, a1, m1, t1, a2, m2, t2;
  double ws, z0 = 1.45, bounce, chi_b, sway, chi_s;
  double Y1, y1, c1, Y2, y2, c2;
  double P0 = 0.15, P1, p1, cp1, Pb = 0.02, cpb;
  double R1, r1, cr1, Rs = 0.02, crs;
};

}  // namespace

std::unique_ptr<const Shape> MakeHandheld(Random& random) { return std::make_unique<const Handheld>(random); }

}  // namespace cheval::sim::internal

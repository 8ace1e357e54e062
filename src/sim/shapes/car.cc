// Road vehicle (docs/sim.md, "The kinds": car).
#include <array>
#include <cmath>
#include <memory>

#include "../internal/shape.h"
#include "../internal/streams.h"
#include "cheval/common/random.h"

namespace cheval::sim::internal {
namespace {

// Horizontal speed s = 8 + 4 sin(n1 t + f1) + 2.5 sin(n2 t + f2) ∈ [1.5, 14.5] m/s (periods 35–45 s
// and 11–15 s: accelerations and brakings up to ~1.8 m/s²). Heading ψ = ψ0 + Σ three sinusoids with
// yaw-rate amplitudes 0.05–0.09 rad/s (periods 40–60, 20–30, 9–14 s), so the curvature ψ'/s changes
// smoothly. Road grade g = G sin(·), G ∈ [0.02, 0.05]; u = s (cos ψ, sin ψ, g), q = 0.
// Attitude: yaw ψ (along the velocity), pitch -atan g (nose up uphill) - 0.01 s' (dip on braking),
// roll 0.01 s ψ' (outwards in turns), both 0.01 rad per m/s².
class Car final : public IntegratedShape<Car> {
 public:
  explicit Car(Random& r) {
    n1 = kTwoPi / r.Uniform(35.0, 45.0);
    n2 = kTwoPi / r.Uniform(11.0, 15.0);
    f1 = r.Uniform(0.0, kTwoPi);
    f2 = r.Uniform(0.0, kTwoPi);
    psi0 = r.Uniform(-kPi, kPi);
    const std::array<std::array<double, 2>, 3> periods = {{{40.0, 60.0}, {20.0, 30.0}, {9.0, 14.0}}};
    for (int k = 0; k < 3; ++k) {
      m[k] = kTwoPi / r.Uniform(periods[k][0], periods[k][1]);
      a[k] = SignedUniform(r, 0.05, 0.09) / m[k];  // heading amplitude from the yaw-rate amplitude
      th[k] = r.Uniform(0.0, kTwoPi);
    }
    grade = r.Uniform(0.02, 0.05);
    grade_rate = kTwoPi / r.Uniform(50.0, 90.0);
    grade_phase = r.Uniform(0.0, kTwoPi);
  }

  template <class T>
  Vec3<T> IntegrandAt(const T& t) const {
    using std::cos;
    using std::sin;
    const T s = Speed(t), psi = Heading(t);
    return {s * cos(psi), s * sin(psi), s * Grade(t)};
  }
  Vec3<Jet> Offset(const Jet&) const override { return {Jet(0.0), Jet(0.0), Jet(0.0)}; }
  Mat3<Jet> Attitude(const Vec3<Jet>&, const Jet& t) const override {
    const Jet s = Speed(t), psi = Heading(t);
    const Jet roll = k_roll * s * Derivative(psi);
    const Jet pitch = -atan(Grade(t)) - k_pitch * Derivative(s);
    return RotationZYX(psi, pitch, roll);
  }

 private:
  template <class T>
  T Speed(const T& t) const {
    using std::sin;
    return s0 + s1 * sin(n1 * t + f1) + s2 * sin(n2 * t + f2);
  }
  template <class T>
  T Heading(const T& t) const {
    using std::sin;
    T psi = T(psi0);
    for (int k = 0; k < 3; ++k) psi = psi + a[k] * sin(m[k] * t + th[k]);
    return psi;
  }
  template <class T>
  T Grade(const T& t) const {
    using std::sin;
    return grade * sin(grade_rate * t + grade_phase);
  }

  double s0 = 8.0, s1 = 4.0, s2 = 2.5, n1, n2, f1, f2;
  double psi0;
  std::array<double, 3> a, m, th;
  double grade, grade_rate, grade_phase;
  double k_roll = 0.01, k_pitch = 0.01;
};

}  // namespace

std::unique_ptr<const Shape> MakeCar(Random& random) { return std::make_unique<const Car>(random); }

}  // namespace cheval::sim::internal

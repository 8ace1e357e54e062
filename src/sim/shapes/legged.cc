// Trotting quadruped body (docs/sim.md, "The kinds": legged).
#include <cmath>
#include <memory>

#include "../internal/shape.h"
#include "../internal/streams.h"
#include "cheval/common/random.h"

namespace cheval::sim::internal {
namespace {

// Forward speed s = s0 + 0.2 sin(ν t + φ), s0 ∈ [0.55, 0.7] (period 6–10 s); heading
// ψ = ψ0 + α sin(μ t + θ) (yaw-rate amplitude 0.1–0.2 rad/s, period 8–14 s); u = s (cos ψ, sin ψ, 0).
// Gait frequency f ∈ [2, 3] Hz (ω_g = 2πf): height 0.32 m + a_z sin(ω_g t + χ_z), a_z ∈ [1, 1.5] cm,
// and lateral sway a_y sin(ω_g t + χ_y), a_y ∈ [0.5, 1] cm, along the body's left axis
// (-sin ψ, cos ψ). Attitude: yaw ψ + 0.01–0.02 sin(ω_g t + ·), pitch 0.01–0.02 sin(ω_g t + ·),
// roll 0.02–0.035 sin(ω_g t + ·) rad.
class Legged final : public IntegratedShape<Legged> {
 public:
  explicit Legged(Random& r) {
    s0 = r.Uniform(0.55, 0.7);
    nu = kTwoPi / r.Uniform(6.0, 10.0);
    phi = r.Uniform(0.0, kTwoPi);
    psi0 = r.Uniform(-kPi, kPi);
    mu = kTwoPi / r.Uniform(8.0, 14.0);
    alpha = SignedUniform(r, 0.1, 0.2) / mu;
    theta = r.Uniform(0.0, kTwoPi);
    wg = kTwoPi * r.Uniform(2.0, 3.0);
    az = r.Uniform(0.010, 0.015);
    chi_z = r.Uniform(0.0, kTwoPi);
    ay = r.Uniform(0.005, 0.010);
    chi_y = r.Uniform(0.0, kTwoPi);
    yaw_amp = r.Uniform(0.01, 0.02);
    chi_w = r.Uniform(0.0, kTwoPi);
    pitch_amp = r.Uniform(0.01, 0.02);
    chi_p = r.Uniform(0.0, kTwoPi);
    roll_amp = r.Uniform(0.02, 0.035);
    chi_r = r.Uniform(0.0, kTwoPi);
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
    const Jet sway = ay * sin(wg * t + chi_y);
    return {-sin(psi) * sway, cos(psi) * sway, h0 + az * sin(wg * t + chi_z)};
  }
  Mat3<Jet> Attitude(const Vec3<Jet>&, const Jet& t) const override {
    return RotationZYX(Heading(t) + yaw_amp * sin(wg * t + chi_w), pitch_amp * sin(wg * t + chi_p),
                       roll_amp * sin(wg * t + chi_r));
  }

 private:
  template <class T>
  T Heading(const T& t) const {
    using std::sin;
    return psi0 + alpha * sin(mu * t + theta);
  }

  double s0, s1 = 0.2, nu, phi;
  double psi0, alpha, mu, theta;
  double wg;
  double h0 = 0.32, az, chi_z, ay, chi_y;
  double yaw_amp, chi_w, pitch_amp, chi_p, roll_amp, chi_r;
};

}  // namespace

std::unique_ptr<const Shape> MakeLegged(Random& random) { return std::make_unique<const Legged>(random); }

}  // namespace cheval::sim::internal

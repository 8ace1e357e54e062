#include "cheval/sim/motion.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <utility>
#include <variant>

#include "cheval/common/error.h"

namespace cheval::sim {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kGravity = 9.81;      // m/s², thrust direction of the drone
constexpr double kMaxDurationS = 1e6;  // keeps the quadrature knots (one per second) small
constexpr double kMaxSamples = 1e8;
constexpr int64_t kMaxAbsStartNs = 4'000'000'000'000'000'000;
constexpr double kKnotSpacingS = 1.0;    // quadrature knots: cumulative integral every second
constexpr double kDronePeakSpeed = 8.0;  // m/s, by construction

// ---------------------------------------------------------------------------------------------
// Truncated Taylor arithmetic: a Jet holds f(t0 + τ) = Σ_k c[k] τ^k for k < kTerms, so c[1] is the
// first derivative and c[2] half the second. Every operation is exact on the truncated series,
// which makes derivatives of the closed forms exact (forward-mode differentiation of any order).
// Derivative() loses the top term (set to 0); callers use at most order kTerms - 2 of its result.
// Four terms suffice: the drone's attitude needs the acceleration's derivative, i.e. p'''.
constexpr int kTerms = 4;

struct Jet {
  std::array<double, kTerms> c{};

  Jet() = default;
  Jet(double value) { c[0] = value; }  // NOLINT(google-explicit-constructor): constants mix freely
  static Jet Variable(double t) {
    Jet x(t);
    x.c[1] = 1.0;
    return x;
  }

  friend Jet operator+(const Jet& a, const Jet& b) {
    Jet r;
    for (int k = 0; k < kTerms; ++k) r.c[k] = a.c[k] + b.c[k];
    return r;
  }
  friend Jet operator-(const Jet& a, const Jet& b) {
    Jet r;
    for (int k = 0; k < kTerms; ++k) r.c[k] = a.c[k] - b.c[k];
    return r;
  }
  friend Jet operator-(const Jet& a) {
    Jet r;
    for (int k = 0; k < kTerms; ++k) r.c[k] = -a.c[k];
    return r;
  }
  friend Jet operator*(const Jet& a, const Jet& b) {
    Jet r;
    for (int k = 0; k < kTerms; ++k) {
      for (int j = 0; j <= k; ++j) r.c[k] += a.c[j] * b.c[k - j];
    }
    return r;
  }
  friend Jet operator/(const Jet& a, const Jet& b) {
    Jet q;
    for (int k = 0; k < kTerms; ++k) {
      double s = a.c[k];
      for (int j = 1; j <= k; ++j) s -= b.c[j] * q.c[k - j];
      q.c[k] = s / b.c[0];
    }
    return q;
  }
  friend Jet sin(const Jet& u) { return SinCos(u)[0]; }
  friend Jet cos(const Jet& u) { return SinCos(u)[1]; }
  // (sin u, cos u): s' = c u', c' = -s u' coefficient by coefficient.
  static std::array<Jet, 2> SinCos(const Jet& u) {
    Jet s, c;
    s.c[0] = std::sin(u.c[0]);
    c.c[0] = std::cos(u.c[0]);
    for (int k = 1; k < kTerms; ++k) {
      double ds = 0.0, dc = 0.0;
      for (int j = 1; j <= k; ++j) {
        ds += j * u.c[j] * c.c[k - j];
        dc += j * u.c[j] * s.c[k - j];
      }
      s.c[k] = ds / k;
      c.c[k] = -dc / k;
    }
    return {s, c};
  }
  friend Jet sqrt(const Jet& u) {
    Jet r;
    r.c[0] = std::sqrt(u.c[0]);
    for (int k = 1; k < kTerms; ++k) {
      double s = u.c[k];
      for (int j = 1; j < k; ++j) s -= r.c[j] * r.c[k - j];
      r.c[k] = s / (2.0 * r.c[0]);
    }
    return r;
  }
  // d/dt of the series; the top coefficient is unknown and set to 0.
  friend Jet Derivative(const Jet& u) {
    Jet d;
    for (int k = 0; k + 1 < kTerms; ++k) d.c[k] = (k + 1) * u.c[k + 1];
    return d;
  }
  // The series with value `value` at τ = 0 whose derivative is `d` (exact: uses d up to kTerms - 2).
  friend Jet Antiderivative(double value, const Jet& d) {
    Jet r(value);
    for (int k = 1; k < kTerms; ++k) r.c[k] = d.c[k - 1] / k;
    return r;
  }
  friend Jet atan(const Jet& u) { return Antiderivative(std::atan(u.c[0]), Derivative(u) / (1.0 + u * u)); }
};

template <class T>
using Vec3 = std::array<T, 3>;
template <class T>
using Mat3 = std::array<std::array<T, 3>, 3>;  // row-major: m[row][column]

Vec3<Jet> Cross(const Vec3<Jet>& a, const Vec3<Jet>& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

Vec3<Jet> Normalized(const Vec3<Jet>& a) {
  const Jet n = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
  return {a[0] / n, a[1] / n, a[2] / n};
}

// R_world_body = Rz(yaw) Ry(pitch) Rx(roll) (body x forward, y left, z up; pitch > 0 is nose down).
Mat3<Jet> RotationZYX(const Jet& yaw, const Jet& pitch, const Jet& roll) {
  const auto [sy, cy] = Jet::SinCos(yaw);
  const auto [sp, cp] = Jet::SinCos(pitch);
  const auto [sr, cr] = Jet::SinCos(roll);
  return {{{cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr},
           {sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr},
           {-sp, cp * sr, cp * cr}}};
}

// ---------------------------------------------------------------------------------------------
// Randomness: std::mt19937_64 (fully specified by the standard) with our own uniform and normal
// transforms, so a seed gives the same numbers with every standard library. One stream per use.
class Random {
 public:
  Random(uint64_t seed, uint64_t stream) : engine_(SplitMix(seed ^ SplitMix(stream + 0x632be59bd9b4e019ULL))) {}

  double Uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }  // [0, 1)
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  double Sign() { return Uniform() < 0.5 ? -1.0 : 1.0; }
  // Standard normal by Box–Muller (both outputs used).
  double Normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double u1 = 1.0 - Uniform();  // (0, 1]
    const double u2 = Uniform();
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(kTwoPi * u2);
    has_spare_ = true;
    return r * std::cos(kTwoPi * u2);
  }

 private:
  static uint64_t SplitMix(uint64_t x) {
    x += 0x9e3779b97f4a7c15ULL;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
    return x ^ (x >> 31);
  }

  std::mt19937_64 engine_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

enum Stream : uint64_t { kShape = 1, kGaps, kDropout, kJitter, kNoise, kAddNoise, kRotationNoise, kEstimate };

// ---------------------------------------------------------------------------------------------
// The kinds. Each is p(t) = ∫_0^t u(τ) dτ + q(t) with u = Integrand (only when kIntegrated) and
// q = Offset in closed form, and R(t) = Attitude(p, t). Parameters are drawn in the constructor.

// Road vehicle. Horizontal speed s = 8 + 4 sin(n1 t + f1) + 2.5 sin(n2 t + f2) ∈ [1.5, 14.5] m/s
// (periods 35–45 s and 11–15 s: accelerations and brakings up to ~1.8 m/s²). Heading ψ = ψ0 + Σ
// three sinusoids with yaw-rate amplitudes 0.05–0.09 rad/s (periods 40–60, 20–30, 9–14 s), so the
// curvature ψ'/s changes smoothly. Road grade g = G sin(·), G ∈ [0.02, 0.05]; u = s (cos ψ, sin ψ, g).
// Attitude: yaw ψ (along the velocity), pitch -atan g (nose up uphill) - 0.01 s' (dip on braking),
// roll 0.01 s ψ' (outwards in turns), both 0.01 rad per m/s².
struct Car {
  static constexpr bool kIntegrated = true;
  double s0 = 8.0, s1 = 4.0, s2 = 2.5, n1, n2, f1, f2;
  double psi0;
  std::array<double, 3> a, m, th;
  double grade, grade_rate, grade_phase;
  double k_roll = 0.01, k_pitch = 0.01;

  explicit Car(Random& r) {
    n1 = kTwoPi / r.Uniform(35.0, 45.0);
    n2 = kTwoPi / r.Uniform(11.0, 15.0);
    f1 = r.Uniform(0.0, kTwoPi);
    f2 = r.Uniform(0.0, kTwoPi);
    psi0 = r.Uniform(-kPi, kPi);
    const std::array<std::array<double, 2>, 3> periods = {{{40.0, 60.0}, {20.0, 30.0}, {9.0, 14.0}}};
    for (int k = 0; k < 3; ++k) {
      m[k] = kTwoPi / r.Uniform(periods[k][0], periods[k][1]);
      a[k] = r.Sign() * r.Uniform(0.05, 0.09) / m[k];  // heading amplitude from the yaw-rate amplitude
      th[k] = r.Uniform(0.0, kTwoPi);
    }
    grade = r.Uniform(0.02, 0.05);
    grade_rate = kTwoPi / r.Uniform(50.0, 90.0);
    grade_phase = r.Uniform(0.0, kTwoPi);
  }
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
  template <class T>
  Vec3<T> Integrand(const T& t) const {
    using std::cos;
    using std::sin;
    const T s = Speed(t), psi = Heading(t);
    return {s * cos(psi), s * sin(psi), s * Grade(t)};
  }
  Vec3<Jet> Offset(const Jet&) const { return {Jet(0.0), Jet(0.0), Jet(0.0)}; }
  Mat3<Jet> Attitude(const Vec3<Jet>&, const Jet& t) const {
    const Jet s = Speed(t), psi = Heading(t);
    const Jet roll = k_roll * s * Derivative(psi);
    const Jet pitch = -atan(Grade(t)) - k_pitch * Derivative(s);
    return RotationZYX(psi, pitch, roll);
  }
};

// Trotting quadruped body. Forward speed s = s0 + 0.2 sin(ν t + φ), s0 ∈ [0.55, 0.7] (period 6–10 s);
// heading ψ = ψ0 + α sin(μ t + θ) (yaw-rate amplitude 0.1–0.2 rad/s, period 8–14 s); u = s (cos ψ,
// sin ψ, 0). Gait frequency f ∈ [2, 3] Hz (ω_g = 2πf): height 0.32 m + a_z sin(ω_g t + χ_z),
// a_z ∈ [1, 1.5] cm, and lateral sway a_y sin(ω_g t + χ_y), a_y ∈ [0.5, 1] cm, along the body's left
// axis (-sin ψ, cos ψ). Attitude: yaw ψ + 0.01–0.02 sin(ω_g t + ·), pitch 0.01–0.02 sin(ω_g t + ·),
// roll 0.02–0.035 sin(ω_g t + ·) rad.
struct Legged {
  static constexpr bool kIntegrated = true;
  double s0, s1 = 0.2, nu, phi;
  double psi0, alpha, mu, theta;
  double wg;
  double h0 = 0.32, az, chi_z, ay, chi_y;
  double yaw_amp, chi_w, pitch_amp, chi_p, roll_amp, chi_r;

  explicit Legged(Random& r) {
    s0 = r.Uniform(0.55, 0.7);
    nu = kTwoPi / r.Uniform(6.0, 10.0);
    phi = r.Uniform(0.0, kTwoPi);
    psi0 = r.Uniform(-kPi, kPi);
    mu = kTwoPi / r.Uniform(8.0, 14.0);
    alpha = r.Sign() * r.Uniform(0.1, 0.2) / mu;
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
  T Heading(const T& t) const {
    using std::sin;
    return psi0 + alpha * sin(mu * t + theta);
  }
  template <class T>
  Vec3<T> Integrand(const T& t) const {
    using std::cos;
    using std::sin;
    const T s = s0 + s1 * sin(nu * t + phi), psi = Heading(t);
    return {s * cos(psi), s * sin(psi), T(0.0)};
  }
  Vec3<Jet> Offset(const Jet& t) const {
    const Jet psi = Heading(t);
    const Jet sway = ay * sin(wg * t + chi_y);
    return {-sin(psi) * sway, cos(psi) * sway, h0 + az * sin(wg * t + chi_z)};
  }
  Mat3<Jet> Attitude(const Vec3<Jet>&, const Jet& t) const {
    return RotationZYX(Heading(t) + yaw_amp * sin(wg * t + chi_w), pitch_amp * sin(wg * t + chi_p),
                       roll_amp * sin(wg * t + chi_r));
  }
};

// Multirotor on a figure-eight: q = c + Rz(γ) (A sin(w t + φ), B sin(2 w t), D sin(3 w t + φ_z)),
// period 2π/w of 14–20 s, φ ∈ [-0.3, 0.3] (far from ±π/4, where the curve degenerates into a parabola
// flown back and forth with stops). Shape ratios A : B : D are drawn, then scaled so the peak speed
// over a period is 8 m/s. Yaw along the horizontal velocity; the body z axis along a + g e_z (thrust),
// body x the heading projected perpendicular to it (differential flatness, Mellinger & Kumar 2011).
struct Drone {
  static constexpr bool kIntegrated = false;
  double A, B, D, w, phase, phase_z, gamma, cz;

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
      const Vec3<Jet> p = Offset(Jet::Variable(kTwoPi / w * i / n));
      peak = std::max(peak, std::sqrt(p[0].c[1] * p[0].c[1] + p[1].c[1] * p[1].c[1] + p[2].c[1] * p[2].c[1]));
    }
    const double scale = kDronePeakSpeed / peak;
    A *= scale;
    B *= scale;
    D *= scale;
  }
  template <class T>
  Vec3<T> Integrand(const T&) const {
    return {T(0.0), T(0.0), T(0.0)};
  }
  Vec3<Jet> Offset(const Jet& t) const {
    const Jet x = A * sin(w * t + phase), y = B * sin(2.0 * w * t);
    const double cg = std::cos(gamma), sg = std::sin(gamma);
    return {cg * x - sg * y, sg * x + cg * y, cz + D * sin(3.0 * w * t + phase_z)};
  }
  Mat3<Jet> Attitude(const Vec3<Jet>& p, const Jet&) const {
    const Vec3<Jet> v = {Derivative(p[0]), Derivative(p[1]), Derivative(p[2])};
    const Vec3<Jet> thrust = {Derivative(v[0]), Derivative(v[1]), Derivative(v[2]) + kGravity};
    const Jet horizontal = sqrt(v[0] * v[0] + v[1] * v[1]);
    const Vec3<Jet> heading = {v[0] / horizontal, v[1] / horizontal, Jet(0.0)};
    const Vec3<Jet> b3 = Normalized(thrust);
    const Vec3<Jet> b2 = Normalized(Cross(b3, heading));
    const Vec3<Jet> b1 = Cross(b2, b3);
    return {{{b1[0], b2[0], b3[0]}, {b1[1], b2[1], b3[1]}, {b1[2], b2[2], b3[2]}}};
  }
};

// Camera carried by a walking person. Path speed s = s0 + s1 sin(ν t + φ), s0 ∈ [0.9, 1.1],
// s1 ∈ [0.15, 0.3] (period 15–25 s); path heading ψ = ψ0 + two sinusoids (yaw-rate amplitudes
// 0.15–0.25 and 0.1–0.2 rad/s, periods 20–40 and 8–15 s); u = s (cos ψ, sin ψ, 0). Step frequency
// f_s ∈ [1.5, 2] Hz: height 1.45 m + a_b sin(2π f_s t + ·), a_b ∈ [2, 4] cm, and sideways sway
// 1–2 cm at f_s/2 along (-sin ψ, cos ψ). Camera: yaw ψ + Y1 sin(2π f1 t + ·) + Y2 sin(2π f2 t + ·)
// (Y1 ∈ [0.6, 0.9] rad at 0.12–0.2 Hz, Y2 ∈ [0.12, 0.2] rad at 0.6–0.9 Hz), pitch 0.15 + P1 sin(2π g t
// + ·) + 0.02 sin(2π f_s t + ·) (P1 ∈ [0.25, 0.4] rad at 0.1–0.25 Hz), roll 0.04–0.08 sin(2π h t + ·)
// (0.2–0.4 Hz) + 0.02 sin(π f_s t + ·).
struct Handheld {
  static constexpr bool kIntegrated = true;
  double s0, s1, nu, phi;
  double psi0, a1, m1, t1, a2, m2, t2;
  double ws, z0 = 1.45, bounce, chi_b, sway, chi_s;
  double Y1, y1, c1, Y2, y2, c2;
  double P0 = 0.15, P1, p1, cp1, Pb = 0.02, cpb;
  double R1, r1, cr1, Rs = 0.02, crs;

  explicit Handheld(Random& r) {
    s0 = r.Uniform(0.9, 1.1);
    s1 = r.Uniform(0.15, 0.3);
    nu = kTwoPi / r.Uniform(15.0, 25.0);
    phi = r.Uniform(0.0, kTwoPi);
    psi0 = r.Uniform(-kPi, kPi);
    m1 = kTwoPi / r.Uniform(20.0, 40.0);
    a1 = r.Sign() * r.Uniform(0.15, 0.25) / m1;
    t1 = r.Uniform(0.0, kTwoPi);
    m2 = kTwoPi / r.Uniform(8.0, 15.0);
    a2 = r.Sign() * r.Uniform(0.1, 0.2) / m2;
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
  T Heading(const T& t) const {
    using std::sin;
    return psi0 + a1 * sin(m1 * t + t1) + a2 * sin(m2 * t + t2);
  }
  template <class T>
  Vec3<T> Integrand(const T& t) const {
    using std::cos;
    using std::sin;
    const T s = s0 + s1 * sin(nu * t + phi), psi = Heading(t);
    return {s * cos(psi), s * sin(psi), T(0.0)};
  }
  Vec3<Jet> Offset(const Jet& t) const {
    const Jet psi = Heading(t);
    const Jet side = sway * sin(0.5 * ws * t + chi_s);
    return {-sin(psi) * side, cos(psi) * side, z0 + bounce * sin(ws * t + chi_b)};
  }
  Mat3<Jet> Attitude(const Vec3<Jet>&, const Jet& t) const {
    const Jet yaw = Heading(t) + Y1 * sin(y1 * t + c1) + Y2 * sin(y2 * t + c2);
    const Jet pitch = P0 + P1 * sin(p1 * t + cp1) + Pb * sin(ws * t + cpb);
    const Jet roll = R1 * sin(r1 * t + cr1) + Rs * sin(0.5 * ws * t + crs);
    return RotationZYX(yaw, pitch, roll);
  }
};

using Shape = std::variant<Car, Legged, Drone, Handheld>;

Shape MakeShape(MotionKind kind, uint64_t seed) {
  Random random(seed, kShape);
  switch (kind) {
    case MotionKind::kCar:
      return Car(random);
    case MotionKind::kLegged:
      return Legged(random);
    case MotionKind::kDrone:
      return Drone(random);
    case MotionKind::kHandheld:
      return Handheld(random);
  }
  throw UsageError("unknown motion kind");
}

// ---------------------------------------------------------------------------------------------
// Quadrature of u: 16-point Gauss–Legendre on pieces of at most kKnotSpacingS. The integrands have
// frequencies below ~1 rad/s, so the error on a 1 s piece is ~ (ω h/2)^32 / 32!, far below rounding.
constexpr int kGaussPoints = 16;

struct GaussLegendre {
  std::array<double, kGaussPoints> x{}, w{};
  GaussLegendre() {
    // Newton on the Legendre polynomial P_n from the asymptotic guesses (Numerical Recipes gauleg).
    const int n = kGaussPoints;
    for (int i = 0; i < n; ++i) {
      double z = std::cos(kPi * (i + 0.75) / (n + 0.5));
      double dp = 0.0;
      for (int iteration = 0; iteration < 100; ++iteration) {
        double p0 = 1.0, p1 = z;
        for (int j = 2; j <= n; ++j) {
          const double p2 = ((2.0 * j - 1.0) * z * p1 - (j - 1.0) * p0) / j;
          p0 = p1;
          p1 = p2;
        }
        dp = n * (z * p1 - p0) / (z * z - 1.0);
        const double step = p1 / dp;
        z -= step;
        if (std::abs(step) < 1e-16) break;
      }
      x[i] = z;
      w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
    }
  }
};

const GaussLegendre& Gauss() {
  static const GaussLegendre gauss;
  return gauss;
}

template <class S>
Eigen::Vector3d Integrate(const S& shape, double a, double b) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  if (a == b) return sum;
  const GaussLegendre& gauss = Gauss();
  const int pieces = std::max(1, static_cast<int>(std::ceil(std::abs(b - a) / kKnotSpacingS - 1e-9)));
  const double length = (b - a) / pieces;
  for (int piece = 0; piece < pieces; ++piece) {
    const double lo = a + piece * length;
    const double mid = lo + 0.5 * length, half = 0.5 * length;
    for (int i = 0; i < kGaussPoints; ++i) {
      const Vec3<double> u = shape.Integrand(mid + half * gauss.x[i]);
      sum += gauss.w[i] * half * Eigen::Vector3d(u[0], u[1], u[2]);
    }
  }
  return sum;
}

// ∫_0^t u from the cumulative knots (knots[k] = ∫_0^{k h} u), then the last partial piece.
template <class S>
Eigen::Vector3d IntegralFromZero(const S& shape, const std::vector<Eigen::Vector3d>& knots, double t) {
  if (t <= 0.0 || knots.empty()) return Integrate(shape, 0.0, t);
  const auto last = static_cast<double>(knots.size() - 1);
  const double k = std::min(std::floor(t / kKnotSpacingS), last);
  return knots[static_cast<size_t>(k)] + Integrate(shape, k * kKnotSpacingS, t);
}

template <class S>
MotionState Evaluate(const S& shape, const std::vector<Eigen::Vector3d>& knots, double t) {
  const Jet time = Jet::Variable(t);
  Vec3<Jet> p = shape.Offset(time);
  if constexpr (S::kIntegrated) {
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

void CheckPositive(double value, const char* option, const char* unit) {
  if (!(value > 0) || !std::isfinite(value)) {
    throw UsageError(fmt::format("{} must be a positive number of {}, got {}", option, unit, value));
  }
}

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
  for (MotionKind kind : {MotionKind::kCar, MotionKind::kLegged, MotionKind::kDrone, MotionKind::kHandheld}) {
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

struct MotionModel::Impl {
  MotionOptions options;
  Shape shape;
  std::vector<Eigen::Vector3d> knots;  // ∫_0^{k h} u, k = 0 .. ceil(duration / h) + 1 (integrated kinds)
  int64_t samples = 0;                 // of the nominal grid
};

MotionModel::MotionModel(const MotionOptions& options) {
  MotionOptions resolved = options;
  const MotionDefaults defaults = DefaultsFor(options.kind);
  if (!resolved.duration_s) resolved.duration_s = defaults.duration_s;
  if (!resolved.rate_hz) resolved.rate_hz = defaults.rate_hz;
  const double duration = *resolved.duration_s, rate = *resolved.rate_hz;
  CheckPositive(duration, "--duration", "seconds");
  if (duration > kMaxDurationS) throw UsageError(fmt::format("--duration must be at most 1e6 s, got {}", duration));
  CheckPositive(rate, "--rate", "Hz");
  // The relative 1e-12 guards floor() against products such as 0.29 · 100 = 28.999999999999996.
  const double grid = std::floor(duration * rate * (1.0 + 1e-12));
  if (grid + 1.0 > kMaxSamples) throw UsageError("--duration x --rate asks for more than 1e8 samples");
  if (options.start_stamp_ns > kMaxAbsStartNs || options.start_stamp_ns < -kMaxAbsStartNs) {
    throw UsageError(fmt::format("start stamp must be within ±4e18 ns, got {}", options.start_stamp_ns));
  }
  auto impl = std::make_shared<Impl>(Impl{resolved, MakeShape(options.kind, options.seed), {}, 0});
  impl->samples = static_cast<int64_t>(grid) + 1;
  std::visit(
      [&](const auto& shape) {
        if constexpr (std::decay_t<decltype(shape)>::kIntegrated) {
          const auto count = static_cast<size_t>(std::ceil(duration / kKnotSpacingS)) + 2;
          impl->knots.reserve(count);
          impl->knots.push_back(Eigen::Vector3d::Zero());
          for (size_t k = 1; k < count; ++k) {
            impl->knots.push_back(impl->knots.back() + Integrate(shape, (k - 1.0) * kKnotSpacingS, k * kKnotSpacingS));
          }
        }
      },
      impl->shape);
  impl_ = std::move(impl);
}

const MotionOptions& MotionModel::options() const { return impl_->options; }

MotionState MotionModel::StateAtTime(double t_s) const {
  return std::visit([&](const auto& shape) { return Evaluate(shape, impl_->knots, t_s); }, impl_->shape);
}

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

traj::Trajectory Measure(const MotionModel& model, const MeasurementOptions& measurement) {
  const MotionOptions& options = model.options();
  const double duration = *options.duration_s, rate = *options.rate_hz;
  const double noise = measurement.noise_m, jitter = measurement.jitter_s;
  if (!(noise >= 0) || !std::isfinite(noise)) {
    throw UsageError(fmt::format("--noise must be a non-negative number of metres, got {}", noise));
  }
  if (!(jitter >= 0) || !(jitter < duration)) {
    throw UsageError(fmt::format("--jitter must be a non-negative number of seconds below --duration ({} s), got {}",
                                 duration, jitter));
  }
  const double rotation_noise = measurement.rotation_noise_rad;
  if (!(rotation_noise >= 0) || !std::isfinite(rotation_noise)) {
    throw UsageError(fmt::format("--rotation-noise must be a non-negative number of radians, got {}", rotation_noise));
  }
  const double dropout = measurement.dropout_probability;
  if (!(dropout >= 0) || !(dropout < 1)) {
    throw UsageError(fmt::format("--dropout must be a probability in [0, 1), got {}", dropout));
  }
  const int gap_count = measurement.gap_count;
  const double gap_s = measurement.gap_s;
  if (gap_count < 0) throw UsageError(fmt::format("--gap-count must be non-negative, got {}", gap_count));
  if (gap_count > 0 && (!(gap_s > 0) || !std::isfinite(gap_s))) {
    throw UsageError(
        fmt::format("--gap-seconds must be a positive number of seconds when --gap-count is given, got {}", gap_s));
  }
  if (gap_count == 0 && gap_s != 0) {
    throw UsageError(fmt::format("--gap-seconds {} needs --gap-count (the number of gaps)", gap_s));
  }
  const double slot = gap_count > 0 ? duration / gap_count : 0.0;
  const double margin = 1.0 / rate;
  if (gap_count > 0 && !(gap_s + 2.0 * margin < slot)) {
    throw UsageError(
        fmt::format("--gap-count {} x --gap-seconds {} does not fit in --duration {} s: each gap needs a slot of "
                    "duration / count longer than the gap plus two sample periods",
                    gap_count, gap_s, duration));
  }

  const std::vector<int64_t> nominal = model.NominalStamps();
  const int64_t start = options.start_stamp_ns;
  // Gaps as [begin, end) offsets in ns from the start, one per slot.
  std::vector<std::pair<int64_t, int64_t>> gaps;
  Random gap_random(options.seed, kGaps);
  for (int k = 0; k < gap_count; ++k) {
    const double begin = k * slot + margin + gap_random.Uniform() * (slot - gap_s - 2.0 * margin);
    gaps.emplace_back(std::llround(begin * 1e9), std::llround((begin + gap_s) * 1e9));
  }
  Random dropout_random(options.seed, kDropout), jitter_random(options.seed, kJitter),
      noise_random(options.seed, kNoise), rotation_random(options.seed, kRotationNoise);

  struct Sample {
    int64_t stamp;
    Eigen::Vector3d noise;
    Eigen::Vector3d rotation_noise;
  };
  std::vector<Sample> kept;
  kept.reserve(nominal.size());
  size_t gap = 0;
  for (const int64_t stamp : nominal) {
    // Every stream draws for every nominal sample, so each effect is independent of the others.
    const bool dropped = dropout_random.Uniform() < dropout;
    const double offset_s = jitter_random.Normal() * jitter;
    const Eigen::Vector3d n(noise_random.Normal(), noise_random.Normal(), noise_random.Normal());
    const Eigen::Vector3d r(rotation_random.Normal(), rotation_random.Normal(), rotation_random.Normal());
    const int64_t offset = stamp - start;
    while (gap < gaps.size() && offset >= gaps[gap].second) ++gap;
    const bool in_gap = gap < gaps.size() && offset >= gaps[gap].first;
    if (dropped || in_gap) continue;
    kept.push_back({stamp + static_cast<int64_t>(std::llround(offset_s * 1e9)), noise * n, rotation_noise * r});
  }
  if (kept.size() < 2) {
    throw UsageError(fmt::format("--dropout {} and the gaps leave {} of {} samples; at least 2 are needed", dropout,
                                 kept.size(), nominal.size()));
  }
  // Jittered stamps: sorted, then each one not above its predecessor moved to predecessor + 1 ns.
  std::stable_sort(kept.begin(), kept.end(), [](const Sample& a, const Sample& b) { return a.stamp < b.stamp; });
  std::vector<int64_t> stamps(kept.size());
  for (size_t i = 0; i < kept.size(); ++i) {
    if (i > 0 && kept[i].stamp <= kept[i - 1].stamp) kept[i].stamp = kept[i - 1].stamp + 1;
    stamps[i] = kept[i].stamp;
  }

  const traj::Trajectory truth = SampleMotion(model, stamps);
  traj::Trajectory measured(traj::Channels{traj::OrientationKind::kQuaternion, false, false, true});
  measured.Reserve(truth.size());
  const auto quaternions = truth.View().quaternions();
  for (Eigen::Index i = 0; i < truth.size(); ++i) {
    const Eigen::Vector3d p = truth.positions().col(i) + kept[static_cast<size_t>(i)].noise;
    Eigen::Vector4d q = quaternions.col(i);
    const Eigen::Vector3d& r = kept[static_cast<size_t>(i)].rotation_noise;
    if (rotation_noise > 0) {
      const double angle = r.norm();
      const Eigen::Quaterniond perturbed =
          Eigen::Quaterniond(q[3], q[0], q[1], q[2]) *
          Eigen::Quaterniond(Eigen::AngleAxisd(angle, angle > 0 ? Eigen::Vector3d(r / angle) : Eigen::Vector3d::UnitX()));
      q << perturbed.x(), perturbed.y(), perturbed.z(), perturbed.w();
    }
    measured.Append(stamps[static_cast<size_t>(i)], p.data(), q.data());
  }
  return measured;
}

traj::Trajectory SimulateEstimate(const MotionModel& model, const EstimatorSimOptions& options) {
  const MotionOptions& motion = model.options();
  const double duration = *motion.duration_s;
  auto require_non_negative = [](double value, const char* what) {
    if (!(value >= 0) || !std::isfinite(value)) {
      throw UsageError(fmt::format("{} must be a non-negative finite number, got {}", what, value));
    }
  };
  if (!(options.rate_hz > 0) || !std::isfinite(options.rate_hz)) {
    throw UsageError(fmt::format("--estimate-rate must be a positive number of Hz, got {}", options.rate_hz));
  }
  require_non_negative(options.velocity_random_walk, "--estimate-drift");
  require_non_negative(options.rotation_random_walk_rad, "--estimate-rotation-drift");
  require_non_negative(options.position_noise_m, "the estimate's position noise");
  require_non_negative(options.velocity_noise_mps, "the estimate's velocity noise");
  if (!(options.delay_s >= 0) || !(options.delay_s < duration)) {
    throw UsageError(fmt::format("the estimate's delay must be in [0, {}) s, got {}", duration, options.delay_s));
  }
  const double span = duration - options.delay_s;
  const int64_t count = static_cast<int64_t>(std::floor(span * options.rate_hz)) + 1;
  if (count < 2 || count > 100'000'000) {
    throw UsageError(fmt::format("--estimate-rate {} Hz over {} s gives {} poses; 2 to 1e8 are needed",
                                 options.rate_hz, span, count));
  }
  std::vector<int64_t> stamps(static_cast<size_t>(count));
  const int64_t first = motion.start_stamp_ns + std::llround(options.delay_s * 1e9);
  for (int64_t i = 0; i < count; ++i) {
    stamps[static_cast<size_t>(i)] = first + std::llround(static_cast<double>(i) * 1e9 / options.rate_hz);
  }
  const traj::Trajectory truth = SampleMotion(model, stamps);
  // One stream per estimate, after the streams of the measured copy.
  Random random(motion.seed, kEstimate + 0x100 * options.stream);
  auto normal3 = [&random] { return Eigen::Vector3d(random.Normal(), random.Normal(), random.Normal()); };

  traj::Trajectory estimate(traj::Channels{traj::OrientationKind::kQuaternion, true, false, true});
  estimate.Reserve(truth.size());
  const auto quaternions = truth.View().quaternions();
  const auto velocities = truth.View().velocities();
  Eigen::Vector3d velocity_error = Eigen::Vector3d::Zero(), position_drift = Eigen::Vector3d::Zero(),
                  rotation_error = Eigen::Vector3d::Zero();
  for (Eigen::Index i = 0; i < truth.size(); ++i) {
    if (i > 0) {
      const double dt = static_cast<double>(stamps[static_cast<size_t>(i)] - stamps[static_cast<size_t>(i - 1)]) * 1e-9;
      position_drift += velocity_error * dt;  // the drift is the integral of the velocity error
      velocity_error += options.velocity_random_walk * std::sqrt(dt) * normal3();
      rotation_error += options.rotation_random_walk_rad * std::sqrt(dt) * normal3();
    }
    const Eigen::Vector3d p = truth.positions().col(i) + position_drift + options.position_noise_m * normal3();
    const Eigen::Vector3d v = velocities.col(i) + velocity_error + options.velocity_noise_mps * normal3();
    const Eigen::Vector4d q_truth = quaternions.col(i);
    const double angle = rotation_error.norm();
    const Eigen::Quaterniond q =
        Eigen::Quaterniond(q_truth[3], q_truth[0], q_truth[1], q_truth[2]) *
        Eigen::Quaterniond(Eigen::AngleAxisd(angle, angle > 0 ? Eigen::Vector3d(rotation_error / angle)
                                                              : Eigen::Vector3d::UnitX()));
    const double xyzw[4] = {q.x(), q.y(), q.z(), q.w()};
    estimate.Append(stamps[static_cast<size_t>(i)], p.data(), xyzw, v.data());
  }
  return estimate;
}

traj::Trajectory AddPositionNoise(const traj::TrajectoryView& truth, double sigma_m, uint64_t seed) {
  if (!(sigma_m >= 0) || !std::isfinite(sigma_m)) {
    throw UsageError(fmt::format("--noise must be a non-negative number of metres, got {}", sigma_m));
  }
  traj::Channels channels = truth.channels();
  channels.velocity = false;
  channels.angular_velocity = false;
  traj::Trajectory measured(channels);
  measured.Reserve(truth.size());
  Random random(seed, kAddNoise);
  const auto p = truth.positions();
  const int stride = traj::OrientationStride(channels.orientation);
  std::vector<double> orientation(static_cast<size_t>(std::max(stride, 1)));
  for (Eigen::Index i = 0; i < truth.size(); ++i) {
    const Eigen::Vector3d noisy =
        p.col(i) + sigma_m * Eigen::Vector3d(random.Normal(), random.Normal(), random.Normal());
    if (channels.orientation == traj::OrientationKind::kQuaternion) {
      const Eigen::Vector4d q = truth.quaternions().col(i);
      std::copy(q.data(), q.data() + 4, orientation.begin());
    } else if (channels.orientation == traj::OrientationKind::kMatrix) {
      const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> R = truth.Rotation(i);
      std::copy(R.data(), R.data() + 9, orientation.begin());
    }
    measured.Append(truth.stamps_ns()[i], noisy.data(), orientation.data());
  }
  return measured;
}

}  // namespace cheval::sim

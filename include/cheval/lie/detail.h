#pragma once
/// \file
/// Small helpers shared by the Lie groups of cheval::lie: the skew-symmetric matrix of a 3-vector
/// and the scalar coefficient functions of the exponential maps and their Jacobians.
///
/// Every coefficient below is an even function of the rotation angle θ and is evaluated from θ²:
/// by its closed form when θ² is above a threshold and by its Taylor series below it. The series
/// keeps both the values and their derivatives (for ceres::Jet) finite and correct at θ = 0, where
/// the closed forms are 0/0. Each threshold and number of terms is chosen so that the truncation
/// error of the series is below 1e-17 relative; the closed forms just above a threshold lose at
/// most three digits to cancellation, and those coefficients enter the group operations multiplied
/// by θ² or more, so the absolute effect stays at the 1e-15 level. Not part of the stable API.

#include <array>
#include <cmath>
#include <cstddef>

#include <Eigen/Core>

namespace cheval::lie::detail {

template <typename Scalar>
using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
template <typename Scalar>
using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;

/// Skew-symmetric matrix [w]× such that [w]× v = w × v.
template <typename Scalar>
Matrix3<Scalar> Hat3(const Vector3<Scalar>& w) {
  Matrix3<Scalar> m;
  m << Scalar(0), -w.z(), w.y(),  //
      w.z(), Scalar(0), -w.x(),   //
      -w.y(), w.x(), Scalar(0);
  return m;
}

/// Inverse of Hat3: the vector of the skew-symmetric part (m − mᵀ)/2 of a 3x3 matrix.
template <typename Scalar, typename Derived>
Vector3<Scalar> Vee3(const Eigen::MatrixBase<Derived>& m) {
  return Vector3<Scalar>(Scalar(0.5) * (m(2, 1) - m(1, 2)), Scalar(0.5) * (m(0, 2) - m(2, 0)),
                         Scalar(0.5) * (m(1, 0) - m(0, 1)));
}

/// n! as a double (exact up to 22!).
constexpr double Factorial(int n) { return n <= 1 ? 1.0 : n * Factorial(n - 1); }

/// Horner evaluation of c[0] + c[1] x + c[2] x² + ...
template <typename Scalar, std::size_t N>
Scalar Polynomial(const Scalar& x, const std::array<double, N>& c) {
  Scalar sum(c[N - 1]);
  for (std::size_t i = N - 1; i-- > 0;) sum = sum * x + Scalar(c[i]);
  return sum;
}

/// Coefficients c[k] = sign^k · scale / (factor^k · (2k + offset)!) of a series in θ², the shape of
/// every Taylor series below.
template <std::size_t N>
constexpr std::array<double, N> FactorialSeries(int offset, double sign = -1.0, double factor = 1.0,
                                                double scale = 1.0) {
  std::array<double, N> c{};
  double power = 1.0;
  for (std::size_t k = 0; k < N; ++k) {
    c[k] = scale * power / Factorial(2 * static_cast<int>(k) + offset);
    power *= sign / factor;
  }
  return c;
}

/// Below this θ² the SO(3)/SE(3)/SE_2(3) coefficients use their series. With five terms
/// (up to θ⁸) the first omitted term is at most θ¹⁰/12! ≈ 2e-19 at θ² = 1e-2 (the one of A).
inline constexpr double kSeriesAngleSq = 1e-2;

/// cos(θ/2) and sin(θ/2)/θ, the scalar and vector factors of the unit quaternion of Exp(ω).
template <typename Scalar>
struct HalfAngle {
  Scalar cos_half;        ///< cos(θ/2)
  Scalar sin_half_by_th;  ///< sin(θ/2)/θ, → 1/2 as θ → 0
};

template <typename Scalar>
HalfAngle<Scalar> ComputeHalfAngle(const Scalar& theta_sq) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  // cos(θ/2) = Σ (−1)^k θ^2k / (4^k (2k)!),   sin(θ/2)/θ = Σ (−1)^k θ^2k / (2 · 4^k (2k+1)!).
  static constexpr auto kCos = FactorialSeries<5>(0, -1.0, 4.0);
  static constexpr auto kSinc = FactorialSeries<5>(1, -1.0, 4.0, 0.5);
  if (theta_sq < Scalar(kSeriesAngleSq)) {
    return {Polynomial(theta_sq, kCos), Polynomial(theta_sq, kSinc)};
  }
  const Scalar theta = sqrt(theta_sq);
  const Scalar half = Scalar(0.5) * theta;
  return {cos(half), sin(half) / theta};
}

/// The coefficients of the SO(3) Jacobians J_l = I + A[ω]× + B[ω]×² and J_r = I − A[ω]× + B[ω]×²
/// (J_l is also the matrix V of the SE(3) exponential).
template <typename Scalar>
struct RotationCoefficients {
  Scalar a;  ///< A = (1 − cos θ)/θ²  → 1/2
  Scalar b;  ///< B = (θ − sin θ)/θ³  → 1/6
};

template <typename Scalar>
RotationCoefficients<Scalar> ComputeRotationCoefficients(const Scalar& theta_sq) {
  using std::sin;
  using std::sqrt;
  // A = Σ (−1)^k θ^2k/(2k+2)!,  B = Σ (−1)^k θ^2k/(2k+3)!.
  static constexpr auto kA = FactorialSeries<5>(2);
  static constexpr auto kB = FactorialSeries<5>(3);
  if (theta_sq < Scalar(kSeriesAngleSq)) {
    return {Polynomial(theta_sq, kA), Polynomial(theta_sq, kB)};
  }
  const Scalar theta = sqrt(theta_sq);
  const Scalar sin_half = sin(Scalar(0.5) * theta);
  // 1 − cos θ = 2 sin²(θ/2) avoids the cancellation of 1 − cos θ; θ − sin θ loses
  // log10(6/θ²) ≤ 3 digits at the threshold.
  return {Scalar(2) * sin_half * sin_half / theta_sq, (theta - sin(theta)) / (theta_sq * theta)};
}

/// Below this θ² the coefficients C2, C3 of Barfoot's Q use their series (nine terms; the first
/// omitted terms are 1/22! and 10/23!, below 1e-21). Their closed forms cancel a factor ~θ⁴ (the
/// numerator of C3 is θ⁵/60 made of terms of size 2θ), so they are used only from θ² = 1 on, where
/// they keep 14 digits.
inline constexpr double kQSeriesAngleSq = 1.0;

/// The coefficients C2 = (θ² + 2 cos θ − 2)/(2θ⁴) → 1/24 and C3 = (2θ − 3 sin θ + θ cos θ)/(2θ⁵)
/// → 1/120 of Barfoot's Q block of the SE(3) Jacobian (its first coefficient is B above).
template <typename Scalar>
struct QCoefficients {
  Scalar c2;
  Scalar c3;
};

template <typename Scalar>
QCoefficients<Scalar> ComputeQCoefficients(const Scalar& theta_sq) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  // C2 = Σ (−1)^k θ^2k/(2k+4)!,  C3 = Σ (−1)^k (k+1) θ^2k/(2k+5)!.
  static constexpr auto kC2 = FactorialSeries<9>(4);
  static constexpr auto kC3 = [] {
    auto c = FactorialSeries<9>(5);
    for (std::size_t k = 0; k < c.size(); ++k) c[k] *= static_cast<double>(k + 1);
    return c;
  }();
  if (theta_sq < Scalar(kQSeriesAngleSq)) {
    return {Polynomial(theta_sq, kC2), Polynomial(theta_sq, kC3)};
  }
  const Scalar theta = sqrt(theta_sq);
  const Scalar cos_theta = cos(theta);
  const Scalar sin_theta = sin(theta);
  const Scalar theta_4 = theta_sq * theta_sq;
  return {(theta_sq + Scalar(2) * cos_theta - Scalar(2)) / (Scalar(2) * theta_4),
          (Scalar(2) * theta - Scalar(3) * sin_theta + theta * cos_theta) /
              (Scalar(2) * theta_4 * theta)};
}

/// Barfoot's Q(ρ, φ) ("State Estimation for Robotics", 2017, eq. 7.86b): the lower-left block of
/// the SE(3) left Jacobian [[J_l(φ), 0], [Q, J_l(φ)]] in cheval's (rotation, translation) tangent
/// order. Arguments are given rotation first:
///   Q = ½ρ^ + B (φ^ρ^ + ρ^φ^ + φ^ρ^φ^) + C2 (φ^φ^ρ^ + ρ^φ^φ^ − 3 φ^ρ^φ^)
///       + C3 (φ^ρ^φ^φ^ + φ^φ^ρ^φ^),   with ^ = Hat3.
template <typename Scalar>
Matrix3<Scalar> BarfootQ(const Vector3<Scalar>& phi, const Vector3<Scalar>& rho) {
  const Scalar theta_sq = phi.squaredNorm();
  const RotationCoefficients<Scalar> r = ComputeRotationCoefficients(theta_sq);
  const QCoefficients<Scalar> q = ComputeQCoefficients(theta_sq);
  const Matrix3<Scalar> p_hat = Hat3(phi);
  const Matrix3<Scalar> r_hat = Hat3(rho);
  const Matrix3<Scalar> pr = p_hat * r_hat;
  const Matrix3<Scalar> rp = r_hat * p_hat;
  const Matrix3<Scalar> prp = pr * p_hat;
  return Scalar(0.5) * r_hat + r.b * (pr + rp + prp) +
         q.c2 * (p_hat * pr + rp * p_hat - Scalar(3) * prp) + q.c3 * (prp * p_hat + p_hat * prp);
}

/// D = 1/θ² − cos(θ/2) / (2θ sin(θ/2)), the [ω]×² coefficient of the inverse SO(3) Jacobians.
/// Finite for 0 ≤ θ < 2π (it has a pole at 2π); Log returns θ ≤ π.
template <typename Scalar>
Scalar ComputeInverseJacobianCoefficient(const Scalar& theta_sq) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  // From the Laurent series of cot: D = Σ_{n≥1} (−1)^(n+1) B_2n θ^(2n−2)/(2n)!, with the Bernoulli
  // numbers B_2 = 1/6, B_4 = −1/30, B_6 = 1/42, B_8 = −1/30, B_10 = 5/66.
  static constexpr std::array<double, 5> kD = {1.0 / 12.0, 1.0 / 720.0, 1.0 / 30240.0,
                                               1.0 / 1209600.0, 1.0 / 47900160.0};
  if (theta_sq < Scalar(kSeriesAngleSq)) return Polynomial(theta_sq, kD);
  const Scalar theta = sqrt(theta_sq);
  const Scalar half = Scalar(0.5) * theta;
  // cos(θ/2)/sin(θ/2) rather than (1 + cos θ)/sin θ, which is 0/0 at θ = π.
  return Scalar(1) / theta_sq - cos(half) / (Scalar(2) * theta * sin(half));
}

/// Below this squared norm |v|² of the quaternion's vector part, SO3::Log uses the series of
/// atan(x)/x (x² = |v|²/w² ≤ 1.001e-3); six terms leave an error below x¹²/13 ≈ 1e-19.
inline constexpr double kLogSeriesSinSq = 1e-3;

/// θ/|v| for the unit quaternion (w, v) with w ≥ 0, where θ = 2 atan2(|v|, w) ∈ [0, π] is its
/// rotation angle, so that Log = (θ/|v|) v.
template <typename Scalar>
Scalar ComputeAngleOverSinHalf(const Scalar& w, const Scalar& v_sq) {
  using std::atan2;
  using std::sqrt;
  // atan(x)/x = Σ (−1)^k x^2k/(2k+1).
  static constexpr std::array<double, 6> kAtan = {1.0,        -1.0 / 3.0, 1.0 / 5.0,
                                                  -1.0 / 7.0, 1.0 / 9.0,  -1.0 / 11.0};
  if (v_sq < Scalar(kLogSeriesSinSq)) {
    return Scalar(2) / w * Polynomial(v_sq / (w * w), kAtan);
  }
  const Scalar n = sqrt(v_sq);
  return Scalar(2) * atan2(n, w) / n;
}

/// Moments M_k(σ) = ∫₀¹ s^k e^(σs) ds for k = 0 … N−1 (M_0 = (e^σ − 1)/σ, dM_k/dσ = M_(k+1)).
/// For |σ| < 1 by the power series Σ_j σ^j / (j! (k+j+1)) (20 terms: remainder < 1/20! ≈ 4e-19);
/// otherwise by the recurrence M_k = (e^σ − k M_(k−1))/σ, whose error growth k!/|σ|^k is cancelled
/// by the 1/k! weights with which the moments enter the Sim(3) coefficients.
template <int N, typename Scalar>
std::array<Scalar, N> ComputeExpMoments(const Scalar& sigma) {
  using std::exp;
  std::array<Scalar, N> m;
  if (sigma * sigma < Scalar(1)) {
    constexpr int kTerms = 20;
    std::array<Scalar, kTerms> power;  // σ^j / j!
    power[0] = Scalar(1);
    for (int j = 1; j < kTerms; ++j) power[j] = power[j - 1] * sigma / Scalar(j);
    for (int k = 0; k < N; ++k) {
      Scalar sum(0);
      for (int j = kTerms; j-- > 0;) sum += power[j] / Scalar(k + j + 1);  // smallest first
      m[k] = sum;
    }
    return m;
  }
  const Scalar e = exp(sigma);
  m[0] = (e - Scalar(1)) / sigma;
  for (int k = 1; k < N; ++k) m[k] = (e - Scalar(k) * m[k - 1]) / sigma;
  return m;
}

/// Below this θ² the Sim(3) coefficients use their series in θ²; nine terms leave an error below
/// θ¹⁸/19! ≈ 4e-23 at θ² = 0.25. Above it the closed forms divide by θ² ≥ 0.25 only.
inline constexpr double kSim3SeriesAngleSq = 0.25;

/// The coefficients of W(ω, σ) = a0 I + a1 [ω]× + a2 [ω]×² = ∫₀¹ e^(sσ) Exp(sω) ds, the matrix with
/// t = W ρ in the Sim(3) exponential, and their partial derivatives with respect to σ and to
/// θ² = |ω|². With F(z) = (e^z − 1)/z and z = σ + iθ:
///   a0 = F(σ),   a1 = Im F(z)/θ,   a2 = (F(σ) − Re F(z))/θ².
template <typename Scalar>
struct Sim3Coefficients {
  Scalar a0, a1, a2;                          ///< W = a0 I + a1 [ω]× + a2 [ω]×²
  Scalar da0_dsigma, da1_dsigma, da2_dsigma;  ///< ∂/∂σ
  Scalar da1_dtheta_sq, da2_dtheta_sq;        ///< ∂/∂(θ²); a0 does not depend on θ
};

template <typename Scalar>
Sim3Coefficients<Scalar> ComputeSim3Coefficients(const Scalar& theta_sq, const Scalar& sigma) {
  using std::cos;
  using std::exp;
  using std::sin;
  using std::sqrt;
  Sim3Coefficients<Scalar> c;
  if (theta_sq < Scalar(kSim3SeriesAngleSq)) {
    // Expanding sin(sθ) and 1 − cos(sθ) under the integral:
    //   a1 = Σ_m (−θ²)^m M_(2m+1)/(2m+1)!,   a2 = Σ_m (−θ²)^m M_(2m+2)/(2m+2)!,
    // and ∂/∂σ raises every moment index by one (dM_k/dσ = M_(k+1)).
    constexpr int kTerms = 9;
    const std::array<Scalar, 2 * kTerms + 2> m = ComputeExpMoments<2 * kTerms + 2>(sigma);
    c.a0 = m[0];
    c.da0_dsigma = m[1];
    c.a1 = c.a2 = c.da1_dsigma = c.da2_dsigma = c.da1_dtheta_sq = c.da2_dtheta_sq = Scalar(0);
    Scalar power(1);  // (−θ²)^i
    for (int i = 0; i < kTerms; ++i) {
      const Scalar f1(Factorial(2 * i + 1));
      const Scalar f2(Factorial(2 * i + 2));
      c.a1 += power * m[2 * i + 1] / f1;
      c.a2 += power * m[2 * i + 2] / f2;
      c.da1_dsigma += power * m[2 * i + 2] / f1;
      c.da2_dsigma += power * m[2 * i + 3] / f2;
      if (i + 1 < kTerms) {
        // d/dθ² (−θ²)^(i+1) = −(i+1) (−θ²)^i.
        const Scalar weight = -Scalar(i + 1) * power;
        c.da1_dtheta_sq += weight * m[2 * i + 3] / Scalar(Factorial(2 * i + 3));
        c.da2_dtheta_sq += weight * m[2 * i + 4] / Scalar(Factorial(2 * i + 4));
      }
      power *= -theta_sq;
    }
    return c;
  }
  const Scalar theta = sqrt(theta_sq);
  const Scalar e = exp(sigma);
  const Scalar e_cos = e * cos(theta);
  const Scalar e_sin = e * sin(theta);
  const Scalar denom = sigma * sigma + theta_sq;  // |z|²
  // F(z) = (e^z − 1)/z and F'(z) = (e^z − F(z))/z, split into real and imaginary parts.
  const Scalar re_f = ((e_cos - Scalar(1)) * sigma + e_sin * theta) / denom;
  const Scalar im_f = (e_sin * sigma - (e_cos - Scalar(1)) * theta) / denom;
  const Scalar re_df = ((e_cos - re_f) * sigma + (e_sin - im_f) * theta) / denom;
  const Scalar im_df = ((e_sin - im_f) * sigma - (e_cos - re_f) * theta) / denom;
  const std::array<Scalar, 2> m = ComputeExpMoments<2>(sigma);  // F(σ), F'(σ)
  c.a0 = m[0];
  c.da0_dsigma = m[1];
  c.a1 = im_f / theta;
  c.a2 = (m[0] - re_f) / theta_sq;
  c.da1_dsigma = im_df / theta;
  c.da2_dsigma = (m[1] - re_df) / theta_sq;
  // ∂/∂θ F(σ + iθ) = i F'(z); ∂/∂θ² = (1/2θ) ∂/∂θ.
  c.da1_dtheta_sq = (re_df - c.a1) / (Scalar(2) * theta_sq);
  c.da2_dtheta_sq = (im_df / theta - Scalar(2) * c.a2) / (Scalar(2) * theta_sq);
  return c;
}

}  // namespace cheval::lie::detail

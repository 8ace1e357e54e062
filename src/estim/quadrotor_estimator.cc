#include "cheval/estim/quadrotor_estimator.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include "cheval/cheb/chebyshev.h"
#include "cheval/common/error.h"
#include "cheval/estim/problem.h"
#include "cheval/estim/thrust_vector_prior.h"
#include "cheval/lie/so3.h"

namespace cheval::estim {
namespace {

using Problem = PseudoSpectralProblem<QuadrotorModel>;

// Pixel residuals of the landmarks of one frame, whitened by the pixel σ.
struct FrameProjection {
  Eigen::Matrix3d camera_from_body;
  double fx, fy, cx, cy, inv_sigma;
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;

  template <typename T>
  bool operator()(const T* x, const Eigen::Matrix<T, 3, 3>& R, T* r) const {
    const Eigen::Matrix<T, 3, 1> p(x[0], x[1], x[2]);
    const Eigen::Matrix<T, 3, 3> C = camera_from_body.cast<T>() * R.transpose();
    for (size_t i = 0; i < points.size(); ++i) {
      const Eigen::Matrix<T, 3, 1> c = C * (points[i].cast<T>() - p);
      if (c.z() < T(1e-3)) return false;  // behind the camera: Ceres rejects the step
      r[2 * i] = (T(fx) * c.x() / c.z() + T(cx) - T(pixels[i].x())) * T(inv_sigma);
      r[2 * i + 1] = (T(fy) * c.y() / c.z() + T(cy) - T(pixels[i].y())) * T(inv_sigma);
    }
    return true;
  }
};

// The front end's pose at t, interpolated (linear / slerp) between its samples.
struct InitialTrajectory {
  const std::vector<PoseSample>& poses;
  PoseSample At(double t) const {
    auto it = std::lower_bound(poses.begin(), poses.end(), t, [](const PoseSample& s, double v) { return s.t < v; });
    if (it == poses.begin()) return poses.front();
    if (it == poses.end()) return poses.back();
    const PoseSample& b = *it;
    const PoseSample& a = *(it - 1);
    const double f = b.t > a.t ? (t - a.t) / (b.t - a.t) : 0.0;
    return {t, a.p + f * (b.p - a.p), a.q.slerp(f, b.q)};
  }
};

}  // namespace

QuadrotorStateEstimate FlatnessInitialState(const QuadrotorParameters& q, const std::vector<PoseSample>& poses,
                                            double t, double window_s) {
  if (poses.size() < 3) throw ComputeError("the flatness-based initialisation needs at least 3 poses");
  if (!(window_s > 0)) throw UsageError(fmt::format("the initialisation window must be > 0 s, got {}", window_s));
  const double first = poses.front().t, last = poses.back().t;
  const double half = 0.5 * window_s;
  const double center = last - first <= window_s ? 0.5 * (first + last) : std::clamp(t, first + half, last - half);
  auto lo = std::lower_bound(poses.begin(), poses.end(), center - half - 1e-9,
                             [](const PoseSample& s, double v) { return s.t < v; });
  auto hi = std::upper_bound(poses.begin(), poses.end(), center + half + 1e-9,
                             [](double v, const PoseSample& s) { return v < s.t; });
  while (hi - lo < 3) {  // a window with too few poses: widen it by one pose on each side
    if (lo != poses.begin()) --lo;
    if (hi != poses.end()) ++hi;
  }
  const int n = static_cast<int>(hi - lo);
  const Eigen::Quaterniond q_t = InitialTrajectory{poses}.At(t).q;
  const lie::SO3d R_t(q_t);
  Eigen::MatrixXd A(n, 3), P(n, 3), Phi(n, 3);
  for (int i = 0; i < n; ++i) {
    const PoseSample& s = *(lo + i);
    const double tau = s.t - t;
    A.row(i) << 1.0, tau, tau * tau;
    P.row(i) = s.p.transpose();
    Phi.row(i) = lie::SO3d(s.q).Minus(R_t).transpose();
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
  const Eigen::MatrixXd c = qr.solve(P);                                     // p(t + τ) ≈ c0 + c1 τ + c2 τ²
  const Eigen::MatrixXd b = A.leftCols(2).colPivHouseholderQr().solve(Phi);  // φ(t + τ) ≈ b0 + b1 τ
  QuadrotorStateEstimate out;
  out.t = t;
  out.p = c.row(0).transpose();
  out.v = c.row(1).transpose();
  out.w = b.row(1).transpose();
  out.R = q_t.toRotationMatrix();
  const Eigen::Vector3d a = 2.0 * c.row(2).transpose();
  const Eigen::Vector3d force =
      q.mass_kg * (a + Eigen::Vector3d(0, 0, q.gravity_mps2)) + q.drag_coefficient * out.v.norm() * out.v;
  const double thrust = force.dot(out.R.col(2));
  const Eigen::Vector3d Jw = q.inertia_kgm2.cwiseProduct(out.w);
  const Eigen::Vector3d tau = out.w.cross(Jw);
  const double arm = q.arm_m, k = q.moment_coefficient / q.thrust_coefficient;
  Eigen::Matrix4d mix;  // [T, τx, τy, τz] = mix · f (the motor layout of models.h)
  mix << 1, 1, 1, 1,            //
      arm, arm, -arm, -arm,     //
      -arm, arm, arm, -arm,     //
      -k, k, -k, k;
  const Eigen::Vector4d f = mix.fullPivLu().solve(Eigen::Vector4d(thrust, tau.x(), tau.y(), tau.z()));
  for (int i = 0; i < 4; ++i) {
    out.rotor[i] = std::min(std::sqrt(std::max(f[i], 0.0) / q.thrust_coefficient), q.max_rotor_speed_radps);
  }
  return out;
}

std::vector<double> AdaptiveRotorPriorSigma(const std::vector<double>& energy, int degree, int controls) {
  if (degree < 1 || controls < 1) throw UsageError("the adaptive rotor prior needs degree >= 1 and controls >= 1");
  const int S = static_cast<int>(energy.size());
  std::vector<double> sigma(S);
  for (int s = 0; s < S; ++s) {
    double sum = 0;
    int pooled = 0;
    for (int n = std::max(s - 1, 0); n <= std::min(s + 1, S - 1); ++n, ++pooled) {
      if (!(energy[n] >= 0)) throw UsageError(fmt::format("segment {} has a negative rotor-rate energy", n));
      sum += energy[n];
    }
    sigma[s] = std::sqrt(sum / (static_cast<double>(pooled) * degree * controls));
  }
  return sigma;
}

namespace {

// Rows C_a V_a (axis a = x, y, z) of the velocities V_a of the given nodes (their velocity blocks):
// linear, so the Jacobian is constant. With C_a the Gauss–Legendre rows of (D + λ_a)² D over a
// segment, the squared sum is ∫_s |(D + λ_a)² v_a'|² dt exactly.
class VelocityRowsCost : public ceres::CostFunction {
 public:
  VelocityRowsCost(Problem& p, const std::vector<int>& nodes, std::array<Eigen::MatrixXd, 3> coefficients)
      : coefficients_(std::move(coefficients)) {
    for (int g : nodes) {
      blocks_.push_back(p.Vector(g) + 3);
      mutable_parameter_block_sizes()->push_back(3);
    }
    set_num_residuals(3 * static_cast<int>(coefficients_[0].rows()));
  }
  const std::vector<double*>& blocks() const { return blocks_; }
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const int rows = static_cast<int>(coefficients_[0].rows()), n = static_cast<int>(blocks_.size());
    for (int a = 0; a < 3; ++a) {
      for (int q = 0; q < rows; ++q) {
        double r = 0;
        for (int k = 0; k < n; ++k) r += coefficients_[a](q, k) * parameters[k][a];
        residuals[a * rows + q] = r;
      }
    }
    if (jacobians) {
      for (int k = 0; k < n; ++k) {
        if (!jacobians[k]) continue;
        Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>> J(jacobians[k], 3 * rows, 3);
        J.setZero();
        for (int a = 0; a < 3; ++a) {
          for (int q = 0; q < rows; ++q) J(a * rows + q, a) = coefficients_[a](q, k);
        }
      }
    }
    return true;
  }

 private:
  std::array<Eigen::MatrixXd, 3> coefficients_;
  std::vector<double*> blocks_;
};

// The parts a Matérn prior of order m (2: Matérn-3/2, 3: Matérn-5/2) takes from the pilot, per world
// axis a, for a quantity x(t) known at the nodes of each segment (X_s, N + 1 x 3) through the
// Gauss–Legendre rows q_s[j] of its j-th derivative (j = 0..m; |q_s[j] X_s|² = ∫_s |x^(j)|² dt):
// λ_a matched to the root-mean-square frequency ν = sqrt(−∫x''x / ∫x²) of the pilot's x_a (a
// Matérn-3/2 process has ν = λ, a Matérn-5/2 one ν = λ/√3; at most max_rate), the rows of
// (D + λ_a)^m over each segment, and σ_s, the maximum-likelihood intensity of segment s (3 axes of
// N + 1 − m increments).
struct MaternParts {
  Eigen::Vector3d lambda;
  std::vector<std::array<Eigen::MatrixXd, 3>> rows;  // per segment and axis
  std::vector<double> sigma;                         // per segment
};

MaternParts FitMaternParts(const std::vector<std::array<Eigen::MatrixXd, 4>>& q, const std::vector<Eigen::MatrixXd>& X,
                           int m, int N, double max_rate) {
  const int S = static_cast<int>(X.size());
  Eigen::Vector3d num = Eigen::Vector3d::Zero(), den = Eigen::Vector3d::Zero();
  for (int s = 0; s < S; ++s) {
    const Eigen::MatrixXd A0 = q[s][0] * X[s], A2 = q[s][2] * X[s];
    for (int a = 0; a < 3; ++a) {
      num[a] -= A2.col(a).dot(A0.col(a));  // ∫ x'' x = −∫ |x'|² + ends
      den[a] += A0.col(a).squaredNorm();
    }
  }
  MaternParts parts;
  const double rms_to_lambda = m == 3 ? std::sqrt(3.0) : 1.0;
  for (int a = 0; a < 3; ++a) {
    parts.lambda[a] =
        rms_to_lambda * std::sqrt(std::clamp(den[a] > 0 ? num[a] / den[a] : 0.0, 0.0, max_rate * max_rate));
  }
  const double binomial[4][4] = {{1, 0, 0, 0}, {1, 1, 0, 0}, {1, 2, 1, 0}, {1, 3, 3, 1}};
  parts.rows.resize(S);
  parts.sigma.resize(S);
  for (int s = 0; s < S; ++s) {
    double e = 0;
    for (int a = 0; a < 3; ++a) {
      parts.rows[s][a] = Eigen::MatrixXd::Zero(N + 1, N + 1);
      for (int j = 0; j <= m; ++j) parts.rows[s][a] += binomial[m][j] * std::pow(parts.lambda[a], m - j) * q[s][j];
      e += (parts.rows[s][a] * X[s].col(a)).squaredNorm();
    }
    parts.sigma[s] = std::max(std::sqrt(e / (3.0 * (N + 1 - m))), 1e-9);
  }
  return parts;
}

// W with |W y|² = yᵀ P⁻¹ y for the stationary covariance P of the process's first state
// y = (x, x', .., x^(m−1)): with the energy of (D + λ)^m x, the exact density of the stationary
// process. From the spectrum σ² / (λ² + ω²)^m: m = 2: P = diag(1/(4λ³), 1/(4λ)) σ²; m = 3:
// P = [[3, 0, −λ²], [0, λ², 0], [−λ², 0, 3λ⁴]] σ² / (16λ⁵).
Eigen::MatrixXd StationaryStartWhitening(int m, double lambda, double sigma) {
  const double l = lambda;
  Eigen::MatrixXd cov(m, m);
  if (m == 2) {
    cov << 1 / (4 * l * l * l), 0, 0, 1 / (4 * l);
  } else {
    cov << 3, 0, -l * l, 0, l * l, 0, -l * l, 0, 3 * l * l * l * l;
    cov /= 16 * std::pow(l, 5);
  }
  cov *= sigma * sigma;
  const Eigen::MatrixXd info = cov.inverse();
  return Eigen::LLT<Eigen::MatrixXd>(info).matrixL().transpose();
}

// The kinematic acceleration's prior (QuadrotorEstimateOptions::motion_prior): per world axis a, a
// Matérn-3/2 process on v_a', ∫ |(D + λ_a)² v_a'|² dt / σ_s² per segment, λ_a and σ_s from the
// pilot as in AddThrustAccelerationPrior, v' and v'' continuous at the breakpoints and the
// stationary law of (v', v'') at the first time. The collective rotor speed then follows from
// the collocation of v' = f − g − drag.
std::vector<ceres::ResidualBlockId> AddMotionPrior(Problem& problem, const QuadrotorEstimateOptions& options) {
  std::vector<ceres::ResidualBlockId> ids;
  const int S = problem.num_segments(), N = options.degree;
  const int m = options.thrust_prior_order;  // 2: Matérn-3/2 on v', 3: Matérn-5/2
  std::vector<Eigen::MatrixXd> V(S);
  std::vector<std::array<Eigen::MatrixXd, 4>> Q(S);  // GL rows of v', v'', ... (the velocity's 1st .. (m+1)-th derivatives)
  for (int s = 0; s < S; ++s) {
    V[s].resize(N + 1, 3);
    for (int k = 0; k <= N; ++k) {
      V[s].row(k) = Eigen::Map<const Eigen::Vector3d>(problem.Vector(problem.NodeOf(s, k)) + 3).transpose();
    }
    for (int j = 0; j <= m; ++j) Q[s][j] = problem.SmoothnessMatrix(j + 1, s, N + 1);
  }
  const MaternParts parts = FitMaternParts(Q, V, m, N, options.thrust_prior_max_rate);
  const std::vector<std::array<Eigen::MatrixXd, 3>>& rows = parts.rows;
  const std::vector<double>& sigma_f = parts.sigma;
  for (int s = 0; s < S; ++s) {
    std::vector<int> nodes;
    for (int k = 0; k <= N; ++k) nodes.push_back(problem.NodeOf(s, k));
    std::array<Eigen::MatrixXd, 3> r;
    for (int a = 0; a < 3; ++a) r[a] = rows[s][a] / sigma_f[s];
    auto* cost = new VelocityRowsCost(problem, nodes, r);
    ids.push_back(problem.ceres_problem().AddResidualBlock(cost, nullptr, cost->blocks()));
  }
  for (int s = 0; s + 1 < S; ++s) {  // v' and v'' continuous at the inner breakpoints
    std::vector<int> nodes;
    for (int g = s * N; g <= (s + 2) * N; ++g) nodes.push_back(g);
    const Eigen::MatrixXd J = problem.SmoothnessJumpMatrix(m + 1, s, std::sqrt(sigma_f[s] * sigma_f[s + 1]));
    auto* cost = new VelocityRowsCost(problem, nodes, {J, J, J});
    ids.push_back(problem.ceres_problem().AddResidualBlock(cost, nullptr, cost->blocks()));
  }
  const detail::TimeRow row = problem.RowAt(problem.start_time());
  const Eigen::MatrixXd D = cheb::DifferentiationMatrix(N);
  const double scale = 2.0 / (problem.breakpoints()[1] - problem.breakpoints()[0]);
  Eigen::MatrixXd R0(m, N + 1);  // rows of v', v'', v''' at t0
  R0.row(0) = row.dw;
  for (int i = 1; i < m; ++i) R0.row(i) = scale * R0.row(i - 1) * D;
  std::array<Eigen::MatrixXd, 3> C;
  for (int a = 0; a < 3; ++a) C[a] = StationaryStartWhitening(m, parts.lambda[a], sigma_f[0]) * R0;
  std::vector<int> nodes;
  for (int k = 0; k <= N; ++k) nodes.push_back(problem.NodeOf(0, k));
  auto* cost = new VelocityRowsCost(problem, nodes, C);
  ids.push_back(problem.ceres_problem().AddResidualBlock(cost, nullptr, cost->blocks()));
  return ids;
}

// The collective rotor speed's prior after the pilot (QuadrotorEstimateOptions::thrust_prior,
// docs/estimator.md "Defaults"): per world axis a, a Matérn-3/2 process on the thrust acceleration
// a = (k_F ΣΩ²/m) R e3 − ḡ, ∫|(D + λ_a)² a_a|² dt / σ_s² per segment, with λ_a the pilot's
// root-mean-square frequency on that axis, σ_s the maximum-likelihood intensity of segment s, the
// rate of a continuous at the breakpoints and the stationary law of (a, a') at the first time.
std::vector<ceres::ResidualBlockId> AddThrustAccelerationPrior(Problem& problem, const Vehicle& vehicle,
                                                               const QuadrotorEstimateOptions& options) {
  std::vector<ceres::ResidualBlockId> ids;
  const int S = problem.num_segments(), N = options.degree;
  const double k_over_m = vehicle.quadrotor.thrust_coefficient / vehicle.quadrotor.mass_kg;
  const Eigen::Vector3d gbar(0, 0, vehicle.quadrotor.gravity_mps2);
  const int m = options.thrust_prior_order;  // 2: Matérn-3/2, (D + λ)² a; 3: Matérn-5/2, (D + λ)³ a
  std::vector<Eigen::MatrixXd> F(S);  // pilot's f − ḡ at the nodes
  std::vector<std::array<Eigen::MatrixXd, 4>> Q(S);  // GL rows of 1, D, D², D³
  for (int s = 0; s < S; ++s) {
    F[s].resize(N + 1, 3);
    for (int k = 0; k <= N; ++k) {
      const int g = problem.NodeOf(s, k);
      F[s].row(k) = (ThrustVectorSmoothnessCost::ThrustAcceleration(problem.Control(g), problem.Quaternion(g), k_over_m) -
                     gbar).transpose();
    }
    for (int j = 0; j <= m; ++j) Q[s][j] = problem.SmoothnessMatrix(j, s, N + 1);
  }
  const MaternParts parts = FitMaternParts(Q, F, m, N, options.thrust_prior_max_rate);
  const std::vector<std::array<Eigen::MatrixXd, 3>>& rows = parts.rows;
  const std::vector<double>& sigma_f = parts.sigma;
  // The rows act on f; the prior is on f − ḡ: offsets −λ^m ḡ_a (the constant's only surviving term).
  std::vector<Eigen::MatrixXd> offsets(S, Eigen::MatrixXd(N + 1, 3));
  for (int s = 0; s < S; ++s) {
    for (int a = 0; a < 3; ++a) offsets[s].col(a) = -std::pow(parts.lambda[a], m) * gbar[a] * Q[s][0].rowwise().sum();
  }
  for (int s = 0; s < S; ++s) {
    std::vector<int> nodes;
    for (int k = 0; k <= N; ++k) nodes.push_back(problem.NodeOf(s, k));
    auto* cost = new ThrustVectorSmoothnessCost(problem, nodes, rows[s], offsets[s], k_over_m);
    cost->set_weight(1.0 / sigma_f[s]);
    ids.push_back(problem.ceres_problem().AddResidualBlock(cost, nullptr, cost->blocks()));
  }
  // f' (and f'' for m = 3) continuous at the inner breakpoints (as AddControlSmoothnessPrior's jumps).
  for (int s = 0; s + 1 < S; ++s) {
    std::vector<int> nodes;
    for (int g = s * N; g <= (s + 2) * N; ++g) nodes.push_back(g);
    auto* cost = new ThrustVectorSmoothnessCost(problem, nodes, problem.SmoothnessJumpMatrix(m, s, 1.0), k_over_m);
    cost->set_weight(1.0 / std::sqrt(sigma_f[s] * sigma_f[s + 1]));
    ids.push_back(problem.ceres_problem().AddResidualBlock(cost, nullptr, cost->blocks()));
  }
  // The stationary law of the process's first state (a, a', .., a^(m−1)) at t0
  // (StationaryStartWhitening).
  const detail::TimeRow row = problem.RowAt(problem.start_time());
  Eigen::MatrixXd R0(m, N + 1);  // rows of a, a', a'' at t0 in the first segment's point order
  R0.row(0) = row.w;
  R0.row(1) = row.dw;
  if (m == 3) {
    const Eigen::MatrixXd D = cheb::DifferentiationMatrix(N);
    const double scale = 2.0 / (problem.breakpoints()[1] - problem.breakpoints()[0]);
    R0.row(2) = scale * row.dw * D;
  }
  std::array<Eigen::MatrixXd, 3> C;
  Eigen::MatrixXd o(m, 3);
  for (int a = 0; a < 3; ++a) {
    const Eigen::MatrixXd W = StationaryStartWhitening(m, parts.lambda[a], sigma_f[0]);
    C[a] = W * R0;
    o.col(a) = -W.col(0) * gbar[a];
  }
  std::vector<int> nodes;
  for (int k = 0; k <= N; ++k) nodes.push_back(problem.NodeOf(0, k));
  auto* cost = new ThrustVectorSmoothnessCost(problem, nodes, C, o, k_over_m);
  ids.push_back(problem.ceres_problem().AddResidualBlock(cost, nullptr, cost->blocks()));
  return ids;
}

}  // namespace

QuadrotorEstimate EstimateQuadrotor(const Vehicle& vehicle, const std::vector<Eigen::Vector3d>& landmarks,
                                    const std::vector<PixelObservation>& pixels,
                                    const std::vector<PoseSample>& initial, const QuadrotorEstimateOptions& options,
                                    const std::vector<double>& query_times) {
  const auto start = std::chrono::steady_clock::now();
  if (options.degree < 2 || options.degree > 64) throw UsageError(fmt::format("--degree must be in [2, 64], got {}", options.degree));
  if (!(options.segment_s > 0) || !std::isfinite(options.segment_s)) {
    throw UsageError(fmt::format("--segment must be a positive number of seconds, got {}", options.segment_s));
  }
  if (options.pilot_iterations < 1) {
    throw UsageError(fmt::format("the pilot solve needs >= 1 iteration, got {}", options.pilot_iterations));
  }
  if (!(options.adaptive_rotor_prior_floor > 0)) {
    throw UsageError(fmt::format("the adaptive rotor-prior floor must be > 0, got {}", options.adaptive_rotor_prior_floor));
  }
  if (!(options.initial_trust_region_radius > 0)) {
    throw UsageError(fmt::format("the initial trust-region radius must be > 0, got {}", options.initial_trust_region_radius));
  }
  if (options.thrust_prior_rounds < 1) {
    throw UsageError(fmt::format("the thrust prior needs >= 1 empirical-Bayes round, got {}", options.thrust_prior_rounds));
  }
  if (options.thrust_prior_order < 2 || options.thrust_prior_order > 3) {
    throw UsageError(fmt::format("the thrust prior's order must be 2 or 3, got {}", options.thrust_prior_order));
  }
  if (pixels.empty()) throw ComputeError("no camera measurements");
  double t0 = pixels.front().t, t1 = pixels.front().t;
  for (const PixelObservation& m : pixels) {
    t0 = std::min(t0, m.t);
    t1 = std::max(t1, m.t);
    if (m.landmark < 0 || m.landmark >= static_cast<int>(landmarks.size())) {
      throw ComputeError(fmt::format("measurement at {:.6f} s refers to landmark {}, but the map has {}", m.t, m.landmark,
                                     landmarks.size()));
    }
  }
  if (!(t1 > t0)) throw ComputeError("the camera measurements span no time (need frames at 2 or more times)");
  if (initial.empty() || initial.front().t > t0 + 1e-6 || initial.back().t < t1 - 1e-6) {
    throw ComputeError(fmt::format("the initial poses ({:.6f} .. {:.6f} s) do not cover the measurement interval "
                                   "[{:.6f}, {:.6f}] s",
                                   initial.empty() ? 0.0 : initial.front().t, initial.empty() ? 0.0 : initial.back().t,
                                   t0, t1));
  }
  const int segments = std::max(1, static_cast<int>(std::lround((t1 - t0) / options.segment_s)));
  std::vector<double> breakpoints(segments + 1);
  for (int s = 0; s <= segments; ++s) breakpoints[s] = t0 + (t1 - t0) * s / segments;
  breakpoints.back() = t1;
  Problem problem(QuadrotorModel{vehicle.quadrotor}, breakpoints, options.degree);

  // Initial values: the flatness-based fit of the front end's poses (FlatnessInitialState).
  for (int g = 0; g < problem.num_nodes(); ++g) {
    const QuadrotorStateEstimate x0 = FlatnessInitialState(vehicle.quadrotor, initial, problem.NodeTime(g),
                                                           options.initial_window_s);
    Eigen::VectorXd x(9);
    x << x0.p, x0.v, x0.w;
    problem.SetNode(g, x, x0.R, x0.rotor);
  }
  problem.SetChartReferences();

  Eigen::Matrix<double, 12, 1> sigma;
  sigma << Eigen::Vector3d::Constant(options.sigma_position_rate), Eigen::Vector3d::Constant(options.sigma_acceleration),
      Eigen::Vector3d::Constant(options.sigma_angular_acceleration), Eigen::Vector3d::Constant(options.sigma_rotation_rate);
  problem.AddCollocation(sigma);
  // The rotor prior on the collective and the roll, pitch and yaw combinations of the rotor speeds
  // (the mixer's rows, orthonormal): with one σ for all four it is the per-rotor prior.
  Eigen::Matrix4d rotor_basis;
  rotor_basis << 1, 1, -1, -1,  //
      1, 1, 1, 1,               //
      1, -1, 1, -1,             //
      1, -1, -1, 1;
  rotor_basis *= 0.5;  // columns: collective, roll, pitch, yaw
  if (options.sigma_rotor_rate > 0) {
    problem.AddControlSmoothnessPrior(options.rotor_prior_order, options.sigma_rotor_rate, rotor_basis);
  }

  const PinholeCamera& cam = vehicle.camera;
  const double pixel_sigma = std::max(cam.pixel_noise_px, 0.1);  // a noise-free file still gets a finite weight
  ceres::HuberLoss huber(options.huber_pixels);
  for (size_t i = 0; i < pixels.size();) {
    FrameProjection frame{PinholeCamera::BodyFromCamera().transpose(), cam.fx, cam.fy, cam.cx, cam.cy, 1.0 / pixel_sigma,
                          {}, {}};
    size_t j = i;
    for (; j < pixels.size() && pixels[j].t == pixels[i].t; ++j) {
      frame.points.push_back(landmarks[pixels[j].landmark]);
      frame.pixels.push_back(pixels[j].uv);
    }
    const int rows = static_cast<int>(2 * (j - i));
    problem.AddMeasurement(pixels[i].t, std::move(frame), rows, 2, {0}, &huber);
    i = j;
  }

  // Progress after every iteration of every solve (the pilot's and the final one's).
  class IterationProgress : public ceres::IterationCallback {
   public:
    explicit IterationProgress(const ProgressFn& progress) : progress_(progress) {}
    ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
      if (summary.iteration > 0) ReportProgress(progress_, "solver iterations", ++done_, 0);
      return ceres::SOLVER_CONTINUE;
    }

   private:
    const ProgressFn& progress_;
    int64_t done_ = 0;
  } iteration_progress(options.progress);
  ceres::Solver::Options solver;
  if (options.progress) solver.callbacks.push_back(&iteration_progress);
  solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver.max_num_iterations = options.max_iterations;
  solver.num_threads = options.threads;
  solver.logging_type = ceres::SILENT;
  solver.initial_trust_region_radius = options.initial_trust_region_radius;
  solver.function_tolerance = options.function_tolerance;
  solver.gradient_tolerance = options.gradient_tolerance;
  solver.parameter_tolerance = options.parameter_tolerance;
  const bool adaptive = options.adaptive_rotor_prior && options.sigma_rotor_rate > 0 && options.rotor_prior_order == 1;
  if (adaptive) solver.max_num_iterations = options.pilot_iterations;
  ceres::Solver::Summary summary = problem.Solve(solver);
  int iterations = static_cast<int>(summary.iterations.size()) - 1;
  if (adaptive) {  // empirical Bayes: σ per segment from the pilot's rotor speeds, then the solve
    const int S = problem.num_segments();
    std::vector<double> energy(S);
    for (int s = 0; s < S; ++s) energy[s] = problem.ControlDerivativeEnergy(1, s);
    const std::vector<double> segment_sigma = AdaptiveRotorPriorSigma(energy, options.degree, QuadrotorModel::kControlDim);
    const bool thrust = options.thrust_prior;
    const double off = std::numeric_limits<double>::infinity();  // weight 0
    for (int s = 0; s < S; ++s) {
      const double sigma_s = std::max(options.adaptive_rotor_prior_floor, segment_sigma[s]);
      problem.SetControlSmoothnessSigmas(1, s, Eigen::Vector4d(thrust ? off : sigma_s, sigma_s, sigma_s, sigma_s));
    }
    std::vector<ceres::ResidualBlockId> thrust_blocks;
    if (thrust) {
      thrust_blocks = options.motion_prior ? AddMotionPrior(problem, options)
                                           : AddThrustAccelerationPrior(problem, vehicle, options);
    }
    solver.max_num_iterations = options.max_iterations;
    summary = problem.Solve(solver);
    iterations += static_cast<int>(summary.iterations.size()) - 1;
    for (int round = 1; thrust && round < options.thrust_prior_rounds; ++round) {
      // Another empirical-Bayes round: λ_a and σ_s from the solution with the thrust prior.
      for (ceres::ResidualBlockId id : thrust_blocks) problem.ceres_problem().RemoveResidualBlock(id);
      thrust_blocks = options.motion_prior ? AddMotionPrior(problem, options)
                                           : AddThrustAccelerationPrior(problem, vehicle, options);
      summary = problem.Solve(solver);
      iterations += static_cast<int>(summary.iterations.size()) - 1;
    }
  }

  QuadrotorEstimate out;
  out.states = problem.num_nodes();
  out.segments = problem.num_segments();
  out.degree = problem.degree();
  out.iterations = iterations;
  out.converged = summary.termination_type == ceres::CONVERGENCE;
  out.solver_report = summary.BriefReport();
  out.solver_full_report = summary.FullReport();
  out.start_time = t0;
  out.end_time = t1;
  for (double t : query_times) {
    if (t < t0 || t > t1) continue;
    const StateSample s = problem.Interpolate(t);
    out.samples.push_back({t, s.vector.segment<3>(0), s.vector.segment<3>(3), s.vector.segment<3>(6), s.rotation,
                           s.control.head<4>()});
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace cheval::estim

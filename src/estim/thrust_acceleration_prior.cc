#include "thrust_acceleration_prior.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/LU>

#include "cheval/estim/internal/thrust_acceleration_cost.h"

namespace cheval::estim {
namespace {

using Problem = PseudoSpectralProblem<QuadrotorModel>;
using internal::ThrustAccelerationCost;

constexpr int kOrder = 2;  // (D + λ)² a: a Matérn-3/2 process

// What the prior takes from the pilot, per world axis a, for x(t) = a(t) known at the nodes of each
// segment (X_s, N + 1 x 3) through the Gauss–Legendre rows q_s[j] of its j-th derivative (j = 0..2;
// |q_s[j] X_s|² = ∫_s |x^(j)|² dt): λ_a, the root-mean-square frequency ν = sqrt(−∫x''x / ∫x²) of
// the pilot's x_a (a Matérn-3/2 process has ν = λ; at most max_rate), the rows of (D + λ_a)² over
// each segment, and σ_s, the maximum-likelihood intensity of segment s (3 axes of N − 1 increments).
struct MaternParts {
  Eigen::Vector3d lambda;
  std::vector<std::array<Eigen::MatrixXd, 3>> rows;  // per segment and axis
  std::vector<double> sigma;                         // per segment
};

MaternParts FitMaternParts(const std::vector<std::array<Eigen::MatrixXd, kOrder + 1>>& q,
                           const std::vector<Eigen::MatrixXd>& X, int N, double max_rate) {
  const int S = static_cast<int>(X.size()), m = kOrder;
  Eigen::Vector3d num = Eigen::Vector3d::Zero(), den = Eigen::Vector3d::Zero();
  for (int s = 0; s < S; ++s) {
    const Eigen::MatrixXd A0 = q[s][0] * X[s], A2 = q[s][2] * X[s];
    for (int a = 0; a < 3; ++a) {
      num[a] -= A2.col(a).dot(A0.col(a));  // ∫ x'' x = −∫ |x'|² + ends
      den[a] += A0.col(a).squaredNorm();
    }
  }
  MaternParts parts;
  for (int a = 0; a < 3; ++a) {
    parts.lambda[a] = std::sqrt(std::clamp(den[a] > 0 ? num[a] / den[a] : 0.0, 0.0, max_rate * max_rate));
  }
  const double binomial[kOrder + 1] = {1, 2, 1};
  parts.rows.resize(S);
  parts.sigma.resize(S);
  for (int s = 0; s < S; ++s) {
    double e = 0;
    for (int a = 0; a < 3; ++a) {
      parts.rows[s][a] = Eigen::MatrixXd::Zero(N + 1, N + 1);
      for (int j = 0; j <= m; ++j) parts.rows[s][a] += binomial[j] * std::pow(parts.lambda[a], m - j) * q[s][j];
      e += (parts.rows[s][a] * X[s].col(a)).squaredNorm();
    }
    parts.sigma[s] = std::max(std::sqrt(e / (3.0 * (N + 1 - m))), 1e-9);
  }
  return parts;
}

// W with |W y|² = yᵀ P⁻¹ y for the stationary covariance P = diag(1/(4λ³), 1/(4λ)) σ² of (x, x')
// (from the spectrum σ² / (λ² + ω²)²).
Eigen::MatrixXd StationaryStartWhitening(double lambda, double sigma) {
  const double l = lambda;
  Eigen::MatrixXd cov(kOrder, kOrder);
  cov << 1 / (4 * l * l * l), 0, 0, 1 / (4 * l);
  cov *= sigma * sigma;
  const Eigen::MatrixXd info = cov.inverse();
  return Eigen::LLT<Eigen::MatrixXd>(info).matrixL().transpose();
}

// The rotor-speed and quaternion blocks of the global nodes first..last.
void NodeBlocks(Problem& problem, int first, int last, std::vector<double*>* controls, std::vector<double*>* quaternions) {
  for (int g = first; g <= last; ++g) {
    controls->push_back(problem.Control(g));
    quaternions->push_back(problem.Quaternion(g));
  }
}

}  // namespace

void AddThrustAccelerationPrior(Problem& problem, const QuadrotorParameters& vehicle, double max_rate) {
  const int S = problem.num_segments(), N = problem.degree(), m = kOrder;
  const double k_over_m = vehicle.thrust_coefficient / vehicle.mass_kg;
  const Eigen::Vector3d gbar(0, 0, vehicle.gravity_mps2);
  std::vector<Eigen::MatrixXd> F(S);                       // the pilot's f − ḡ at the nodes
  std::vector<std::array<Eigen::MatrixXd, kOrder + 1>> Q(S);  // GL rows of 1, D, D²
  for (int s = 0; s < S; ++s) {
    F[s].resize(N + 1, 3);
    for (int k = 0; k <= N; ++k) {
      const int g = problem.NodeOf(s, k);
      F[s].row(k) =
          (ThrustAccelerationCost::ThrustAcceleration(problem.Control(g), problem.Quaternion(g), k_over_m) - gbar)
              .transpose();
    }
    for (int j = 0; j <= m; ++j) Q[s][j] = problem.SmoothnessMatrix(j, s, N + 1);
  }
  const MaternParts parts = FitMaternParts(Q, F, N, max_rate);
  const std::vector<double>& sigma = parts.sigma;
  for (int s = 0; s < S; ++s) {  // the energy; the rows act on f, the prior is on f − ḡ: offsets −λ² ḡ_a
    Eigen::MatrixXd offsets(N + 1, 3);
    for (int a = 0; a < 3; ++a) offsets.col(a) = -std::pow(parts.lambda[a], m) * gbar[a] * Q[s][0].rowwise().sum();
    const internal::Segment segment = problem.SegmentOf(s);
    auto cost = std::make_unique<ThrustAccelerationCost>(segment.control, segment.quaternion, parts.rows[s], offsets,
                                                         k_over_m);
    cost->set_weight(1.0 / sigma[s]);
    problem.AddPrior(std::move(cost));
  }
  for (int s = 0; s + 1 < S; ++s) {  // f' continuous at the inner breakpoints
    std::vector<double*> controls, quaternions;
    NodeBlocks(problem, s * N, (s + 2) * N, &controls, &quaternions);
    auto cost = std::make_unique<ThrustAccelerationCost>(controls, quaternions, problem.SmoothnessJumpMatrix(m, s, 1.0),
                                                         k_over_m);
    cost->set_weight(1.0 / std::sqrt(sigma[s] * sigma[s + 1]));
    problem.AddPrior(std::move(cost));
  }
  // The stationary law of (a, a') at t0.
  const internal::TimeRow row = problem.RowAt(problem.start_time());
  Eigen::MatrixXd R0(m, N + 1);  // rows of a, a' at t0 in the first segment's point order
  R0.row(0) = row.w;
  R0.row(1) = row.dw;
  std::array<Eigen::MatrixXd, 3> C;
  Eigen::MatrixXd o(m, 3);
  for (int a = 0; a < 3; ++a) {
    const Eigen::MatrixXd W = StationaryStartWhitening(parts.lambda[a], sigma[0]);
    C[a] = W * R0;
    o.col(a) = -W.col(0) * gbar[a];
  }
  const internal::Segment first = problem.SegmentOf(0);
  problem.AddPrior(std::make_unique<ThrustAccelerationCost>(first.control, first.quaternion, C, o, k_over_m));
}

}  // namespace cheval::estim

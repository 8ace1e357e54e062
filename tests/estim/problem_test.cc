// The pseudo-spectral problem (estim/problem.h) and its costs (estim/internal/*_cost.h) on small
// models: every analytic Jacobian against central differences on the manifold, the exact
// rotation-rate relation ω = J_r(φ) φ' (and that the paper's ω = φ' is wrong away from the chart
// origin), the priors against closed forms, and control recovery of a unicycle.
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include <ceres/ceres.h>
#include <gtest/gtest.h>
#include <Eigen/Core>

#include "../support/residual_only.h"
#include "cheval/cheb/chebyshev.h"
#include "cheval/common/error.h"
#include "cheval/estim/models.h"
#include "cheval/estim/problem.h"
#include "cheval/lie/so3.h"

namespace cheval::estim {
namespace {

// Attitude kinematics for tests: vector state ω (body rate), rotation R; control u = ω'.
struct AttitudeModel {
  static constexpr int kVectorDim = 3;
  static constexpr int kBlockSize = 3;
  static constexpr bool kHasRotation = true;
  static constexpr int kControlDim = 3;
  template <typename T>
  void Dynamics(const T* x, const Eigen::Matrix<T, 3, 3>& /*R*/, const T* u, T* x_dot, T* omega) const {
    for (int i = 0; i < 3; ++i) {
      x_dot[i] = u[i];
      omega[i] = x[i];
    }
  }
};

// A unicycle (planar car), a model without a rotation: vector state (4) = (x, y, θ, s) in blocks of
// 2 — position (m), heading (rad), forward speed (m/s); control (2) = (forward acceleration m/s²,
// yaw rate rad/s). x' = s cos θ, y' = s sin θ, θ' = u1, s' = u0.
struct UnicycleModel {
  static constexpr int kVectorDim = 4;
  static constexpr int kBlockSize = 2;
  static constexpr bool kHasRotation = false;
  static constexpr int kControlDim = 2;

  template <typename T>
  void Dynamics(const T* x, const Eigen::Matrix<T, 3, 3>& /*R*/, const T* u, T* x_dot, T* /*omega*/) const {
    using std::cos;
    using std::sin;
    x_dot[0] = x[3] * cos(x[2]);
    x_dot[1] = x[3] * sin(x[2]);
    x_dot[2] = u[1];
    x_dot[3] = u[0];
  }
};

// φ(t) of a large rotation, its derivative and second derivative.
Eigen::Vector3d Phi(double t) { return {0.8 * std::sin(t), 0.5 * std::cos(2 * t), 0.6 * t}; }
Eigen::Vector3d PhiDot(double t) { return {0.8 * std::cos(t), -1.0 * std::sin(2 * t), 0.6}; }

// Body rate of R(t) = Exp(φ(t)) and its time derivative (by Jets in t).
void BodyRate(double t, Eigen::Vector3d* w, Eigen::Vector3d* w_dot) {
  using J1 = ceres::Jet<double, 1>;
  const J1 tj(t, 0);
  using std::cos;
  using std::sin;
  const Eigen::Matrix<J1, 3, 1> phi(J1(0.8) * sin(tj), J1(0.5) * cos(J1(2) * tj), J1(0.6) * tj);
  const Eigen::Matrix<J1, 3, 1> phi_dot(J1(0.8) * cos(tj), J1(-1.0) * sin(J1(2) * tj), J1(0.6));
  const Eigen::Matrix<J1, 3, 1> rate = lie::SO3<J1>::RightJacobian(phi) * phi_dot;
  for (int i = 0; i < 3; ++i) {
    (*w)[i] = rate[i].a;
    (*w_dot)[i] = rate[i].v[0];
  }
}

// Central differences of `evaluate` (which reads the problem's current parameter values, `rows`
// numbers) along every tangent coordinate of every block, moved by ±h on the block's manifold: one
// column per tangent coordinate, in the order of `blocks`.
Eigen::MatrixXd CentralDifferences(ceres::Problem& cp, const std::vector<double*>& blocks, int rows,
                                   const std::function<Eigen::VectorXd()>& evaluate, double h = 1e-6) {
  int columns = 0;
  for (double* block : blocks) columns += cp.ParameterBlockTangentSize(block);
  Eigen::MatrixXd out(rows, columns);
  int col = 0;
  for (double* block : blocks) {
    const int size = cp.ParameterBlockSize(block), tangent = cp.ParameterBlockTangentSize(block);
    const ceres::Manifold* manifold = cp.GetManifold(block);
    const std::vector<double> saved(block, block + size);
    for (int d = 0; d < tangent; ++d, ++col) {
      Eigen::VectorXd side[2];
      for (int k = 0; k < 2; ++k) {
        std::vector<double> delta(tangent, 0.0), moved(size);
        delta[d] = k == 0 ? h : -h;
        if (manifold) {
          manifold->Plus(saved.data(), delta.data(), moved.data());
        } else {
          for (int e = 0; e < size; ++e) moved[e] = saved[e] + delta[e];
        }
        std::copy(moved.begin(), moved.end(), block);
        side[k] = evaluate();
      }
      std::copy(saved.begin(), saved.end(), block);
      out.col(col) = (side[0] - side[1]) / (2 * h);
    }
  }
  return out;
}

// The whole problem's Jacobian (tangent space) as Ceres assembles it from the analytic blocks,
// against central differences of the residuals. h = 1e-6 gives ~1e-9 truncation + rounding on these
// O(1..100) residuals; the tolerance 1e-5 relative to the largest entry leaves a margin.
template <class Model>
void ExpectJacobianMatchesDifferences(PseudoSpectralProblem<Model>& problem) {
  ceres::Problem& cp = problem.ceres_problem();
  ceres::Problem::EvaluateOptions options;
  cp.GetParameterBlocks(&options.parameter_blocks);
  std::vector<double> r0;
  ceres::CRSMatrix crs;
  ASSERT_TRUE(cp.Evaluate(options, nullptr, &r0, nullptr, &crs));
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int i = 0; i < crs.num_rows; ++i) {
    for (int k = crs.rows[i]; k < crs.rows[i + 1]; ++k) J(i, crs.cols[k]) = crs.values[k];
  }
  const Eigen::MatrixXd numeric = CentralDifferences(cp, options.parameter_blocks, crs.num_rows, [&] {
    std::vector<double> r;
    cp.Evaluate(options, nullptr, &r, nullptr, nullptr);
    return Eigen::VectorXd(Eigen::Map<Eigen::VectorXd>(r.data(), r.size()));
  });
  const double scale = std::max(1.0, J.cwiseAbs().maxCoeff());
  EXPECT_LT((J - numeric).cwiseAbs().maxCoeff() / scale, 1e-5);
}

// The gradient Ceres assembles against central differences of the cost (relative 1e-6: the cost is
// smooth and h = 1e-6 leaves ~1e-9 relative truncation + rounding).
template <class Model>
void ExpectGradientMatchesDifferences(PseudoSpectralProblem<Model>& problem) {
  ceres::Problem& cp = problem.ceres_problem();
  ceres::Problem::EvaluateOptions options;
  cp.GetParameterBlocks(&options.parameter_blocks);
  double cost = 0;
  std::vector<double> gradient;
  ASSERT_TRUE(cp.Evaluate(options, &cost, nullptr, &gradient, nullptr));
  const Eigen::MatrixXd numeric = CentralDifferences(cp, options.parameter_blocks, 1, [&] {
    double c = 0;
    cp.Evaluate(options, &c, nullptr, nullptr, nullptr);
    return Eigen::VectorXd::Constant(1, c).eval();
  });
  const Eigen::VectorXd analytic = Eigen::Map<Eigen::VectorXd>(gradient.data(), gradient.size());
  const double largest = std::max(1.0, analytic.cwiseAbs().maxCoeff());
  EXPECT_LT((numeric.row(0).transpose() - analytic).cwiseAbs().maxCoeff() / largest, 1e-6);
}

// Builds the attitude problem on [0, 2] (2 segments) with nodes on the exact trajectory; with
// `paper_relation` the node body rates are set to φ' instead (what ω = φ' would predict).
PseudoSpectralProblem<AttitudeModel> AttitudeProblem(int degree, bool paper_relation) {
  PseudoSpectralProblem<AttitudeModel> problem(AttitudeModel{}, {0.0, 1.0, 2.0}, degree);
  for (int g = 0; g < problem.num_nodes(); ++g) {
    const double t = problem.NodeTime(g);
    Eigen::Vector3d w, w_dot;
    BodyRate(t, &w, &w_dot);
    if (paper_relation) w = PhiDot(t);
    problem.SetNode(g, w, lie::SO3d::Exp(Phi(t)).Matrix(), w_dot);
  }
  problem.SetChartReferences();
  problem.AddCollocation(Eigen::Matrix<double, 6, 1>::Ones());
  return problem;
}

double Cost(PseudoSpectralProblem<AttitudeModel>& problem) {
  double cost = 0;
  problem.ceres_problem().Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr, nullptr);
  return cost;
}

// On the exact trajectory the defects vanish spectrally (the chart curves are smooth, so degree 24
// resolves them to ~1e-9); with ω = φ' (the paper's relation) they are O(0.1): the relation matters.
TEST(PseudoSpectralProblem, RotationDefectUsesRightJacobian) {
  auto exact = AttitudeProblem(24, false);
  auto paper = AttitudeProblem(24, true);
  EXPECT_LT(Cost(exact), 1e-14);
  EXPECT_GT(Cost(paper), 1e-2);
}

TEST(PseudoSpectralProblem, CollocationJacobiansMatchDifferences) {
  auto problem = AttitudeProblem(6, false);
  // Move the nodes off the trajectory so every term of the Jacobian is exercised.
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0.0, 0.1);
  for (int g = 0; g < problem.num_nodes(); ++g) {
    for (int i = 0; i < 3; ++i) problem.Vector(g)[i] += n(rng);
    for (int i = 0; i < 3; ++i) problem.Control(g)[i] += n(rng);
  }
  ExpectJacobianMatchesDifferences(problem);
}

// A rotation + vector measurement with many rows (compressed by QR) and a robust loss.
struct PointObservation {
  std::vector<Eigen::Vector3d> points;
  int first = 0;  // index of points[0] in the whole set (sets the measured offsets)
  template <typename T>
  bool operator()(const T* x, const Eigen::Matrix<T, 3, 3>& R, T* r) const {
    for (size_t i = 0; i < points.size(); ++i) {
      const Eigen::Matrix<T, 3, 1> v = R.transpose() * points[i].cast<T>() + Eigen::Map<const Eigen::Matrix<T, 3, 1>>(x);
      for (int e = 0; e < 3; ++e) r[3 * i + e] = v[e] - T(0.1 * static_cast<double>(first + static_cast<int>(i) + e));
    }
    return true;
  }
};

// Cost, gradient (tangent space) and Gauss-Newton matrix JᵀJ of a whole problem.
struct Normal {
  double cost = 0;
  Eigen::VectorXd gradient;
  Eigen::MatrixXd JtJ;
};
template <class Model>
Normal NormalEquations(PseudoSpectralProblem<Model>& problem) {
  ceres::Problem& cp = problem.ceres_problem();
  // Node by node (the same order in every problem built on the same nodes).
  std::vector<double*> blocks;
  using P = PseudoSpectralProblem<Model>;
  for (int g = 0; g < problem.num_nodes(); ++g) {
    for (int b = 0; b < P::kBlocks; ++b) blocks.push_back(problem.Vector(g) + b * P::kBlock);
    if (P::kRotation) blocks.push_back(problem.Quaternion(g));
    blocks.push_back(problem.Control(g));
  }
  ceres::Problem::EvaluateOptions options;
  options.parameter_blocks = blocks;
  Normal n;
  std::vector<double> gradient;
  ceres::CRSMatrix crs;
  cp.Evaluate(options, &n.cost, nullptr, &gradient, &crs);
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int i = 0; i < crs.num_rows; ++i) {
    for (int k = crs.rows[i]; k < crs.rows[i + 1]; ++k) J(i, crs.cols[k]) = crs.values[k];
  }
  n.gradient = Eigen::Map<Eigen::VectorXd>(gradient.data(), gradient.size());
  n.JtJ = J.transpose() * J;
  return n;
}

// Many rows of one time are compressed to (used tangent + 1) rows by a QR of their Jacobian. The
// compressed residual is not the original vector, so its Jacobian is not checked by differences;
// what must hold is that cost, gradient and Gauss-Newton matrix are those of the uncompressed rows.
// Without a loss: all three against the same points added one by one (3 rows each: not
// compressed), to rounding (1e-10 relative). With a Cauchy loss per point: cost against ρ summed
// by hand and the gradient against central differences of the cost (h = 1e-6: ~1e-8 relative).
TEST(PseudoSpectralProblem, CompressedMeasurementKeepsCostGradientAndNormalMatrix) {
  const PointObservation obs{{{1, 2, 3}, {-1, 0.5, 2}, {0.3, -2, 1}, {2, 2, -1}}};
  auto compressed = AttitudeProblem(6, false);
  auto split = AttitudeProblem(6, false);
  for (double t : {0.37, 1.61}) {
    compressed.AddMeasurement(t, obs, 12, 3, {0});
    for (int i = 0; i < 4; ++i) split.AddMeasurement(t, PointObservation{{obs.points[i]}, i}, 3, 3, {0});
  }
  const Normal a = NormalEquations(compressed), b = NormalEquations(split);
  EXPECT_NEAR(a.cost, b.cost, 1e-10 * b.cost);
  EXPECT_LT((a.gradient - b.gradient).cwiseAbs().maxCoeff(), 1e-10 * b.gradient.cwiseAbs().maxCoeff());
  EXPECT_LT((a.JtJ - b.JtJ).cwiseAbs().maxCoeff(), 1e-10 * b.JtJ.cwiseAbs().maxCoeff());
  ceres::CauchyLoss loss(0.5);
  for (const ceres::LossFunction* l : {static_cast<const ceres::LossFunction*>(nullptr),
                                       static_cast<const ceres::LossFunction*>(&loss)}) {
    auto problem = AttitudeProblem(6, false);
    problem.AddMeasurement(0.37, obs, 12, 3, {0}, l);
    problem.AddMeasurement(1.61, obs, 12, 3, {0}, l);
    auto plain = AttitudeProblem(6, false);
    const double collocation = Cost(plain);
    double expected = 0;
    for (double t : {0.37, 1.61}) {
      const StateSample st = problem.Interpolate(t);
      std::vector<double> r(12);
      obs(st.vector.data(), st.rotation, r.data());
      for (int i = 0; i < 4; ++i) {
        const double sq = Eigen::Map<Eigen::Vector3d>(&r[3 * i]).squaredNorm();
        double rho[3] = {sq, 1, 0};
        if (l) l->Evaluate(sq, rho);
        expected += 0.5 * rho[0];
      }
    }
    EXPECT_NEAR(Cost(problem) - collocation, expected, 1e-10 * std::max(1.0, expected));
    ExpectGradientMatchesDifferences(problem);
  }
}

// A vector measurement declared not to use the rotation has no quaternion among its blocks and the
// same cost, gradient and Gauss–Newton matrix as the same measurement with the rotation among them
// (its functor ignores R: the rotation's columns are zero).
struct VectorObservation {
  template <typename T>
  bool operator()(const T* x, const Eigen::Matrix<T, 3, 3>& /*R*/, T* r) const {
    for (int e = 0; e < 3; ++e) r[e] = x[e] * x[e] - T(0.2 * e);
    return true;
  }
};
TEST(PseudoSpectralProblem, MeasurementWithoutRotationKeepsNormalEquations) {
  auto without = AttitudeProblem(6, false);
  auto with = AttitudeProblem(6, false);
  ceres::HuberLoss loss(0.3);
  for (double t : {0.37, 1.61}) {
    without.AddMeasurement(t, VectorObservation{}, 3, 3, {0}, &loss, false);
    with.AddMeasurement(t, VectorObservation{}, 3, 3, {0}, &loss, true);
  }
  std::vector<ceres::ResidualBlockId> ids;
  without.ceres_problem().GetResidualBlocks(&ids);
  int vector_only = 0;  // residual blocks on the 7 nodes' vector blocks and nothing else: the measurements
  for (ceres::ResidualBlockId id : ids) {
    std::vector<double*> blocks;
    without.ceres_problem().GetParameterBlocksForResidualBlock(id, &blocks);
    vector_only += blocks.size() == 7 && std::all_of(blocks.begin(), blocks.end(), [&](double* b) {
                     return without.ceres_problem().ParameterBlockSize(b) == 3;
                   });
  }
  EXPECT_EQ(vector_only, 2);
  const Normal a = NormalEquations(without), b = NormalEquations(with);
  EXPECT_NEAR(a.cost, b.cost, 1e-12 * b.cost);
  EXPECT_LT((a.gradient - b.gradient).cwiseAbs().maxCoeff(), 1e-12 * b.gradient.cwiseAbs().maxCoeff());
  EXPECT_LT((a.JtJ - b.JtJ).cwiseAbs().maxCoeff(), 1e-12 * b.JtJ.cwiseAbs().maxCoeff());
  ExpectGradientMatchesDifferences(without);
}

// Measurements added as batches (one block per segment) have the cost, gradient and Gauss–Newton
// matrix of the same measurements added one by one, with a loss per sample, with and without the
// rotation, and with more or fewer rows than the nodes' tangent.
TEST(PseudoSpectralProblem, MeasurementBatchKeepsNormalEquations) {
  ceres::HuberLoss loss(0.3);
  for (int samples : {3, 17}) {
    for (bool uses_rotation : {true, false}) {
      auto one_by_one = AttitudeProblem(6, false);
      auto batched = AttitudeProblem(6, false);
      std::vector<double> times;
      std::vector<PointObservation> observations;
      for (int i = 0; i < samples; ++i) {
        const double t = 0.05 + 1.9 * i / samples;
        const PointObservation obs{{{1.0 + i, 2, 3 - 0.1 * i}}, i % 3};
        times.push_back(t);
        observations.push_back(obs);
        one_by_one.AddMeasurement(t, obs, 3, 3, {0}, &loss, uses_rotation);
      }
      batched.AddMeasurements(times, observations, 3, 3, {0}, &loss, uses_rotation);
      std::vector<ceres::ResidualBlockId> a_ids, b_ids;
      one_by_one.ceres_problem().GetResidualBlocks(&a_ids);
      batched.ceres_problem().GetResidualBlocks(&b_ids);
      EXPECT_EQ(a_ids.size() - b_ids.size(), static_cast<size_t>(samples - 2));  // one block per segment
      // The degrees of freedom still count every measurement's rows (a reduced χ² divides by them).
      EXPECT_EQ(batched.num_represented_rows(), one_by_one.ceres_problem().NumResiduals());
      EXPECT_EQ(one_by_one.num_represented_rows(), one_by_one.ceres_problem().NumResiduals());
      const Normal a = NormalEquations(one_by_one), b = NormalEquations(batched);
      EXPECT_NEAR(a.cost, b.cost, 1e-10 * a.cost) << samples << uses_rotation;
      EXPECT_LT((a.gradient - b.gradient).cwiseAbs().maxCoeff(), 1e-10 * a.gradient.cwiseAbs().maxCoeff());
      EXPECT_LT((a.JtJ - b.JtJ).cwiseAbs().maxCoeff(), 1e-10 * a.JtJ.cwiseAbs().maxCoeff());
      ExpectGradientMatchesDifferences(batched);
    }
  }
}

// A measurement evaluated alone (Ceres pricing a step: doubles) costs what it costs linearised
// (ceres::Jet): compressed and not, with and without a loss, with and without the rotation.
TEST(PseudoSpectralProblem, MeasurementCostsTheSameWithAndWithoutJacobians) {
  const PointObservation obs{{{1, 2, 3}, {-1, 0.5, 2}, {0.3, -2, 1}, {2, 2, -1}}};
  ceres::HuberLoss loss(0.3);
  auto problem = AttitudeProblem(6, false);
  problem.AddMeasurement(0.37, obs, 12, 3, {0}, &loss);                      // compressed
  problem.AddMeasurement(1.61, PointObservation{{obs.points[1]}, 1}, 3, 3, {0}, &loss);  // not
  problem.AddMeasurement(0.9, VectorObservation{}, 3, 3, {0}, nullptr, false);  // no rotation
  problem.AddMeasurements({0.2, 0.3, 1.2}, std::vector<PointObservation>(3, obs), 12, 3, {0}, &loss);  // batches
  // Nodes off the trajectory, so that every residual is far from zero.
  for (int g = 0; g < problem.num_nodes(); ++g) {
    const StateSample x = problem.Interpolate(problem.NodeTime(g));
    problem.SetNode(g, x.vector * 1.3 + Eigen::Vector3d(0.1, -0.2, 0.05),
                    x.rotation * lie::SO3d::Exp(Eigen::Vector3d(0.02 * g, -0.1, 0.3)).Matrix(), x.control);
  }
  EXPECT_EQ(cheval::testing::ExpectResidualOnlyEvaluationMatches(problem.ceres_problem()), 3 + 2 + 2 * 7 * 2);
}

// A point mass for the delayed positions: vector state (p, v) in blocks of 3, control u = v'.
struct PointMassModel {
  static constexpr int kVectorDim = 6;
  static constexpr int kBlockSize = 3;
  static constexpr bool kHasRotation = false;
  static constexpr int kControlDim = 3;
  template <typename T>
  void Dynamics(const T* x, const Eigen::Matrix<T, 3, 3>& /*R*/, const T* u, T* x_dot, T* /*omega*/) const {
    for (int i = 0; i < 3; ++i) {
      x_dot[i] = x[3 + i];
      x_dot[3 + i] = u[i];
    }
  }
};
Eigen::Vector3d MassPosition(double t) { return {std::sin(t), t * t, std::cos(2 * t)}; }
Eigen::Vector3d MassVelocity(double t) { return {std::cos(t), 2 * t, -2 * std::sin(2 * t)}; }

// Positions stamped by a clock δ behind the problem's: with the problem's nodes on the trajectory, the
// cost vanishes at the true δ (to the expansion's error δ³|p⁽³⁾|/6) and not at δ = 0; its gradient (δ
// included) matches central differences, and a step is priced as the linearisation says.
TEST(PseudoSpectralProblem, DelayedPositionsMeetTheTrajectoryAtTheirClockOffset) {
  const double true_offset = 0.03, sigma = 1e-3;
  PseudoSpectralProblem<PointMassModel> problem(PointMassModel{}, {0.0, 1.0, 2.0}, 10);
  for (int g = 0; g < problem.num_nodes(); ++g) {
    const double t = problem.NodeTime(g);
    Eigen::VectorXd x(6);
    x << MassPosition(t), MassVelocity(t);
    problem.SetNode(g, x, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  }
  double offset = 0;
  ceres::HuberLoss loss(3.0);
  std::vector<double> times;
  std::vector<Eigen::Vector3d> measured;
  for (int s = 0; s < 2; ++s) {
    for (int i = 0; i < 20; ++i) {
      times.push_back(s + 0.013 + 0.049 * i);
      measured.push_back(MassPosition(times.back() + true_offset));
    }
  }
  problem.AddDelayedPositions(times, measured, 0, 1, sigma, &loss, &offset);
  const auto cost = [&] {
    double c = 0;
    problem.ceres_problem().Evaluate(ceres::Problem::EvaluateOptions(), &c, nullptr, nullptr, nullptr);
    return c;
  };
  const double at_zero = cost();
  offset = true_offset;
  const double at_truth = cost();
  EXPECT_GT(at_zero, 1e3);              // 3 cm of motion against σ = 1 mm
  EXPECT_LT(at_truth, 1e-4 * at_zero);  // the expansion's error is a few µm
  offset = 0.02;
  ExpectGradientMatchesDifferences(problem);
  EXPECT_EQ(cheval::testing::ExpectResidualOnlyEvaluationMatches(problem.ceres_problem()), 2);
  EXPECT_EQ(problem.num_represented_rows(), 3 * 40);
}

// An accelerometer-like measurement of v' = x'[3..6) of the point mass, against a measured value.
struct MassAcceleration {
  Eigen::Vector3d measured;
  template <typename T>
  bool operator()(const T* x_dot, T* r) const {
    for (int i = 0; i < 3; ++i) r[i] = (x_dot[3 + i] - T(measured[i])) * T(2.0);
    return true;
  }
};

// Derivative measurements added as batches (one compressed block per segment, only the velocity
// blocks) have the cost, gradient and Gauss–Newton matrix of the same measurements added one by one
// (every block, a loss per sample); a step is priced as the linearisation says, and the degrees of
// freedom count every sample's rows.
TEST(PseudoSpectralProblem, DerivativeMeasurementBatchKeepsNormalEquations) {
  ceres::HuberLoss loss(0.5);
  const auto mass_problem = [] {
    PseudoSpectralProblem<PointMassModel> problem(PointMassModel{}, {0.0, 1.0, 2.0}, 6);
    for (int g = 0; g < problem.num_nodes(); ++g) {
      const double t = problem.NodeTime(g);
      Eigen::VectorXd x(6);
      x << MassPosition(t), MassVelocity(t) * (1 + 0.1 * g);  // off the trajectory: residuals of all sizes
      problem.SetNode(g, x, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
    }
    problem.AddCollocation(Eigen::Matrix<double, 6, 1>::Ones());  // the same in both: every block in the problem
    return problem;
  };
  auto one_by_one = mass_problem(), batched = mass_problem();
  std::vector<double> times;
  std::vector<MassAcceleration> measured;
  for (int i = 0; i < 30; ++i) {
    times.push_back(0.01 + 1.98 * i / 29);
    measured.push_back({Eigen::Vector3d(-std::sin(times.back()), 2, 0.3 * i)});
    one_by_one.AddDerivativeMeasurement(times.back(), measured.back(), 3, &loss);
  }
  batched.AddDerivativeMeasurements(times, measured, 3, 3, {1}, &loss);
  std::vector<ceres::ResidualBlockId> ids;
  batched.ceres_problem().GetResidualBlocks(&ids);
  std::vector<ceres::ResidualBlockId> collocation_ids;
  mass_problem().ceres_problem().GetResidualBlocks(&collocation_ids);
  EXPECT_EQ(ids.size() - collocation_ids.size(), 2u);  // one block per segment
  EXPECT_EQ(batched.num_represented_rows(), one_by_one.num_represented_rows());
  const Normal a = NormalEquations(one_by_one), b = NormalEquations(batched);
  EXPECT_NEAR(a.cost, b.cost, 1e-10 * a.cost);
  EXPECT_LT((a.gradient - b.gradient).cwiseAbs().maxCoeff(), 1e-10 * a.gradient.cwiseAbs().maxCoeff());
  EXPECT_LT((a.JtJ - b.JtJ).cwiseAbs().maxCoeff(), 1e-10 * a.JtJ.cwiseAbs().maxCoeff());
  ExpectGradientMatchesDifferences(batched);
  EXPECT_EQ(cheval::testing::ExpectResidualOnlyEvaluationMatches(batched.ceres_problem()),
            static_cast<int>(collocation_ids.size()) + 2);
  EXPECT_THROW(batched.AddDerivativeMeasurements({0.5}, std::vector<MassAcceleration>{}, 3, 3, {1}), UsageError);
  EXPECT_THROW(batched.AddDerivativeMeasurements({0.5}, std::vector<MassAcceleration>(1), 3, 3, {2}), UsageError);
}

TEST(PseudoSpectralProblem, OutsideIntervalIsAnError) {
  auto problem = AttitudeProblem(6, false);
  PointObservation obs{{{1, 2, 3}}};
  EXPECT_THROW(problem.AddMeasurement(2.5, obs, 3, 3, {0}), ComputeError);
  EXPECT_THROW(problem.Interpolate(-0.1), ComputeError);
  EXPECT_THROW(PseudoSpectralProblem<AttitudeModel>(AttitudeModel{}, {0.0, 0.0}, 6), UsageError);
}

// Unicycle: θ(t) = 0.3 sin t + 0.2 t, speed s(t) = 1 + 0.2 t; controls (0.2, 0.3 cos t + 0.2).
// Positions integrated by RK4 at 1 kHz (error ~1e-13); measured at 50 Hz without noise.
struct UnicycleTruth {
  std::vector<double> t;
  std::vector<Eigen::Vector2d> xy;
};
UnicycleTruth SimulateUnicycle(double duration) {
  UnicycleTruth truth;
  Eigen::Vector2d p(0, 0);
  const double dt = 1e-3;
  auto vel = [](double t) {
    const double th = 0.3 * std::sin(t) + 0.2 * t, s = 1 + 0.2 * t;
    return Eigen::Vector2d(s * std::cos(th), s * std::sin(th));
  };
  for (int i = 0; i <= static_cast<int>(std::lround(duration / dt)); ++i) {
    const double t = i * dt;
    if (i % 20 == 0) {
      truth.t.push_back(t);
      truth.xy.push_back(p);
    }
    p += dt / 6 * (vel(t) + 4 * vel(t + dt / 2) + vel(t + dt));  // RK4 of a time-only right side
  }
  return truth;
}

struct XYMeasurement {
  Eigen::Vector2d xy;
  double sigma;
  template <typename T>
  bool operator()(const T* x, const Eigen::Matrix<T, 3, 3>& /*R*/, T* r) const {
    r[0] = (x[0] - T(xy[0])) / T(sigma);
    r[1] = (x[1] - T(xy[1])) / T(sigma);
    return true;
  }
};

// Speed measured through the derivative row: x'² + y'² = s².
struct SpeedMeasurement {
  double speed;
  template <typename T>
  bool operator()(const T* x_dot, T* r) const {
    r[0] = (x_dot[0] * x_dot[0] + x_dot[1] * x_dot[1] - T(speed * speed)) / T(0.01);
    return true;
  }
};

TEST(UnicycleModel, RecoversControlsFromPositions) {
  const UnicycleTruth truth = SimulateUnicycle(4.0);
  PseudoSpectralProblem<UnicycleModel> problem(UnicycleModel{}, {0.0, 2.0, 4.0}, 14);
  // Initial values as a front end would give them: position of the nearest measurement, heading
  // and speed from the difference of its neighbours, zero controls.
  for (int g = 0; g < problem.num_nodes(); ++g) {
    const size_t i = std::min<size_t>(std::lround(problem.NodeTime(g) / 0.02), truth.t.size() - 2);
    const Eigen::Vector2d d = (truth.xy[i + 1] - truth.xy[i]) / 0.02;
    problem.SetNode(g, Eigen::Vector4d(truth.xy[i].x(), truth.xy[i].y(), std::atan2(d.y(), d.x()), d.norm()),
                    Eigen::Matrix3d::Identity(), Eigen::Vector2d::Zero());
  }
  problem.SetChartReferences();
  problem.AddCollocation(Eigen::Vector4d::Constant(1e-4));
  for (size_t i = 0; i < truth.t.size(); ++i) problem.AddMeasurement(truth.t[i], XYMeasurement{truth.xy[i], 1e-3}, 2, 2, {0});
  problem.AddDerivativeMeasurement(1.0, SpeedMeasurement{1.2}, 1);
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  options.max_num_iterations = 100;
  const ceres::Solver::Summary summary = problem.Solve(options);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.BriefReport();
  // Noise-free positions: the controls come back to the polynomial approximation error (degree 14
  // on 2 s of these sinusoids: < 1e-4), far below 1e-3.
  double worst = 0;
  for (double t = 0.05; t < 3.96; t += 0.1) {
    const StateSample s = problem.Interpolate(t);
    worst = std::max({worst, std::abs(s.control[0] - 0.2), std::abs(s.control[1] - (0.3 * std::cos(t) + 0.2))});
    EXPECT_NEAR(s.vector[3], 1 + 0.2 * t, 1e-4);
  }
  EXPECT_LT(worst, 1e-3);
  ExpectJacobianMatchesDifferences(problem);
}

// A unicycle problem whose controls are the polynomials u0(t) = t³ − 2t, u1(t) = 0.5 t² + 1 on three
// unequal segments of degree 5 (exactly representable), with only the smoothness prior in it.
// With `kink`, u0 gets + 3 (t − 1.1) after the second breakpoint: u0' jumps by 3 there.
PseudoSpectralProblem<UnicycleModel> PolynomialControls(int order, double sigma, bool kink = false) {
  PseudoSpectralProblem<UnicycleModel> problem(UnicycleModel{}, {0.0, 0.4, 1.1, 2.0}, 5);
  for (int g = 0; g < problem.num_nodes(); ++g) {
    const double t = problem.NodeTime(g);
    const double extra = kink && t > 1.1 ? 3.0 * (t - 1.1) : 0.0;
    problem.SetNode(g, Eigen::Vector4d::Zero(), Eigen::Matrix3d::Identity(),
                    Eigen::Vector2d(t * t * t - 2 * t + extra, 0.5 * t * t + 1));
  }
  problem.AddControlSmoothnessPrior(order, sigma);
  return problem;
}

double TotalCost(ceres::Problem& cp) {
  double cost = 0;
  cp.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr, nullptr);
  return cost;
}

// DerivativeMeasurementCost on a vector part that is a polynomial of the segment's degree: the
// derivative row is exact, so h(x'(t)) = x'(t) − (the closed-form derivative) vanishes to rounding
// (1e-12) at any t, and its Jacobian (w'_k per node, through the Jets) matches differences.
struct RateResidual {
  Eigen::Vector4d expected;
  template <typename T>
  bool operator()(const T* x_dot, T* r) const {
    for (int i = 0; i < 4; ++i) r[i] = x_dot[i] - T(expected[i]);
    return true;
  }
};

TEST(PseudoSpectralProblem, DerivativeMeasurementIsExactOnPolynomials) {
  PseudoSpectralProblem<UnicycleModel> problem(UnicycleModel{}, {0.0, 0.4, 1.1, 2.0}, 5);
  const auto x = [](double t) { return Eigen::Vector4d(t * t * t, 2 - t, 0.5 * t * t, std::pow(t, 5)); };
  const auto x_dot = [](double t) { return Eigen::Vector4d(3 * t * t, -1, t, 5 * std::pow(t, 4)); };
  for (int g = 0; g < problem.num_nodes(); ++g) {
    problem.SetNode(g, x(problem.NodeTime(g)), Eigen::Matrix3d::Identity(), Eigen::Vector2d::Zero());
  }
  for (double t : {0.0, 0.25, 0.4, 0.93, 2.0}) problem.AddDerivativeMeasurement(t, RateResidual{x_dot(t)}, 4);
  EXPECT_LT(TotalCost(problem.ceres_problem()), 1e-20);
  for (int g = 0; g < problem.num_nodes(); ++g) problem.Vector(g)[1] += 0.01 * g;  // off the polynomial
  ExpectJacobianMatchesDifferences(problem);
}

// The prior is ∫ |u^(m)|² dt / σ² exactly (Ceres' cost is half of it), against closed forms; the
// quadrature is exact, so the match is to rounding (1e-12 relative).
TEST(PseudoSpectralProblem, ControlSmoothnessPriorIsTheExactIntegral) {
  const double sigma = 0.7;
  // m = 1: ∫_0^2 (3t² − 2)² dt = [9t⁵/5 − 4t³ + 4t]_0^2 = 57.6 − 32 + 8 = 33.6, ∫_0^2 t² dt = 8/3.
  // m = 2: ∫_0^2 (6t)² dt = 96, ∫_0^2 1 dt = 2 (u' is continuous: the jump residuals are 0).
  // m = 3: ∫_0^2 6² dt = 72.
  const double expected[4] = {0, 33.6 + 8.0 / 3.0, 96.0 + 2.0, 72.0};
  for (int order : {1, 2, 3}) {
    auto problem = PolynomialControls(order, sigma);
    const double cost = TotalCost(problem.ceres_problem()), want = 0.5 * expected[order] / (sigma * sigma);
    EXPECT_NEAR(cost, want, 1e-12 * want) << order;
    ExpectJacobianMatchesDifferences(problem);
  }
  EXPECT_THROW(PolynomialControls(0, sigma), UsageError);
  EXPECT_THROW(PolynomialControls(1, 0.0), UsageError);
}

// A kink (u0' jumps by 3 at t = 1.1; u'' unchanged) leaves the second-order integral unchanged but
// the continuity residual holds u' continuous: the cost rises by ½ (3/σ₁)², σ₁ = σ h^(1/2) with h
// the shortest node spacing of the two segments there (lengths 0.7 and 0.9 s).
TEST(PseudoSpectralProblem, SecondOrderPriorPenalisesRateJumps) {
  const double sigma = 2.0;
  auto smooth = PolynomialControls(2, sigma), kinked = PolynomialControls(2, sigma, true);
  const double c_smooth = TotalCost(smooth.ceres_problem()), c_kinked = TotalCost(kinked.ceres_problem());
  const double x1 = std::cos(M_PI / 5);  // the Chebyshev point next to the end, degree 5
  const double h = (1.0 - x1) * 0.7 / 2;
  const double sigma_1 = sigma * std::sqrt(h);
  EXPECT_NEAR(c_kinked - c_smooth, 0.5 * (3.0 / sigma_1) * (3.0 / sigma_1), 1e-9 * c_kinked);
}

// Per segment, ControlDerivativeEnergy is ∫_s |u'|² dt of the current controls exactly (closed form
// F(t) = 9t⁵/5 − 4t³ + 4t + t³/3 for (3t² − 2)² + t²; quadrature exact, so 1e-12 relative), and
// SetControlSmoothnessSigma re-weights one segment's share of the prior: with σ₁ = 2σ the cost is
// ½ (E₀ + E₁/4 + E₂)/σ², Jacobians still analytic and right.
TEST(PseudoSpectralProblem, SmoothnessPriorSigmaPerSegment) {
  const double sigma = 0.7;
  auto problem = PolynomialControls(1, sigma);
  const auto F = [](double t) { return 9 * std::pow(t, 5) / 5 - 4 * t * t * t + 4 * t + t * t * t / 3; };
  const double bounds[4] = {0.0, 0.4, 1.1, 2.0};
  double energy[3];
  for (int s = 0; s < 3; ++s) {
    energy[s] = F(bounds[s + 1]) - F(bounds[s]);
    EXPECT_NEAR(problem.ControlDerivativeEnergy(1, s), energy[s], 1e-12 * energy[s]) << s;
  }
  // Order 2: ∫ (6t)² + 1 dt = 12 t³ + t.
  EXPECT_NEAR(problem.ControlDerivativeEnergy(2, 2), 12 * (8 - 1.331) + 0.9, 1e-11);
  problem.SetControlSmoothnessSigma(1, 2 * sigma);
  const double want = 0.5 * (energy[0] + energy[1] / 4 + energy[2]) / (sigma * sigma);
  EXPECT_NEAR(TotalCost(problem.ceres_problem()), want, 1e-12 * want);
  ExpectJacobianMatchesDifferences(problem);
  EXPECT_THROW(problem.SetControlSmoothnessSigma(1, 0.0), UsageError);
  EXPECT_THROW(problem.SetControlSmoothnessSigma(3, 1.0), UsageError);
  EXPECT_THROW(problem.ControlDerivativeEnergy(0, 0), UsageError);
  PseudoSpectralProblem<UnicycleModel> bare(UnicycleModel{}, {0.0, 1.0}, 5);
  EXPECT_THROW(bare.SetControlSmoothnessSigma(0, 1.0), UsageError);  // no smoothness prior to re-weight
}

// In an orthonormal basis B of the controls (here a rotation by 30°) the prior is Σ_j ∫ |(Bᵀu)_j'|² /
// σ_j²: ControlDerivativeEnergies splits ∫ |u'|² into the components' shares (they sum to the total),
// and SetControlSmoothnessSigmas weights each. A prior on some components only is a basis of fewer
// columns (here the first: the second component is not in the prior at all). A basis that is not
// orthonormal and a σ that is not finite are rejected.
TEST(PseudoSpectralProblem, SmoothnessPriorPerComponentOfABasis) {
  const double sigma = 0.7, c = std::cos(M_PI / 6), s30 = std::sin(M_PI / 6);
  Eigen::Matrix2d B;
  B << c, -s30, s30, c;
  PseudoSpectralProblem<UnicycleModel> problem(UnicycleModel{}, {0.0, 0.4, 1.1, 2.0}, 5);
  for (int g = 0; g < problem.num_nodes(); ++g) {
    const double t = problem.NodeTime(g);
    problem.SetNode(g, Eigen::Vector4d::Zero(), Eigen::Matrix3d::Identity(), Eigen::Vector2d(t * t * t - 2 * t, 0.5 * t * t + 1));
  }
  problem.AddControlSmoothnessPrior(1, sigma, B);
  double total = 0;
  std::vector<Eigen::Vector2d> parts;
  for (int s = 0; s < 3; ++s) {
    parts.push_back(problem.ControlDerivativeEnergies(1, s, B));
    EXPECT_NEAR(parts.back().sum(), problem.ControlDerivativeEnergy(1, s), 1e-12 * parts.back().sum()) << s;
    total += parts.back().sum();
  }
  EXPECT_NEAR(TotalCost(problem.ceres_problem()), 0.5 * total / (sigma * sigma), 1e-12 * total);
  problem.SetControlSmoothnessSigmas(1, 1, Eigen::Vector2d(2 * sigma, 0.5 * sigma));
  const double want = 0.5 * (parts[0].sum() + parts[2].sum() + parts[1][0] / 4 + 4 * parts[1][1]) / (sigma * sigma);
  EXPECT_NEAR(TotalCost(problem.ceres_problem()), want, 1e-12 * want);
  ExpectJacobianMatchesDifferences(problem);
  EXPECT_THROW(problem.SetControlSmoothnessSigmas(1, 1, Eigen::Vector2d(sigma, std::numeric_limits<double>::infinity())),
               UsageError);
  EXPECT_THROW(problem.AddControlSmoothnessPrior(1, sigma, B), UsageError);  // one prior per order
  EXPECT_THROW(problem.SetControlSmoothnessSigmas(2, 0, Eigen::Vector2d(1, 1)), UsageError);  // no order-2 prior
  // Only the first component: its energy alone; removing the prior leaves no cost.
  problem.RemoveControlSmoothnessPrior(1);
  EXPECT_EQ(TotalCost(problem.ceres_problem()), 0.0);
  problem.AddControlSmoothnessPrior(1, sigma, B.leftCols<1>());
  const double first = parts[0][0] + parts[1][0] + parts[2][0];
  EXPECT_NEAR(TotalCost(problem.ceres_problem()), 0.5 * first / (sigma * sigma), 1e-12 * first);
  ExpectJacobianMatchesDifferences(problem);
  problem.RemoveControlSmoothnessPrior(1);
  EXPECT_THROW(problem.RemoveControlSmoothnessPrior(1), UsageError);
  EXPECT_THROW(problem.AddControlSmoothnessPrior(1, sigma, Eigen::Matrix2d::Constant(1.0)), UsageError);
}

// ControlRateCost on controls linear in t, u = a t + b: D U is exact, so every node's residual is
// sqrt(Δt) a / σ and a segment's N + 1 residuals sum to L a² / σ² per entry (Δt = L / (N + 1)): the
// whole cost is ½ T |a|² / σ², to rounding. Jacobians against differences; σ <= 0 rejected.
TEST(PseudoSpectralProblem, ControlRatePriorOnALinearControl) {
  PseudoSpectralProblem<UnicycleModel> problem(UnicycleModel{}, {0.0, 0.4, 1.1, 2.0}, 5);
  const Eigen::Vector2d a(1.5, -0.4), b(0.2, 3.0);
  for (int g = 0; g < problem.num_nodes(); ++g) {
    problem.SetNode(g, Eigen::Vector4d::Zero(), Eigen::Matrix3d::Identity(), a * problem.NodeTime(g) + b);
  }
  const double sigma = 0.3;
  problem.AddControlRatePrior(sigma);
  const double want = 0.5 * 2.0 * a.squaredNorm() / (sigma * sigma);
  EXPECT_NEAR(TotalCost(problem.ceres_problem()), want, 1e-12 * want);
  ExpectJacobianMatchesDifferences(problem);
  EXPECT_THROW(problem.AddControlRatePrior(0.0), UsageError);
}

// AddPrior takes any cost on the problem's blocks and RemovePrior takes it out again: a rate prior
// built by hand for one node adds exactly its own ½ |r|², and removing it restores the cost.
TEST(PseudoSpectralProblem, PriorsComeAndGoThroughOneInterface) {
  auto problem = PolynomialControls(1, 0.7);
  const double before = TotalCost(problem.ceres_problem());
  const Eigen::MatrixXd D = cheb::DifferentiationMatrix(problem.degree());
  auto cost = std::make_unique<internal::ControlRateCost<2>>(problem.SegmentOf(1), 0.7, D, 2, 0.5);
  Eigen::Vector2d r;
  std::vector<double*> blocks = cost->blocks();
  ASSERT_TRUE(cost->Evaluate(blocks.data(), r.data(), nullptr));
  const PriorId id = problem.AddPrior(std::move(cost));
  EXPECT_NEAR(TotalCost(problem.ceres_problem()), before + 0.5 * r.squaredNorm(), 1e-12 * before);
  problem.RemovePrior(id);
  EXPECT_NEAR(TotalCost(problem.ceres_problem()), before, 1e-14 * before);
}

// HoldControlEntries holds the given control entries constant: the control blocks' tangent keeps
// only the others, and a solve moves only those.
TEST(PseudoSpectralProblem, HeldControlEntriesStayConstant) {
  auto problem = PolynomialControls(1, 0.7);
  std::vector<double> held;
  for (int g = 0; g < problem.num_nodes(); ++g) held.push_back(problem.Control(g)[1]);
  problem.HoldControlEntries({1});
  EXPECT_EQ(problem.ceres_problem().ParameterBlockTangentSize(problem.Control(0)), 1);
  ceres::Solver::Options options;
  options.max_num_iterations = 5;
  problem.Solve(options);
  for (int g = 0; g < problem.num_nodes(); ++g) EXPECT_EQ(problem.Control(g)[1], held[g]) << g;
  // u0 becomes constant (its rate energy goes); u1 = 0.5 t² + 1 keeps ∫_0^2 t² dt = 8/3.
  const double want = 0.5 * (8.0 / 3.0) / (0.7 * 0.7);
  EXPECT_NEAR(TotalCost(problem.ceres_problem()), want, 1e-9 * want);
}

}  // namespace
}  // namespace cheval::estim

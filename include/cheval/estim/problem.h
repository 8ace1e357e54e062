#pragma once
/// \file
/// The pseudo-spectral continuous-time estimator of Agrawal & Dellaert (ICRA 2021) on Ceres
/// (docs/estimator.md). The time span is cut into segments [t_s, t_{s+1}]; on each, the state X and
/// the control U of a dynamics model (models.h) are polynomials of degree N held by their values at
/// the N + 1 Chebyshev–Gauss–Lobatto points (cheb/chebyshev.h). Neighbouring segments share their
/// end node, so states and controls are continuous (the "segments joined by continuity").
///
/// Parameter blocks, per node: the vector part of the state in blocks of Model::kBlockSize, a unit
/// quaternion R_world_body (RightQuaternionManifold) when Model::kHasRotation, and the control.
///
/// Rotations: each segment has a fixed reference R̄_s (SetChartReferences); inside it a rotation is
/// the chart vector φ = Log(R̄_s⁻¹ R), interpolated like any vector, R(t) = R̄_s Exp(φ(t)). Its exact
/// relation to the body rate is ω = J_r(φ) φ' (J_r the right Jacobian), not ω = φ' (which holds only
/// at φ = 0, the approximation of the paper; ESTIMATOR.md).
///
/// Residuals (all Jacobians analytic through the interpolation / differentiation rows, with the small
/// pointwise functions differentiated by ceres::Jet):
/// - AddCollocation: the defect D·X − f(X, U) at every node, weighted by 1/σ per state dimension
///   (the paper's eq. 13); for the rotation, J_r(φ_j) (D φ)_j − ω_j.
/// - AddMeasurement: h(x(t)) at any time through the barycentric row; many rows of one time
///   (e.g. all landmarks of a camera frame) are compressed to kTangent + 1 rows by a QR of their
///   Jacobian, which leaves cost, gradient and Gauss–Newton matrix unchanged; optional robust loss
///   per group of rows. (Evaluated without Jacobians, such a block returns (sqrt(cost), 0, ..., 0):
///   only its squared norm is meaningful.)
/// - AddDerivativeMeasurement: h(x'(t)) of the vector part's derivative (derivative row).
/// - AddVectorPrior / AddRotationPrior / AddControlPrior at a node.
/// - AddControlSmoothnessPrior: ∫ |u^(m)|² dt / σ², exact per segment (Gauss–Legendre), with the
///   jumps of the lower derivatives held at the breakpoints for m >= 2; SetControlSmoothnessSigma
///   re-weights one segment's integral (a σ that varies along the span), ControlDerivativeEnergy
///   returns ∫_s |u^(m)|² dt of the current controls; AddControlRatePrior: the
///   older equal-weight sum of (D U)_j² at the nodes (not a quadrature: kept for existing callers).

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <utility>
#include <vector>

#include <ceres/ceres.h>
#include <ceres/jet.h>
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/QR>

#include "cheval/cheb/chebyshev.h"
#include "cheval/cheb/quadrature.h"
#include "cheval/common/error.h"
#include "cheval/estim/manifold.h"
#include "cheval/lie/so3.h"

namespace cheval::estim {

/// The state of a model at one time: the vector part, the rotation (identity without one) and the
/// control.
struct StateSample {
  Eigen::VectorXd vector;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::VectorXd control;
};

namespace detail {

/// Where a time falls: its segment and the interpolation / derivative rows there (derivative in t).
struct TimeRow {
  int segment = 0;
  Eigen::RowVectorXd w;   ///< x(t) = Σ_k w_k X_k
  Eigen::RowVectorXd dw;  ///< x'(t) = Σ_k dw_k X_k (already scaled by 2 / (t1 - t0))
};

inline Eigen::Matrix3d QuaternionMatrix(const double* q) {
  return Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized().toRotationMatrix();
}

}  // namespace detail

/// A pseudo-spectral estimation problem for `Model` (see models.h for the requirements).
template <class Model>
class PseudoSpectralProblem {
 public:
  static constexpr int kVector = Model::kVectorDim;
  static constexpr int kBlock = Model::kBlockSize;
  static constexpr int kBlocks = kVector / kBlock;
  static constexpr bool kRotation = Model::kHasRotation;
  static constexpr int kControl = Model::kControlDim;
  /// Tangent dimension of the state: vector part + 3 for the rotation.
  static constexpr int kTangent = kVector + (kRotation ? 3 : 0);
  static_assert(kVector % kBlock == 0, "kBlockSize must divide kVectorDim");

  /// Segments [breakpoints[s], breakpoints[s+1]] (seconds, strictly increasing, at least 2 values),
  /// each a polynomial of `degree` (>= 2). Throws UsageError otherwise. Nodes are numbered globally
  /// in increasing time: node s·N + i is the i-th point of segment s from its start.
  PseudoSpectralProblem(Model model, std::vector<double> breakpoints, int degree)
      : model_(std::move(model)), breakpoints_(std::move(breakpoints)), degree_(degree), basis_(std::max(degree, 1)) {
    if (degree < 2) throw UsageError(fmt::format("--degree must be >= 2, got {}", degree));
    if (breakpoints_.size() < 2) throw UsageError("a problem needs at least one segment");
    for (size_t s = 0; s + 1 < breakpoints_.size(); ++s) {
      if (!(breakpoints_[s + 1] > breakpoints_[s]) || !std::isfinite(breakpoints_[s + 1] - breakpoints_[s])) {
        throw UsageError("segment breakpoints must be finite and strictly increasing");
      }
    }
    D_ = cheb::DifferentiationMatrix(degree);
    const int nodes = num_nodes();
    vector_.assign(static_cast<size_t>(nodes) * kVector, 0.0);
    quaternion_.assign(static_cast<size_t>(nodes) * 4, 0.0);
    for (int g = 0; g < nodes; ++g) quaternion_[4 * g + 3] = 1.0;
    control_.assign(static_cast<size_t>(nodes) * kControl, 0.0);
    references_.assign(num_segments(), Eigen::Matrix3d::Identity());
    manifold_set_.assign(nodes, false);
    ceres::Problem::Options options;
    options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    problem_ = std::make_unique<ceres::Problem>(options);
  }

  /// The dynamics model.
  const Model& model() const { return model_; }
  /// Polynomial degree N of every segment.
  int degree() const { return degree_; }
  /// Number of segments.
  int num_segments() const { return static_cast<int>(breakpoints_.size()) - 1; }
  /// Distinct nodes (states): segments · N + 1.
  int num_nodes() const { return num_segments() * degree_ + 1; }
  /// First and last time of the estimated interval, s.
  double start_time() const { return breakpoints_.front(); }
  double end_time() const { return breakpoints_.back(); }
  /// Segment boundaries t_0 < ... < t_S.
  const std::vector<double>& breakpoints() const { return breakpoints_; }
  /// The underlying Ceres problem (for evaluation, covariance, custom residuals).
  ceres::Problem& ceres_problem() { return *problem_; }

  /// Time of global node g.
  double NodeTime(int g) const {
    const int s = std::min(g / degree_, num_segments() - 1);
    return Interval(s).FromUnit(basis_.points()[degree_ - (g - s * degree_)]);
  }

  /// Storage of node g (valid for the problem's lifetime).
  double* Vector(int g) { return &vector_[static_cast<size_t>(g) * kVector]; }
  double* Quaternion(int g) { return &quaternion_[static_cast<size_t>(g) * 4]; }  ///< x, y, z, w
  double* Control(int g) { return &control_[static_cast<size_t>(g) * kControl]; }
  const double* Vector(int g) const { return &vector_[static_cast<size_t>(g) * kVector]; }
  const double* Quaternion(int g) const { return &quaternion_[static_cast<size_t>(g) * 4]; }
  const double* Control(int g) const { return &control_[static_cast<size_t>(g) * kControl]; }

  /// Sets node g (initial values). `rotation` is ignored without a rotation.
  void SetNode(int g, const Eigen::VectorXd& vector, const Eigen::Matrix3d& rotation, const Eigen::VectorXd& control) {
    Eigen::Map<Eigen::VectorXd>(Vector(g), kVector) = vector;
    Eigen::Map<Eigen::Vector4d>(Quaternion(g)) = Eigen::Quaterniond(rotation).normalized().coeffs();
    Eigen::Map<Eigen::VectorXd>(Control(g), kControl) = control;
  }

  /// Fixes each segment's chart reference to the current rotation of its middle node. Call after the
  /// initial values are set and before adding residuals (the charts must stay within π of every
  /// rotation of their segment: short segments).
  void SetChartReferences() {
    for (int s = 0; s < num_segments(); ++s) references_[s] = detail::QuaternionMatrix(Quaternion(s * degree_ + degree_ / 2));
  }

  /// The segment of t and its rows. Throws ComputeError when t is outside [start_time, end_time].
  detail::TimeRow RowAt(double t) const {
    if (!(t >= breakpoints_.front() && t <= breakpoints_.back())) {
      throw ComputeError(fmt::format("time {:.6f} s is outside the estimated interval [{:.6f}, {:.6f}] s", t,
                                     breakpoints_.front(), breakpoints_.back()));
    }
    const int s = std::clamp(
        static_cast<int>(std::upper_bound(breakpoints_.begin(), breakpoints_.end(), t) - breakpoints_.begin()) - 1, 0,
        num_segments() - 1);
    detail::TimeRow row;
    row.segment = s;
    row.w.resize(degree_ + 1);
    row.dw.resize(degree_ + 1);
    const double x = std::clamp(Interval(s).ToUnit(t), -1.0, 1.0);
    basis_.InterpolationRow(x, row.w);
    basis_.DerivativeRow(x, row.dw);
    row.dw *= Interval(s).DerivativeScale();
    return row;
  }

  /// Global node of point k (descending Chebyshev order, k = 0 is the segment's end) of segment s.
  int NodeOf(int s, int k) const { return s * degree_ + (degree_ - k); }

  /// The interpolated state and control at t (ComputeError outside the interval).
  StateSample Interpolate(double t) const {
    const detail::TimeRow row = RowAt(t);
    StateSample out;
    out.vector = Eigen::VectorXd::Zero(kVector);
    out.control = Eigen::VectorXd::Zero(kControl);
    Eigen::Vector3d phi = Eigen::Vector3d::Zero();
    for (int k = 0; k <= degree_; ++k) {
      const int g = NodeOf(row.segment, k);
      out.vector += row.w[k] * Eigen::Map<const Eigen::VectorXd>(Vector(g), kVector);
      out.control += row.w[k] * Eigen::Map<const Eigen::VectorXd>(Control(g), kControl);
      if constexpr (kRotation) phi += row.w[k] * Chart(row.segment, g);
    }
    if constexpr (kRotation) out.rotation = references_[row.segment] * lie::SO3d::Exp(phi).Matrix();
    return out;
  }

  /// Adds the collocation defects of every node of every segment, weighted by 1/sigma (kTangent
  /// entries, > 0: vector part then rotation, in the units of x').
  void AddCollocation(const Eigen::Matrix<double, kTangent, 1>& sigma) {
    for (int i = 0; i < kTangent; ++i) {
      if (!(sigma[i] > 0)) throw UsageError("collocation sigmas must be > 0");
    }
    constexpr int kParts = kBlocks + (kRotation ? 1 : 0);
    for (int s = 0; s < num_segments(); ++s) {
      for (int j = 0; j <= degree_; ++j) {
        for (int part = 0; part < kParts; ++part) {
          auto* cost = new CollocationCost(this, s, j, part, sigma);
          problem_->AddResidualBlock(cost, nullptr, cost->blocks());
        }
      }
      if constexpr (kRotation) {
        for (int k = 0; k <= degree_; ++k) UseManifold(NodeOf(s, k));
      }
    }
  }

  /// Adds a smoothness prior on the control: at every node j of every segment, the residual
  /// sqrt(Δt_j) (D U)_j / sigma with Δt_j = (t1 − t0)/(N + 1), a quadrature of ∫ |u'(t)|² dt / sigma² (a
  /// white-noise prior on u', the continuous-time prior of GP smoothing). sigma > 0, in control units
  /// per s^(1/2) per s.
  void AddControlRatePrior(double sigma) {
    if (!(sigma > 0)) throw UsageError("the control-rate sigma must be > 0");
    for (int s = 0; s < num_segments(); ++s) {
      for (int j = 0; j <= degree_; ++j) {
        auto* cost = new ControlRateCost(this, s, j, sigma);
        problem_->AddResidualBlock(cost, nullptr, cost->blocks());
      }
    }
  }

  /// Adds the smoothness prior ∫ |u^(m)(t)|² dt / sigma² over [start_time, end_time] on the control:
  /// the white-noise-on-u^(m) prior of GP smoothing (m = 1: u a random walk; m = 2: u an integrated
  /// random walk, its rate a random walk — the rotor-acceleration prior). Per segment the integral
  /// is exact: u^(m) is a polynomial of degree N − m, so Gauss–Legendre quadrature with N − m + 1
  /// points integrates its square exactly; one residual block per segment, sqrt(w_q L/2) u^(m)(t_q)/σ
  /// at each quadrature point. For m >= 2 the GP's u', ..., u^(m−1) are continuous: at every inner
  /// breakpoint the jump of u^(i) between the two segments gets the residual jump/σ_i with σ_i² the
  /// prior variance of the change of u^(i) over the shortest node spacing h there (σ² h^(2(m−i)−1)
  /// up to the integrated-Wiener constant, taken as 1), so the jump is held to what the prior allows
  /// across one node step. order in [1, min(3, N)], sigma > 0 (control units per s^m per s^(1/2)).
  void AddControlSmoothnessPrior(int order, double sigma) {
    AddControlSmoothnessPrior(order, sigma, Eigen::Matrix<double, kControl, kControl>::Identity());
  }

  /// The same prior on the components c = Bᵀ u of the control in an orthonormal `basis` B (columns:
  /// the components; e.g. the collective and differential rotor speeds), so that each component
  /// can get its own σ (SetControlSmoothnessSigmas). With B = I it is the prior above. One prior per
  /// order: adding an order again replaces its bookkeeping (the old residuals stay). Throws
  /// UsageError for a basis that is not orthonormal (1e-9).
  void AddControlSmoothnessPrior(int order, double sigma, const Eigen::Matrix<double, kControl, kControl>& basis) {
    if (order < 1 || order > std::min(3, degree_)) {
      throw UsageError(fmt::format("the control smoothness order must be in [1, {}], got {}", std::min(3, degree_), order));
    }
    if (!(sigma > 0)) throw UsageError("the control smoothness sigma must be > 0");
    if (!(basis.transpose() * basis).isIdentity(1e-9)) throw UsageError("the control smoothness basis must be orthonormal");
    const int N = degree_;
    SmoothnessPrior& prior = smoothness_[order];
    prior = SmoothnessPrior{};
    prior.sigma = sigma;
    prior.basis = basis;
    prior.segment_sigma.assign(num_segments(), Eigen::Matrix<double, kControl, 1>::Constant(sigma));
    for (int s = 0; s < num_segments(); ++s) {
      std::vector<int> nodes;
      for (int k = 0; k <= N; ++k) nodes.push_back(NodeOf(s, k));
      auto* cost = new LinearControlCost(this, nodes, SmoothnessRows(order, s), basis);
      cost->set_weight(1.0 / sigma);
      problem_->AddResidualBlock(cost, nullptr, cost->blocks());
      prior.segments.push_back(cost);
    }
    if (first_order_ == 0) first_order_ = order;
    // Continuity of u', ..., u^(m-1) at the inner breakpoints.
    for (int s = 0; order > 1 && s + 1 < num_segments(); ++s) {
      std::vector<int> nodes;
      for (int g = s * N; g <= (s + 2) * N; ++g) nodes.push_back(g);
      auto* cost = new LinearControlCost(this, nodes, SmoothnessJumpMatrix(order, s, sigma), basis);
      problem_->AddResidualBlock(cost, nullptr, cost->blocks());
      prior.jumps.push_back(cost);
    }
  }

  /// Replaces σ of segment s's integral ∫_s |u^(m)|² dt / σ² of AddControlSmoothnessPrior (which must
  /// have been called; the first order added): a prior whose intensity varies along the span
  /// (heteroscedastic). For m >= 2 the jump residuals at the segment's breakpoints take the geometric
  /// mean of the two segments' σ. Takes effect at the next Solve. Throws UsageError for sigma <= 0, a
  /// segment out of range or no smoothness prior.
  void SetControlSmoothnessSigma(int s, double sigma) {
    if (first_order_ == 0) throw UsageError("no control smoothness prior to re-weight");
    SetControlSmoothnessSigmas(first_order_, s, Eigen::Matrix<double, kControl, 1>::Constant(sigma));
  }

  /// σ per component (of the prior's basis) of segment s's integral of the order-m prior.
  void SetControlSmoothnessSigmas(int order, int s, const Eigen::Matrix<double, kControl, 1>& sigma) {
    auto it = smoothness_.find(order);
    if (it == smoothness_.end()) throw UsageError("no control smoothness prior to re-weight");
    if (s < 0 || s >= num_segments()) throw UsageError(fmt::format("segment {} out of range [0, {})", s, num_segments()));
    if (!(sigma.minCoeff() > 0)) throw UsageError("the control smoothness sigma must be > 0");
    SmoothnessPrior& prior = it->second;
    prior.segment_sigma[s] = sigma;
    prior.segments[s]->set_weights(sigma.cwiseInverse());
    for (int j = std::max(s - 1, 0); j <= std::min<int>(s, static_cast<int>(prior.jumps.size()) - 1); ++j) {
      const Eigen::Matrix<double, kControl, 1> mean =
          prior.segment_sigma[j].cwiseProduct(prior.segment_sigma[j + 1]).cwiseSqrt();
      prior.jumps[j]->set_weights(prior.sigma * mean.cwiseInverse());
    }
  }

  /// ∫ |u^(m)(t)|² dt over segment s of the current controls, summed over the control entries
  /// (exact: Gauss–Legendre with N − m + 1 points). order in [1, N]; UsageError otherwise.
  double ControlDerivativeEnergy(int order, int s) const {
    return ControlDerivativeEnergies(order, s, Eigen::Matrix<double, kControl, kControl>::Identity()).sum();
  }

  /// The same per component c_j = B_jᵀ u of an orthonormal basis B (they sum to the total).
  Eigen::Matrix<double, kControl, 1> ControlDerivativeEnergies(int order, int s,
                                                               const Eigen::Matrix<double, kControl, kControl>& basis) const {
    if (order < 1 || order > degree_) throw UsageError(fmt::format("the derivative order must be in [1, {}]", degree_));
    if (s < 0 || s >= num_segments()) throw UsageError(fmt::format("segment {} out of range [0, {})", s, num_segments()));
    const Eigen::MatrixXd C = SmoothnessRows(order, s);
    Eigen::MatrixXd U(degree_ + 1, kControl);
    for (int k = 0; k <= degree_; ++k) U.row(k) = Eigen::Map<const Eigen::Matrix<double, 1, kControl>>(Control(NodeOf(s, k)));
    return (C * U * basis).colwise().squaredNorm().transpose();
  }

  /// The rows of ∫_s |u^(m)|² dt (rows x N + 1 nodes of segment s, point order k = 0..N): the
  /// energy of a control entry is |C U|².
  Eigen::MatrixXd SmoothnessMatrix(int order, int s, int points = 0) const { return SmoothnessRows(order, s, points); }

  /// The jump rows of the order-m prior with σ at the breakpoint between segments s and s + 1
  /// (order − 1 rows over the global nodes s·N .. (s + 2)·N, in that order); empty for m = 1.
  Eigen::MatrixXd SmoothnessJumpMatrix(int order, int s, double sigma) const {
    const int N = degree_;
    const double h_unit = 1.0 - basis_.points()[1];
    const double scale_a = Interval(s).DerivativeScale(), scale_b = Interval(s + 1).DerivativeScale();
    const double h = std::min(h_unit / scale_a, h_unit / scale_b);
    Eigen::MatrixXd coefficients = Eigen::MatrixXd::Zero(order - 1, 2 * N + 1);
    Eigen::MatrixXd Di = Eigen::MatrixXd::Identity(N + 1, N + 1);
    for (int i = 1; i < order; ++i) {
      Di = D_ * Di;
      const double sigma_i = sigma * std::pow(h, order - i - 0.5);
      // Segment s ends at its point k = 0 (global node (s + 1) N); segment s + 1 starts at its point k = N.
      for (int k = 0; k <= N; ++k) {
        coefficients(i - 1, NodeOf(s, k) - s * N) += std::pow(scale_a, i) * Di(0, k) / sigma_i;
        coefficients(i - 1, NodeOf(s + 1, k) - s * N) -= std::pow(scale_b, i) * Di(N, k) / sigma_i;
      }
    }
    return coefficients;
  }

  /// Adds the measurement residual h(x(t)) at time t. `F` has
  /// `template <class T> bool operator()(const T* x, const Eigen::Matrix<T,3,3>& R, T* residual) const`
  /// returning `rows` residuals (already whitened), in groups of `group_rows` rows sharing one robust
  /// `loss` (may be null; the problem does not own it). `used_blocks` lists the vector blocks h
  /// depends on (the rotation is always included when the model has one). Throws ComputeError when t
  /// is outside the interval.
  template <class F>
  void AddMeasurement(double t, F functor, int rows, int group_rows, const std::vector<int>& used_blocks,
                      const ceres::LossFunction* loss = nullptr) {
    auto* cost = new MeasurementCost<F>(this, RowAt(t), std::move(functor), rows, group_rows, used_blocks, loss);
    problem_->AddResidualBlock(cost, cost->ceres_loss(), cost->blocks());
    if constexpr (kRotation) {
      for (int k = 0; k <= degree_; ++k) UseManifold(NodeOf(cost->segment(), k));
    }
  }

  /// Adds a residual h(x'(t)) of the vector part's derivative at t. `F` has
  /// `template <class T> bool operator()(const T* x_dot, T* residual) const` with `rows` residuals.
  template <class F>
  void AddDerivativeMeasurement(double t, F functor, int rows, ceres::LossFunction* loss = nullptr) {
    auto* cost = new DerivativeCost<F>(this, RowAt(t), std::move(functor), rows);
    problem_->AddResidualBlock(cost, loss, cost->blocks());
  }

  /// Prior (x_b − mean)/sigma on vector block b of node g.
  void AddVectorPrior(int g, int block, const Eigen::VectorXd& mean, double sigma) {
    auto* cost = new ceres::AutoDiffCostFunction<VectorPrior, kBlock, kBlock>(new VectorPrior{mean, sigma});
    problem_->AddResidualBlock(cost, nullptr, Vector(g) + block * kBlock);
  }
  /// Prior Log(mean⁻¹ R_g)/sigma on the rotation of node g.
  void AddRotationPrior(int g, const Eigen::Matrix3d& mean, double sigma) {
    auto* cost = new ceres::AutoDiffCostFunction<RotationPrior, 3, 4>(new RotationPrior{Eigen::Quaterniond(mean), sigma});
    problem_->AddResidualBlock(cost, nullptr, Quaternion(g));
    UseManifold(g);
  }
  /// Prior (u_g − mean)/sigma on the control of node g.
  void AddControlPrior(int g, const Eigen::VectorXd& mean, double sigma) {
    auto* cost = new ceres::AutoDiffCostFunction<ControlPrior, kControl, kControl>(new ControlPrior{mean, sigma});
    problem_->AddResidualBlock(cost, nullptr, Control(g));
  }

  /// Chart vector φ = Log(R̄_s⁻¹ R_g) of node g in segment s's chart.
  Eigen::Vector3d Chart(int s, int g) const {
    return lie::SO3d(Eigen::Matrix3d(references_[s].transpose() * detail::QuaternionMatrix(Quaternion(g)))).Log();
  }

  /// Runs Ceres. The quaternions are re-normalised afterwards.
  ceres::Solver::Summary Solve(const ceres::Solver::Options& options) {
    ceres::Solver::Summary summary;
    ceres::Solve(options, problem_.get(), &summary);
    for (int g = 0; g < num_nodes(); ++g) Eigen::Map<Eigen::Vector4d>(Quaternion(g)).normalize();
    return summary;
  }

 private:
  // Rows sqrt(w_q L/2) u^(m)(t_q) over the controls of segment s in point order k = 0..N: their
  // squared sum is ∫_s |u^(m)|² dt, exactly (Gauss–Legendre with N − m + 1 points).
  Eigen::MatrixXd SmoothnessRows(int order, int s, int points = 0) const {
    const int N = degree_;
    Eigen::MatrixXd Dm = Eigen::MatrixXd::Identity(N + 1, N + 1);
    for (int i = 0; i < order; ++i) Dm = D_ * Dm;
    const int nq = points > 0 ? points : N - order + 1;
    const cheb::QuadratureRule rule = cheb::GaussLegendre(nq);
    const Eigen::VectorXd& xq = rule.nodes;
    const Eigen::VectorXd& wq = rule.weights;
    Eigen::RowVectorXd row(N + 1);
    const double length = breakpoints_[s + 1] - breakpoints_[s];
    const double scale = std::pow(Interval(s).DerivativeScale(), order);
    Eigen::MatrixXd coefficients(nq, N + 1);
    for (int q = 0; q < nq; ++q) {
      basis_.InterpolationRow(xq[q], row);
      coefficients.row(q) = std::sqrt(wq[q] * length / 2) * scale * (row * Dm);
    }
    return coefficients;
  }

  // Puts node g's quaternion on the manifold once (the block must already be in the problem).
  void UseManifold(int g) {
    if (manifold_set_[g]) return;
    problem_->SetManifold(Quaternion(g), &manifold_);
    manifold_set_[g] = true;
  }

  cheb::Interval Interval(int s) const { return {breakpoints_[s], breakpoints_[s + 1]}; }

  // The chart data of segment s: φ_k, J_r⁻¹(φ_k) for k = 0..N.
  struct Charts {
    std::vector<Eigen::Vector3d> phi;
    std::vector<Eigen::Matrix3d> jr_inv;
  };
  Charts ComputeCharts(int s, double const* const* quaternions) const {
    Charts c;
    c.phi.resize(degree_ + 1);
    c.jr_inv.resize(degree_ + 1);
    for (int k = 0; k <= degree_; ++k) {
      c.phi[k] = lie::SO3d(Eigen::Matrix3d(references_[s].transpose() * detail::QuaternionMatrix(quaternions[k]))).Log();
      c.jr_inv[k] = lie::SO3d::InverseRightJacobian(c.phi[k]);
    }
    return c;
  }

  // Defect of one part (a vector block, or the rotation) at node j of segment s.
  class CollocationCost : public ceres::CostFunction {
   public:
    CollocationCost(const PseudoSpectralProblem* p, int s, int j, int part, const Eigen::Matrix<double, kTangent, 1>& sigma)
        : p_(p), s_(s), j_(j), part_(part), rotation_part_(part == kBlocks) {
      const int N = p->degree_;
      const int g = p->NodeOf(s, j);
      auto* self = const_cast<PseudoSpectralProblem*>(p);
      rows_ = rotation_part_ ? 3 : kBlock;
      for (int k = 0; k <= N; ++k) {
        const int gk = p->NodeOf(s, k);
        blocks_.push_back(rotation_part_ ? self->Quaternion(gk) : self->Vector(gk) + part * kBlock);
        mutable_parameter_block_sizes()->push_back(rotation_part_ ? 4 : kBlock);
      }
      for (int b = 0; b < kBlocks; ++b) {
        if (!rotation_part_ && b == part) continue;
        local_blocks_.push_back(b);
        blocks_.push_back(self->Vector(g) + b * kBlock);
        mutable_parameter_block_sizes()->push_back(kBlock);
      }
      if (kRotation && !rotation_part_) {
        blocks_.push_back(self->Quaternion(g));
        mutable_parameter_block_sizes()->push_back(4);
      }
      blocks_.push_back(self->Control(g));
      mutable_parameter_block_sizes()->push_back(kControl);
      set_num_residuals(rows_);
      const int offset = rotation_part_ ? kVector : part * kBlock;
      inv_sigma_ = sigma.segment(offset, rows_).cwiseInverse();
    }
    const std::vector<double*>& blocks() const { return blocks_; }

    bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
      const int N = p_->degree_;
      const double scale = p_->Interval(s_).DerivativeScale();
      // Node j's full state and control, from the parameter blocks of this residual.
      Eigen::Matrix<double, kVector, 1> x;
      const double* q_j = nullptr;
      int next = N + 1;
      if (rotation_part_) {
        for (int b = 0; b < kBlocks; ++b) std::copy_n(parameters[next++], kBlock, x.data() + b * kBlock);
        q_j = parameters[j_];
      } else {
        std::copy_n(parameters[j_], kBlock, x.data() + part_ * kBlock);
        for (int b : local_blocks_) std::copy_n(parameters[next++], kBlock, x.data() + b * kBlock);
        if (kRotation) q_j = parameters[next++];
      }
      const double* u = parameters[next];
      if (jacobians == nullptr && !rotation_part_) {  // residual only: f in doubles
        double xdot_d[kVector], omega_d[3];
        const Eigen::Matrix3d Rj = kRotation ? detail::QuaternionMatrix(q_j) : Eigen::Matrix3d::Identity();
        p_->model_.Dynamics(x.data(), Rj, u, xdot_d, omega_d);
        Eigen::Matrix<double, kBlock, 1> r = -Eigen::Map<const Eigen::Matrix<double, kBlock, 1>>(xdot_d + part_ * kBlock);
        for (int k = 0; k <= N; ++k) {
          r += scale * p_->D_(j_, k) * Eigen::Map<const Eigen::Matrix<double, kBlock, 1>>(parameters[k]);
        }
        Eigen::Map<Eigen::VectorXd>{residuals, rows_} = inv_sigma_.cwiseProduct(r);
        return true;
      }
      // f and its Jacobian with respect to (x, δ, u) by Jets.
      using Jet = ceres::Jet<double, kTangent + kControl>;
      Jet xj[kVector], uj[kControl], xdot[kVector], omega[3];
      for (int i = 0; i < kVector; ++i) xj[i] = Jet(x[i], i);
      for (int i = 0; i < kControl; ++i) uj[i] = Jet(u[i], kTangent + i);
      Eigen::Matrix<Jet, 3, 3> R = Eigen::Matrix<Jet, 3, 3>::Identity();
      if constexpr (kRotation) {
        Eigen::Matrix<Jet, 3, 1> delta;
        for (int i = 0; i < 3; ++i) delta[i] = Jet(0.0, kVector + i);
        R = detail::QuaternionMatrix(q_j).template cast<Jet>() * lie::SO3<Jet>::Exp(delta).Matrix();
      }
      p_->model_.Dynamics(xj, R, uj, xdot, omega);
      const Jet* f = rotation_part_ ? omega : xdot + part_ * kBlock;
      Eigen::Matrix<double, Eigen::Dynamic, kTangent + kControl> df(rows_, kTangent + kControl);
      Eigen::VectorXd r(rows_);
      for (int i = 0; i < rows_; ++i) {
        r[i] = -f[i].a;
        df.row(i) = f[i].v.transpose();
      }
      Charts charts;
      Eigen::Matrix3d jr_j = Eigen::Matrix3d::Identity(), djr = Eigen::Matrix3d::Zero();
      if (rotation_part_) {
        charts = p_->ComputeCharts(s_, parameters);
        Eigen::Vector3d phi_dot = Eigen::Vector3d::Zero();
        for (int k = 0; k <= N; ++k) phi_dot += scale * p_->D_(j_, k) * charts.phi[k];
        // J_r(φ_j) φ'_j and its derivative in φ_j (Jets).
        using Jet3 = ceres::Jet<double, 3>;
        Eigen::Matrix<Jet3, 3, 1> phi_j;
        for (int i = 0; i < 3; ++i) phi_j[i] = Jet3(charts.phi[j_][i], i);
        const Eigen::Matrix<Jet3, 3, 1> rate = lie::SO3<Jet3>::RightJacobian(phi_j) * phi_dot.cast<Jet3>();
        for (int i = 0; i < 3; ++i) {
          r[i] += rate[i].a;
          djr.row(i) = rate[i].v.transpose();
        }
        jr_j = lie::SO3d::RightJacobian(charts.phi[j_]);
      } else {
        for (int k = 0; k <= N; ++k) {
          r += scale * p_->D_(j_, k) * Eigen::Map<const Eigen::Matrix<double, kBlock, 1>>(parameters[k]);
        }
      }
      Eigen::Map<Eigen::VectorXd>(residuals, rows_) = inv_sigma_.cwiseProduct(r);
      if (jacobians == nullptr) return true;
      const auto W = inv_sigma_.asDiagonal();
      for (int k = 0; k <= N; ++k) {
        if (jacobians[k] == nullptr) continue;
        if (rotation_part_) {
          Eigen::Matrix3d J = jr_j * (scale * p_->D_(j_, k)) * charts.jr_inv[k];
          if (k == j_) J += djr * charts.jr_inv[k] - df.template block<3, 3>(0, kVector);
          const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> Jw = W * J;
          LiftRotationJacobian(parameters[k], Jw.data(), 3, jacobians[k]);
        } else {
          Eigen::Matrix<double, kBlock, kBlock> J =
              (scale * p_->D_(j_, k)) * Eigen::Matrix<double, kBlock, kBlock>::Identity();
          if (k == j_) J -= df.template block<kBlock, kBlock>(0, part_ * kBlock);
          Eigen::Map<Eigen::Matrix<double, kBlock, kBlock, Eigen::RowMajor>>{jacobians[k]} = W * J;
        }
      }
      next = N + 1;
      auto map = [&](int index, int cols) {
        return Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(jacobians[index],
                                                                                                 rows_, cols);
      };
      if (rotation_part_) {
        for (int b = 0; b < kBlocks; ++b, ++next) {
          if (jacobians[next]) map(next, kBlock) = -(W * df.block(0, b * kBlock, rows_, kBlock));
        }
      } else {
        for (int b : local_blocks_) {
          if (jacobians[next]) map(next, kBlock) = -(W * df.block(0, b * kBlock, rows_, kBlock));
          ++next;
        }
        if (kRotation) {
          if (jacobians[next]) {
            const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> Jd = -(W * df.block(0, kVector, rows_, 3));
            LiftRotationJacobian(q_j, Jd.data(), rows_, jacobians[next]);
          }
          ++next;
        }
      }
      if (jacobians[next]) map(next, kControl) = -(W * df.block(0, kTangent, rows_, kControl));
      return true;
    }

   private:
    const PseudoSpectralProblem* p_;
    int s_, j_, part_;
    bool rotation_part_;
    int rows_ = 0;
    std::vector<int> local_blocks_;
    std::vector<double*> blocks_;
    Eigen::VectorXd inv_sigma_;
  };

  // sqrt(Δt) (D U)_j / σ: linear in the N + 1 controls of the segment.
  class ControlRateCost : public ceres::CostFunction {
   public:
    ControlRateCost(PseudoSpectralProblem* p, int s, int j, double sigma) {
      const double length = p->breakpoints_[s + 1] - p->breakpoints_[s];
      const double factor = std::sqrt(length / (p->degree_ + 1)) * p->Interval(s).DerivativeScale() / sigma;
      for (int k = 0; k <= p->degree_; ++k) {
        blocks_.push_back(p->Control(p->NodeOf(s, k)));
        mutable_parameter_block_sizes()->push_back(kControl);
        coefficients_.push_back(factor * p->D_(j, k));
      }
      set_num_residuals(kControl);
    }
    const std::vector<double*>& blocks() const { return blocks_; }
    bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
      for (int i = 0; i < kControl; ++i) residuals[i] = 0;
      for (size_t k = 0; k < coefficients_.size(); ++k) {
        for (int i = 0; i < kControl; ++i) residuals[i] += coefficients_[k] * parameters[k][i];
        if (jacobians && jacobians[k]) {
          Eigen::Map<Eigen::Matrix<double, kControl, kControl, Eigen::RowMajor>> J(jacobians[k]);
          J = coefficients_[k] * Eigen::Matrix<double, kControl, kControl>::Identity();
        }
      }
      return true;
    }

   private:
    std::vector<double*> blocks_;
    std::vector<double> coefficients_;
  };

  // Rows w_j (C·U·B)_{q j} (C: rows x nodes, U: nodes x controls, B: an orthonormal basis of the
  // controls, w_j a weight per component), linear in the controls of the given nodes.
  class LinearControlCost : public ceres::CostFunction {
   public:
    LinearControlCost(PseudoSpectralProblem* p, const std::vector<int>& nodes, Eigen::MatrixXd coefficients,
                      const Eigen::Matrix<double, kControl, kControl>& basis =
                          Eigen::Matrix<double, kControl, kControl>::Identity())
        : coefficients_(std::move(coefficients)), basis_(basis) {
      for (int g : nodes) {
        blocks_.push_back(p->Control(g));
        mutable_parameter_block_sizes()->push_back(kControl);
      }
      set_num_residuals(static_cast<int>(coefficients_.rows()) * kControl);
      weights_.setOnes();
    }
    const std::vector<double*>& blocks() const { return blocks_; }
    /// A factor on every row (1/σ of a smoothness prior).
    void set_weight(double weight) { weights_.setConstant(weight); }
    /// A factor per component (1/σ_j).
    void set_weights(const Eigen::Matrix<double, kControl, 1>& weights) { weights_ = weights; }
    bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
      const int rows = static_cast<int>(coefficients_.rows());
      const Eigen::Matrix<double, kControl, kControl> WB = basis_ * weights_.asDiagonal();  // u -> weighted components
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, kControl, Eigen::RowMajor>> r(residuals, rows, kControl);
      r.setZero();
      for (int k = 0; k < static_cast<int>(blocks_.size()); ++k) {
        r += coefficients_.col(k) * (Eigen::Map<const Eigen::Matrix<double, 1, kControl>>(parameters[k]) * WB);
        if (jacobians && jacobians[k]) {
          // Residual (q, j) depends on u_k[i] with coefficient C(q, k) (B W)(i, j).
          Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, kControl, Eigen::RowMajor>> J(jacobians[k], rows * kControl,
                                                                                         kControl);
          for (int q = 0; q < rows; ++q) J.template middleRows<kControl>(q * kControl) = coefficients_(q, k) * WB.transpose();
        }
      }
      return true;
    }

   private:
    std::vector<double*> blocks_;
    Eigen::MatrixXd coefficients_;
    Eigen::Matrix<double, kControl, kControl> basis_;
    Eigen::Matrix<double, kControl, 1> weights_;
  };

  // h(x(t)): parameter blocks are the used vector blocks and the rotation of every node of the segment.
  template <class F>
  class MeasurementCost : public ceres::CostFunction {
   public:
    MeasurementCost(PseudoSpectralProblem* p, detail::TimeRow row, F functor, int rows, int group_rows,
                    std::vector<int> used, const ceres::LossFunction* loss)
        : p_(p), row_(std::move(row)), f_(std::move(functor)), rows_(rows), group_rows_(group_rows),
          used_(std::move(used)), loss_(loss) {
      if (rows_ < 1 || group_rows_ < 1 || rows_ % group_rows_ != 0) {
        throw UsageError("measurement rows must be a positive multiple of the group size");
      }
      for (int b : used_) {
        if (b < 0 || b >= kBlocks) throw UsageError("measurement uses a vector block that does not exist");
      }
      used_dim_ = static_cast<int>(used_.size()) * kBlock + (kRotation ? 3 : 0);
      compress_ = rows_ > used_dim_ + 1;
      set_num_residuals(compress_ ? used_dim_ + 1 : rows_);
      for (int k = 0; k <= p->degree_; ++k) {
        const int g = p->NodeOf(row_.segment, k);
        for (int b : used_) {
          blocks_.push_back(p->Vector(g) + b * kBlock);
          mutable_parameter_block_sizes()->push_back(kBlock);
        }
        if (kRotation) {
          blocks_.push_back(p->Quaternion(g));
          mutable_parameter_block_sizes()->push_back(4);
        }
      }
    }
    const std::vector<double*>& blocks() const { return blocks_; }
    int segment() const { return row_.segment; }
    /// The loss Ceres applies: only when the rows are not compressed (then the loss is per block).
    ceres::LossFunction* ceres_loss() const { return compress_ ? nullptr : const_cast<ceres::LossFunction*>(loss_); }

    bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
      const int N = p_->degree_;
      const int per_node = static_cast<int>(used_.size()) + (kRotation ? 1 : 0);
      // Interpolated state: used blocks from the parameters, the others from the problem's storage.
      Eigen::Matrix<double, kVector, 1> x = Eigen::Matrix<double, kVector, 1>::Zero();
      Eigen::Vector3d phi = Eigen::Vector3d::Zero();
      std::vector<Eigen::Vector3d> phis;
      std::vector<Eigen::Matrix3d> jr_inv;
      if constexpr (kRotation) {
        phis.resize(N + 1);
        jr_inv.resize(N + 1);
      }
      for (int k = 0; k <= N; ++k) {
        const int g = p_->NodeOf(row_.segment, k);
        for (int b = 0; b < kBlocks; ++b) {
          const auto it = std::find(used_.begin(), used_.end(), b);
          const double* src = it == used_.end() ? p_->Vector(g) + b * kBlock
                                                : parameters[k * per_node + static_cast<int>(it - used_.begin())];
          x.segment(b * kBlock, kBlock) += row_.w[k] * Eigen::Map<const Eigen::Matrix<double, kBlock, 1>>(src);
        }
        if constexpr (kRotation) {
          const double* q = parameters[k * per_node + per_node - 1];
          phis[k] = lie::SO3d(Eigen::Matrix3d(p_->references_[row_.segment].transpose() * detail::QuaternionMatrix(q))).Log();
          jr_inv[k] = lie::SO3d::InverseRightJacobian(phis[k]);
          phi += row_.w[k] * phis[k];
        }
      }
      if (jacobians == nullptr && compress_) {
        // Residual only (Ceres then needs only the cost): h in doubles, and a residual vector with
        // the same squared norm, (sqrt(Σ ρ), 0, ..., 0).
        Eigen::Matrix3d R_t = Eigen::Matrix3d::Identity();
        if constexpr (kRotation) R_t = p_->references_[row_.segment] * lie::SO3d::Exp(phi).Matrix();
        std::vector<double> h(rows_);
        if (!f_(x.data(), R_t, h.data())) return false;
        double cost = 0.0;
        for (int gi = 0; gi < rows_ / group_rows_; ++gi) {
          double sq = 0.0;
          for (int e = 0; e < group_rows_; ++e) sq += h[gi * group_rows_ + e] * h[gi * group_rows_ + e];
          double rho[3] = {sq, 1.0, 0.0};
          if (loss_ != nullptr) loss_->Evaluate(sq, rho);
          cost += rho[0];
        }
        std::fill_n(residuals, used_dim_ + 1, 0.0);
        residuals[0] = std::sqrt(cost);
        return true;
      }
      // h and its Jacobian in the local tangent (x, δ) at t.
      using Jet = ceres::Jet<double, kTangent>;
      Jet xj[kVector];
      for (int i = 0; i < kVector; ++i) xj[i] = Jet(x[i], i);
      Eigen::Matrix<Jet, 3, 3> R = Eigen::Matrix<Jet, 3, 3>::Identity();
      Eigen::Matrix3d jr_t = Eigen::Matrix3d::Identity();
      if constexpr (kRotation) {
        Eigen::Matrix<Jet, 3, 1> delta;
        for (int i = 0; i < 3; ++i) delta[i] = Jet(0.0, kVector + i);
        const Eigen::Matrix3d R_t = p_->references_[row_.segment] * lie::SO3d::Exp(phi).Matrix();
        R = R_t.cast<Jet>() * lie::SO3<Jet>::Exp(delta).Matrix();
        jr_t = lie::SO3d::RightJacobian(phi);
      }
      std::vector<Jet> h(rows_);
      if (!f_(xj, R, h.data())) return false;
      // Columns of the used tangent: used blocks, then the rotation.
      Eigen::VectorXd r(rows_);
      Eigen::MatrixXd J(rows_, used_dim_);
      for (int i = 0; i < rows_; ++i) {
        r[i] = h[i].a;
        int c = 0;
        for (int b : used_) {
          for (int e = 0; e < kBlock; ++e) J(i, c++) = h[i].v[b * kBlock + e];
        }
        if (kRotation) {
          for (int e = 0; e < 3; ++e) J(i, c++) = h[i].v[kVector + e];
        }
      }
      Eigen::VectorXd out_r;
      Eigen::MatrixXd out_J;
      if (!compress_) {
        out_r = r;
        out_J = J;
      } else {
        double cost = 0.0;  // Σ ρ(s_i) (or s_i without a loss) over the groups
        for (int gi = 0; gi < rows_ / group_rows_; ++gi) {
          auto rg = r.segment(gi * group_rows_, group_rows_);
          const double s = rg.squaredNorm();
          if (loss_ == nullptr) {
            cost += s;
            continue;
          }
          double rho[3];
          loss_->Evaluate(s, rho);
          cost += rho[0];
          const double root = std::sqrt(std::max(rho[1], 0.0));
          rg *= root;
          J.middleRows(gi * group_rows_, group_rows_) *= root;
        }
        // J = Q [T; 0]: cost and gradient kept by [Q1ᵀ r; sqrt(cost − |Q1ᵀ r|²)] with Jacobian [T; 0].
        Eigen::HouseholderQR<Eigen::MatrixXd> qr(J);
        const Eigen::VectorXd qtr = qr.householderQ().adjoint() * r;
        out_r.resize(used_dim_ + 1);
        out_r.head(used_dim_) = qtr.head(used_dim_);
        out_r[used_dim_] = std::sqrt(std::max(0.0, cost - out_r.head(used_dim_).squaredNorm()));
        out_J = Eigen::MatrixXd::Zero(used_dim_ + 1, used_dim_);
        out_J.topRows(used_dim_) = qr.matrixQR().topRows(used_dim_).template triangularView<Eigen::Upper>();
      }
      Eigen::Map<Eigen::VectorXd>(residuals, out_r.size()) = out_r;
      if (jacobians == nullptr) return true;
      const int m = static_cast<int>(out_r.size());
      for (int k = 0; k <= N; ++k) {
        int c = 0;
        for (size_t ub = 0; ub < used_.size(); ++ub, c += kBlock) {
          double* jac = jacobians[k * per_node + static_cast<int>(ub)];
          if (jac == nullptr) continue;
          Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, kBlock, Eigen::RowMajor>>(jac, m, kBlock) =
              row_.w[k] * out_J.middleCols(c, kBlock);
        }
        if constexpr (kRotation) {
          double* jac = jacobians[k * per_node + per_node - 1];
          if (jac == nullptr) continue;
          const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> Jd =
              row_.w[k] * out_J.middleCols(c, 3) * jr_t * jr_inv[k];
          LiftRotationJacobian(parameters[k * per_node + per_node - 1], Jd.data(), m, jac);
        }
      }
      return true;
    }

   private:
    PseudoSpectralProblem* p_;
    detail::TimeRow row_;
    F f_;
    int rows_, group_rows_;
    std::vector<int> used_;
    const ceres::LossFunction* loss_;
    int used_dim_ = 0;
    bool compress_ = false;
    std::vector<double*> blocks_;
  };

  // h(x'(t)) of the vector part: parameter blocks are every vector block of every node.
  template <class F>
  class DerivativeCost : public ceres::CostFunction {
   public:
    DerivativeCost(PseudoSpectralProblem* p, detail::TimeRow row, F functor, int rows)
        : p_(p), row_(std::move(row)), f_(std::move(functor)), rows_(rows) {
      set_num_residuals(rows);
      for (int k = 0; k <= p->degree_; ++k) {
        for (int b = 0; b < kBlocks; ++b) {
          blocks_.push_back(p->Vector(p->NodeOf(row_.segment, k)) + b * kBlock);
          mutable_parameter_block_sizes()->push_back(kBlock);
        }
      }
    }
    const std::vector<double*>& blocks() const { return blocks_; }

    bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
      using Jet = ceres::Jet<double, kVector>;
      Eigen::Matrix<double, kVector, 1> xdot = Eigen::Matrix<double, kVector, 1>::Zero();
      for (int k = 0; k <= p_->degree_; ++k) {
        for (int b = 0; b < kBlocks; ++b) {
          xdot.segment(b * kBlock, kBlock) +=
              row_.dw[k] * Eigen::Map<const Eigen::Matrix<double, kBlock, 1>>(parameters[k * kBlocks + b]);
        }
      }
      Jet xj[kVector];
      for (int i = 0; i < kVector; ++i) xj[i] = Jet(xdot[i], i);
      std::vector<Jet> h(rows_);
      if (!f_(xj, h.data())) return false;
      for (int i = 0; i < rows_; ++i) residuals[i] = h[i].a;
      if (jacobians == nullptr) return true;
      for (int k = 0; k <= p_->degree_; ++k) {
        for (int b = 0; b < kBlocks; ++b) {
          double* jac = jacobians[k * kBlocks + b];
          if (jac == nullptr) continue;
          for (int i = 0; i < rows_; ++i) {
            for (int e = 0; e < kBlock; ++e) jac[i * kBlock + e] = row_.dw[k] * h[i].v[b * kBlock + e];
          }
        }
      }
      return true;
    }

   private:
    PseudoSpectralProblem* p_;
    detail::TimeRow row_;
    F f_;
    int rows_;
    std::vector<double*> blocks_;
  };

  // (x − mean)/sigma on a block of kDim numbers.
  template <int kDim>
  struct MeanPrior {
    Eigen::VectorXd mean;
    double sigma;
    template <typename T>
    bool operator()(const T* x, T* r) const {
      for (int i = 0; i < kDim; ++i) r[i] = (x[i] - T(mean[i])) / T(sigma);
      return true;
    }
  };
  using VectorPrior = MeanPrior<kBlock>;
  using ControlPrior = MeanPrior<kControl>;
  struct RotationPrior {
    Eigen::Quaterniond mean;
    double sigma;
    template <typename T>
    bool operator()(const T* q, T* r) const {
      const lie::SO3<T> R(Eigen::Quaternion<T>(q[3], q[0], q[1], q[2]));
      const Eigen::Matrix<T, 3, 1> e = R.Minus(lie::SO3<T>(mean.cast<T>()));
      for (int i = 0; i < 3; ++i) r[i] = e[i] / T(sigma);
      return true;
    }
  };

  Model model_;
  std::vector<double> breakpoints_;
  int degree_;
  cheb::ChebyshevBasis basis_;
  Eigen::MatrixXd D_;
  std::vector<double> vector_, quaternion_, control_;
  std::vector<Eigen::Matrix3d> references_;
  std::vector<bool> manifold_set_;
  RightQuaternionManifold manifold_;
  // A smoothness prior of one order: its residuals (owned by problem_) and σ per segment and component.
  struct SmoothnessPrior {
    double sigma = 0;  // the σ it was added with (the jump residuals' coefficients hold it)
    Eigen::Matrix<double, kControl, kControl> basis = Eigen::Matrix<double, kControl, kControl>::Identity();
    std::vector<LinearControlCost*> segments, jumps;
    std::vector<Eigen::Matrix<double, kControl, 1>> segment_sigma;
  };
  std::map<int, SmoothnessPrior> smoothness_;
  int first_order_ = 0;  // the order SetControlSmoothnessSigma re-weights
  std::unique_ptr<ceres::Problem> problem_;
};

}  // namespace cheval::estim

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
/// at φ = 0, the approximation of the paper; docs/estimator.md).
///
/// Residuals, each a small cost class with its contract in include/cheval/estim/internal/:
/// AddCollocation (collocation_cost.h), AddMeasurement (measurement_cost.h),
/// AddDerivativeMeasurement(s) (derivative_measurement_cost.h). Priors go through one interface,
/// AddPrior / RemovePrior; the control priors AddControlSmoothnessPrior (control_rows_cost.h) and
/// AddControlRatePrior (control_rate_cost.h) are built on it. A prior that is not wanted is not added.

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <ceres/ceres.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "cheval/cheb/chebyshev.h"
#include "cheval/common/error.h"
#include "cheval/estim/internal/block_cost.h"
#include "cheval/estim/internal/collocation_cost.h"
#include "cheval/estim/internal/control_rate_cost.h"
#include "cheval/estim/internal/control_rows_cost.h"
#include "cheval/estim/internal/delayed_position_cost.h"
#include "cheval/estim/internal/derivative_measurement_cost.h"
#include "cheval/estim/internal/measurement_cost.h"
#include "cheval/estim/internal/segment.h"
#include "cheval/estim/internal/smoothness_rows.h"
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

/// A prior added by PseudoSpectralProblem::AddPrior (to remove it again).
using PriorId = ceres::ResidualBlockId;

/// A pseudo-spectral estimation problem for `Model` (see models.h for the requirements).
template <class Model>
class PseudoSpectralProblem {
  using Dim = internal::Dims<Model>;

 public:
  static constexpr int kVector = Dim::kVector;
  static constexpr int kBlock = Dim::kBlock;
  static constexpr int kBlocks = Dim::kBlocks;
  static constexpr bool kRotation = Dim::kRotation;
  static constexpr int kControl = Dim::kControl;
  /// Tangent dimension of the state: vector part + 3 for the rotation.
  static constexpr int kTangent = Dim::kTangent;
  /// Orthonormal columns (kControl x c, 1 <= c <= kControl): components c = Bᵀu of the control.
  using ControlBasis = Eigen::Matrix<double, kControl, Eigen::Dynamic>;

  /// Segments [breakpoints[s], breakpoints[s+1]] (seconds, strictly increasing, at least 2 values),
  /// each a polynomial of `degree` (>= 2). Throws UsageError otherwise. Nodes are numbered globally
  /// in increasing time: node s·N + i is the i-th point of segment s from its start.
  PseudoSpectralProblem(Model model, std::vector<double> breakpoints, int degree)
      : model_(std::move(model)), breakpoints_(std::move(breakpoints)), degree_(degree), basis_(std::max(degree, 1)) {
    if (degree < 2) throw UsageError(fmt::format("a segment's polynomial degree must be >= 2, got {}", degree));
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
  /// The residual rows of the problem as if no measurement were compressed (BlockCost::represented_rows):
  /// the count a reduced χ² divides by, which Ceres' own count of (compressed) residuals is not.
  int num_represented_rows() const {
    std::vector<ceres::ResidualBlockId> ids;
    problem_->GetResidualBlocks(&ids);
    int rows = 0;
    for (ceres::ResidualBlockId id : ids) {
      const ceres::CostFunction* cost = problem_->GetCostFunctionForResidualBlock(id);
      const auto* block = dynamic_cast<const internal::BlockCost*>(cost);
      rows += block != nullptr ? block->represented_rows() : cost->num_residuals();
    }
    return rows;
  }
  /// The underlying Ceres problem, to evaluate it (cost, Jacobian, covariance). Residuals are added
  /// through the Add* functions of this class only.
  ceres::Problem& ceres_problem() { return *problem_; }

  /// Time of global node g.
  double NodeTime(int g) const {
    const int s = std::min(g / degree_, num_segments() - 1);
    return Interval(s).FromUnit(basis_.points()[degree_ - (g - s * degree_)]);
  }
  /// Global node of point k (descending Chebyshev order, k = 0 is the segment's end) of segment s.
  int NodeOf(int s, int k) const { return s * degree_ + (degree_ - k); }

  /// Storage of node g (valid for the problem's lifetime).
  double* Vector(int g) { return &vector_[static_cast<size_t>(g) * kVector]; }
  double* Quaternion(int g) { return &quaternion_[static_cast<size_t>(g) * 4]; }  ///< x, y, z, w
  double* Control(int g) { return &control_[static_cast<size_t>(g) * kControl]; }
  const double* Vector(int g) const { return &vector_[static_cast<size_t>(g) * kVector]; }
  const double* Quaternion(int g) const { return &quaternion_[static_cast<size_t>(g) * 4]; }
  const double* Control(int g) const { return &control_[static_cast<size_t>(g) * kControl]; }

  /// Segment s as its costs see it: node storage in point order, chart reference, d/dt scale.
  internal::Segment SegmentOf(int s) {
    internal::Segment segment;
    segment.index = s;
    segment.derivative_scale = Interval(s).DerivativeScale();
    segment.reference = references_[s];
    for (int k = 0; k <= degree_; ++k) {
      const int g = NodeOf(s, k);
      segment.vector.push_back(Vector(g));
      segment.quaternion.push_back(Quaternion(g));
      segment.control.push_back(Control(g));
    }
    return segment;
  }

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
    for (int s = 0; s < num_segments(); ++s) references_[s] = internal::QuaternionMatrix(Quaternion(s * degree_ + degree_ / 2));
  }

  /// The segment of t and its rows. Throws ComputeError when t is outside [start_time, end_time].
  internal::TimeRow RowAt(double t) const {
    if (!(t >= breakpoints_.front() && t <= breakpoints_.back())) {
      throw ComputeError(fmt::format("time {:.6f} s is outside the estimated interval [{:.6f}, {:.6f}] s", t,
                                     breakpoints_.front(), breakpoints_.back()));
    }
    const int s = std::clamp(
        static_cast<int>(std::upper_bound(breakpoints_.begin(), breakpoints_.end(), t) - breakpoints_.begin()) - 1, 0,
        num_segments() - 1);
    internal::TimeRow row;
    row.segment = s;
    row.w.resize(degree_ + 1);
    row.dw.resize(degree_ + 1);
    const double x = std::clamp(Interval(s).ToUnit(t), -1.0, 1.0);
    basis_.InterpolationRow(x, row.w);
    basis_.DerivativeRow(x, row.dw);
    row.dw *= Interval(s).DerivativeScale();
    return row;
  }

  /// Chart vector φ = Log(R̄_s⁻¹ R_g) of node g in segment s's chart.
  Eigen::Vector3d Chart(int s, int g) const { return internal::ChartVector(references_[s], Quaternion(g)); }

  /// The interpolated state and control at t (ComputeError outside the interval).
  StateSample Interpolate(double t) const {
    const internal::TimeRow row = RowAt(t);
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

  /// Adds the collocation defects (internal/collocation_cost.h) of every node of every segment,
  /// weighted by 1/sigma (kTangent entries, > 0: vector part then rotation, in the units of x').
  void AddCollocation(const Eigen::Matrix<double, kTangent, 1>& sigma) {
    for (int i = 0; i < kTangent; ++i) {
      if (!(sigma[i] > 0)) throw UsageError("collocation sigmas must be > 0");
    }
    constexpr int kParts = kBlocks + (kRotation ? 1 : 0);
    for (int s = 0; s < num_segments(); ++s) {
      const internal::Segment segment = SegmentOf(s);
      for (int j = 0; j <= degree_; ++j) {
        for (int part = 0; part < kParts; ++part) {
          Add(std::make_unique<internal::CollocationCost<Model>>(model_, segment, D_, j, part, sigma));
        }
      }
      if constexpr (kRotation) {
        for (int k = 0; k <= degree_; ++k) UseManifold(NodeOf(s, k));
      }
    }
  }

  /// Adds the measurement h(x(t)) at time t (internal/measurement_cost.h). `F` has
  /// `template <class T> bool operator()(const T* x, const Eigen::Matrix<T,3,3>& R, T* residual) const`
  /// returning `rows` residuals (already whitened), in groups of `group_rows` rows sharing one robust
  /// `loss` (may be null; the problem does not own it). `used_blocks` lists the vector blocks h
  /// depends on (the rotation is always included when the model has one). Throws ComputeError when t
  /// is outside the interval. `uses_rotation` false: h does not depend on the rotation (it gets the
  /// identity), which then is none of the measurement's blocks.
  template <class F>
  void AddMeasurement(double t, F functor, int rows, int group_rows, const std::vector<int>& used_blocks,
                      const ceres::LossFunction* loss = nullptr, bool uses_rotation = true) {
    AddMeasurements({t}, std::vector<F>{std::move(functor)}, rows, group_rows, used_blocks, loss, uses_rotation);
  }

  /// Adds the measurements h_i(x(t_i)) (`functors[i]` at `times[i]`, as AddMeasurement's, `rows` each)
  /// as one residual block per segment (a batch of internal/measurement_cost.h, compressed): the same
  /// cost, gradient and Gauss–Newton matrix as adding them one by one, with the loss per group of each,
  /// in far fewer and smaller blocks (one per sensor and segment instead of one per sample). Throws
  /// UsageError when the sizes differ, ComputeError when a time is outside the interval.
  template <class F>
  void AddMeasurements(const std::vector<double>& times, std::vector<F> functors, int rows, int group_rows,
                       const std::vector<int>& used_blocks, const ceres::LossFunction* loss = nullptr,
                       bool uses_rotation = true) {
    using Cost = internal::MeasurementCost<Model, F>;
    for (auto& [s, samples] : SamplesBySegment<typename Cost::Sample>(times, std::move(functors), "AddMeasurements")) {
      auto cost = std::make_unique<Cost>(SegmentOf(s), std::move(samples), rows, group_rows, used_blocks, loss,
                                         uses_rotation);
      ceres::LossFunction* ceres_loss = cost->ceres_loss();
      Add(std::move(cost), ceres_loss);
      if constexpr (kRotation) {  // its rotations get the quaternion manifold
        if (uses_rotation) {
          for (int k = 0; k <= degree_; ++k) UseManifold(NodeOf(s, k));
        }
      }
    }
  }

  /// Adds positions stamped by a clock δ behind the problem's: `measured[i]` is the position at
  /// problem time times[i] + δ, from the vector blocks `position_block` and `velocity_block` (blocks
  /// of 3), σ `sigma` and a robust `loss` per sample (may be null, not owned), δ the parameter block
  /// `delay` (1 number, seconds) — one internal/delayed_position_cost.h block per segment. Throws
  /// UsageError when the sizes differ or the blocks are not of 3, ComputeError when a time is outside
  /// the interval.
  void AddDelayedPositions(const std::vector<double>& times, const std::vector<Eigen::Vector3d>& measured,
                           int position_block, int velocity_block, double sigma, const ceres::LossFunction* loss,
                           double* delay) {
    if (Model::kBlockSize != 3) throw UsageError("AddDelayedPositions: the model's vector blocks must be of 3");
    for (auto& [s, samples] :
         SamplesBySegment<internal::DelayedPositionCost::Sample>(times, measured, "AddDelayedPositions")) {
      Add(std::make_unique<internal::DelayedPositionCost>(SegmentOf(s), std::move(samples), position_block,
                                                          velocity_block, sigma, loss, delay));
    }
  }

  /// Adds a residual h(x'(t)) of the vector part's derivative at t
  /// (internal/derivative_measurement_cost.h), `loss` over all its rows (may be null; not owned).
  /// `F` has `template <class T> bool operator()(const T* x_dot, T* residual) const` with `rows`
  /// residuals, and may read every vector block.
  template <class F>
  void AddDerivativeMeasurement(double t, F functor, int rows, const ceres::LossFunction* loss = nullptr) {
    std::vector<int> every_block(kBlocks);
    for (int b = 0; b < kBlocks; ++b) every_block[b] = b;
    AddDerivativeMeasurements({t}, std::vector<F>{std::move(functor)}, rows, rows, every_block, loss);
  }

  /// Adds the residuals h_i(x'(t_i)) (`functors[i]` at `times[i]`, `rows` each, in groups of
  /// `group_rows` sharing one robust `loss`, which may be null and is not owned) as one compressed
  /// residual block per segment (internal/derivative_measurement_cost.h): the same cost, gradient
  /// and Gauss–Newton matrix as adding them one by one. `used_blocks` lists the vector blocks h reads.
  /// Throws UsageError when the sizes differ, ComputeError when a time is outside the interval.
  template <class F>
  void AddDerivativeMeasurements(const std::vector<double>& times, std::vector<F> functors, int rows, int group_rows,
                                 const std::vector<int>& used_blocks, const ceres::LossFunction* loss = nullptr) {
    using Cost = internal::DerivativeMeasurementCost<Model, F>;
    for (auto& [s, samples] :
         SamplesBySegment<typename Cost::Sample>(times, std::move(functors), "AddDerivativeMeasurements")) {
      auto cost = std::make_unique<Cost>(SegmentOf(s), std::move(samples), rows, group_rows, used_blocks, loss);
      ceres::LossFunction* ceres_loss = cost->ceres_loss();
      Add(std::move(cost), ceres_loss);
    }
  }

  /// Adds a prior: any cost on the problem's blocks (its blocks() point into this problem's node
  /// storage; the problem owns it). The one way priors enter the problem.
  PriorId AddPrior(std::unique_ptr<internal::BlockCost> cost) { return Add(std::move(cost)); }
  /// Removes a prior added by AddPrior.
  void RemovePrior(PriorId id) { problem_->RemoveResidualBlock(id); }

  /// Adds the equal-weight control-rate prior (internal/control_rate_cost.h) at every node of every
  /// segment: sqrt(Δt) (D U)_j / sigma, Δt = (t1 − t0)/(N + 1). sigma > 0, in control units per
  /// s^(1/2) per s.
  void AddControlRatePrior(double sigma) {
    if (!(sigma > 0) || !std::isfinite(sigma)) throw UsageError("the control-rate sigma must be a finite number > 0");
    for (int s = 0; s < num_segments(); ++s) {
      const internal::Segment segment = SegmentOf(s);
      for (int j = 0; j <= degree_; ++j) {
        AddPrior(std::make_unique<internal::ControlRateCost<kControl>>(segment, Length(s), D_, j, sigma));
      }
    }
  }

  /// Adds the smoothness prior ∫ |u^(m)(t)|² dt / sigma² over [start_time, end_time] on the control
  /// (internal/control_rows_cost.h): the white-noise-on-u^(m) prior of GP smoothing (m = 1: u a
  /// random walk). Per segment the integral is exact: u^(m) is a polynomial of degree N − m, so
  /// Gauss–Legendre quadrature with N − m + 1 points integrates its square exactly; one residual block
  /// per segment. For m >= 2 the GP's u', ..., u^(m−1) are continuous: at every inner breakpoint the
  /// jump of u^(i) gets the residual jump/σ_i, σ_i = σ h^(m−i−1/2) with h the shortest node spacing
  /// there (SmoothnessJumpMatrix). order in [1, min(3, N)], sigma finite and > 0 (control units per
  /// s^m per s^(1/2)).
  void AddControlSmoothnessPrior(int order, double sigma) {
    AddControlSmoothnessPrior(order, sigma, ControlBasis(Eigen::Matrix<double, kControl, kControl>::Identity()));
  }

  /// The same prior on the components c = Bᵀ u of the control in a `basis` B of orthonormal columns
  /// (e.g. the collective and differential rotor speeds, or only some of them), so that each
  /// component can get its own σ (SetControlSmoothnessSigmas). One prior per order: throws
  /// UsageError when the order has one (RemoveControlSmoothnessPrior first), for a bad order or
  /// sigma, or for a basis whose columns are not orthonormal (1e-9).
  void AddControlSmoothnessPrior(int order, double sigma, const ControlBasis& basis) {
    if (order < 1 || order > std::min(3, degree_)) {
      throw UsageError(fmt::format("the control smoothness order must be in [1, {}], got {}", std::min(3, degree_), order));
    }
    if (smoothness_.count(order)) throw UsageError(fmt::format("the problem has a control smoothness prior of order {}", order));
    CheckSigma(sigma);
    if (basis.cols() < 1 || !(basis.transpose() * basis).isIdentity(1e-9)) {
      throw UsageError("the control smoothness basis must have orthonormal columns");
    }
    const int N = degree_;
    SmoothnessPrior& prior = smoothness_[order];
    prior.sigma = sigma;
    prior.segment_sigma.assign(num_segments(), Eigen::VectorXd::Constant(basis.cols(), sigma));
    for (int s = 0; s < num_segments(); ++s) {
      auto cost = std::make_unique<Rows>(SegmentOf(s).control, SmoothnessRows(order, s), basis);
      cost->set_weight(1.0 / sigma);
      prior.segments.push_back(cost.get());
      prior.ids.push_back(AddPrior(std::move(cost)));
    }
    for (int s = 0; order > 1 && s + 1 < num_segments(); ++s) {  // u', ..., u^(m-1) continuous
      std::vector<double*> controls;
      for (int g = s * N; g <= (s + 2) * N; ++g) controls.push_back(Control(g));
      auto cost = std::make_unique<Rows>(controls, SmoothnessJumpMatrix(order, s, sigma), basis);
      prior.jumps.push_back(cost.get());
      prior.ids.push_back(AddPrior(std::move(cost)));
    }
  }

  /// Removes the order-m smoothness prior (UsageError when there is none).
  void RemoveControlSmoothnessPrior(int order) {
    SmoothnessPrior& prior = Smoothness(order);
    for (PriorId id : prior.ids) RemovePrior(id);
    smoothness_.erase(order);
  }

  /// Replaces σ of segment s's integral of the order-1 prior (or, without one, the lowest order
  /// added) by `sigma` for every component: a prior whose intensity varies along the span.
  void SetControlSmoothnessSigma(int s, double sigma) {
    if (smoothness_.empty()) throw UsageError("no control smoothness prior to re-weight");
    SetControlSmoothnessSigmas(smoothness_.begin()->first, s,
                               Eigen::VectorXd::Constant(smoothness_.begin()->second.segment_sigma[0].size(), sigma));
  }

  /// σ per component (of the prior's basis) of segment s's integral of the order-m prior. For m >= 2
  /// the jump residuals at the segment's breakpoints take the geometric mean of the two segments' σ.
  /// Takes effect at the next Solve. Throws UsageError for a σ that is not finite and > 0, a segment
  /// out of range or no such prior.
  void SetControlSmoothnessSigmas(int order, int s, const Eigen::VectorXd& sigma) {
    SmoothnessPrior& prior = Smoothness(order);
    if (s < 0 || s >= num_segments()) throw UsageError(fmt::format("segment {} out of range [0, {})", s, num_segments()));
    if (sigma.size() != prior.segment_sigma[s].size()) throw UsageError("one sigma per component of the basis");
    for (double x : sigma) CheckSigma(x);
    prior.segment_sigma[s] = sigma;
    prior.segments[s]->set_weights(sigma.cwiseInverse());
    for (int j = std::max(s - 1, 0); j <= std::min<int>(s, static_cast<int>(prior.jumps.size()) - 1); ++j) {
      const Eigen::VectorXd mean = prior.segment_sigma[j].cwiseProduct(prior.segment_sigma[j + 1]).cwiseSqrt();
      prior.jumps[j]->set_weights(prior.sigma * mean.cwiseInverse());
    }
  }

  /// ∫ |u^(m)(t)|² dt over segment s of the current controls, summed over the control entries
  /// (exact: Gauss–Legendre with N − m + 1 points). order in [1, N]; UsageError otherwise.
  double ControlDerivativeEnergy(int order, int s) const {
    return ControlDerivativeEnergies(order, s, ControlBasis(Eigen::Matrix<double, kControl, kControl>::Identity())).sum();
  }

  /// The same per component c_j = B_jᵀ u of a basis of orthonormal columns (with a complete basis
  /// they sum to the total).
  Eigen::VectorXd ControlDerivativeEnergies(int order, int s, const ControlBasis& basis) const {
    if (order < 1 || order > degree_) throw UsageError(fmt::format("the derivative order must be in [1, {}]", degree_));
    if (s < 0 || s >= num_segments()) throw UsageError(fmt::format("segment {} out of range [0, {})", s, num_segments()));
    const Eigen::MatrixXd C = SmoothnessRows(order, s);
    Eigen::MatrixXd U(degree_ + 1, kControl);
    for (int k = 0; k <= degree_; ++k) U.row(k) = Eigen::Map<const Eigen::Matrix<double, 1, kControl>>(Control(NodeOf(s, k)));
    return (C * U * basis).colwise().squaredNorm().transpose();
  }

  /// The rows of ∫_s |x^(m)|² dt for any quantity x known at the nodes of segment s (rows x N + 1,
  /// point order k = 0..N): sqrt(w_q L/2) x^(m)(t_q) at `points` Gauss–Legendre points (0: N − m + 1,
  /// the exact rule), so the energy of x is |C X|².
  Eigen::MatrixXd SmoothnessMatrix(int order, int s, int points = 0) const { return SmoothnessRows(order, s, points); }

  /// The jump rows of the order-m prior with σ at the breakpoint between segments s and s + 1
  /// (order − 1 rows over the global nodes s·N .. (s + 2)·N, in that order); empty for m = 1.
  Eigen::MatrixXd SmoothnessJumpMatrix(int order, int s, double sigma) const {
    return internal::SmoothnessJumpRows(basis_, D_, Interval(s), Interval(s + 1), order, sigma);
  }

  /// Holds the given entries of every node's control constant (known inputs, e.g. a measured
  /// attitude carried in the control): a ceres::SubsetManifold on each control block. Call after the
  /// residuals are added.
  void HoldControlEntries(const std::vector<int>& entries) {
    hold_ = std::make_unique<ceres::SubsetManifold>(kControl, entries);
    for (int g = 0; g < num_nodes(); ++g) problem_->SetManifold(Control(g), hold_.get());
  }

  /// Runs Ceres. The quaternions are re-normalised afterwards.
  ceres::Solver::Summary Solve(const ceres::Solver::Options& options) {
    ceres::Solver::Summary summary;
    ceres::Solve(options, problem_.get(), &summary);
    for (int g = 0; g < num_nodes(); ++g) Eigen::Map<Eigen::Vector4d>(Quaternion(g)).normalize();
    return summary;
  }

 private:
  using Rows = internal::ControlRowsCost<kControl>;
  // A smoothness prior of one order: its residuals (owned by problem_) and σ per segment and component.
  struct SmoothnessPrior {
    double sigma = 0;  // the σ it was added with (the jump residuals' coefficients hold it)
    std::vector<Rows*> segments, jumps;
    std::vector<PriorId> ids;
    std::vector<Eigen::VectorXd> segment_sigma;
  };

  PriorId Add(std::unique_ptr<internal::BlockCost> cost, ceres::LossFunction* loss = nullptr) {
    const std::vector<double*> blocks = cost->blocks();
    return problem_->AddResidualBlock(cost.release(), loss, blocks);
  }

  // The batches of a batched cost: per segment, a Sample {row, item} for each time in it (in the order
  // given). UsageError, naming `caller`, when there is not one item per time.
  template <class Sample, class Item>
  std::map<int, std::vector<Sample>> SamplesBySegment(const std::vector<double>& times, std::vector<Item> items,
                                                     const char* caller) const {
    if (times.size() != items.size()) throw UsageError(fmt::format("{}: one measurement per time", caller));
    std::map<int, std::vector<Sample>> out;
    for (size_t i = 0; i < times.size(); ++i) {
      internal::TimeRow row = RowAt(times[i]);
      const int s = row.segment;
      out[s].push_back({std::move(row), std::move(items[i])});
    }
    return out;
  }

  SmoothnessPrior& Smoothness(int order) {
    auto it = smoothness_.find(order);
    if (it == smoothness_.end()) throw UsageError(fmt::format("no control smoothness prior of order {}", order));
    return it->second;
  }

  static void CheckSigma(double sigma) {
    if (!(sigma > 0) || !std::isfinite(sigma)) {
      throw UsageError(fmt::format("the control smoothness sigma must be a finite number > 0, got {}", sigma));
    }
  }

  Eigen::MatrixXd SmoothnessRows(int order, int s, int points = 0) const {
    return internal::SmoothnessRows(basis_, D_, Interval(s), order, points);
  }

  // Puts node g's quaternion on the manifold once (the block must already be in the problem).
  void UseManifold(int g) {
    if (manifold_set_[g]) return;
    problem_->SetManifold(Quaternion(g), &manifold_);
    manifold_set_[g] = true;
  }

  cheb::Interval Interval(int s) const { return {breakpoints_[s], breakpoints_[s + 1]}; }
  double Length(int s) const { return breakpoints_[s + 1] - breakpoints_[s]; }

  Model model_;
  std::vector<double> breakpoints_;
  int degree_;
  cheb::ChebyshevBasis basis_;
  Eigen::MatrixXd D_;
  std::vector<double> vector_, quaternion_, control_;
  std::vector<Eigen::Matrix3d> references_;
  std::vector<bool> manifold_set_;
  RightQuaternionManifold manifold_;
  std::unique_ptr<ceres::SubsetManifold> hold_;
  std::map<int, SmoothnessPrior> smoothness_;
  std::unique_ptr<ceres::Problem> problem_;  // last: destroyed first, before the manifolds it uses
};

/// The most memory an estimator's problem may take, bytes, as estimated by ProblemBytes.
inline constexpr double kMaxProblemBytes = 3e9;

/// The memory a problem of `nodes` Chebyshev nodes of `degree` takes, bytes: 16 KB + 6 KB x degree
/// per node, the peak measured for the quadrotor estimator (docs/estimator.md, "Limits": 40 KB per
/// node at degree 4, 390 KB at degree 64; the thrust estimator takes less).
inline double ProblemBytes(double nodes, int degree) { return nodes * (16e3 + 6e3 * degree); }

/// round(span_s / segment_s) (at least 1): the number of equal segments an estimator cuts its span
/// into. Throws OptionError(options, "segment_s", ...) naming the node count it would give
/// (segments · degree + 1), its memory and the limit when ProblemBytes exceeds kMaxProblemBytes,
/// before anything is allocated.
inline int SegmentCount(const std::string& options, double span_s, double segment_s, int degree) {
  const double segments = std::max(1.0, std::round(span_s / segment_s));
  const double nodes = segments * degree + 1.0;
  if (!(ProblemBytes(nodes, degree) <= kMaxProblemBytes)) {
    throw OptionError(options, "segment_s",
                      fmt::format("must keep the problem within {:.0f} GB; {} s gives {:.4g} segments of degree {} "
                                  "over the {:.6g} s span = {:.4g} nodes, about {:.3g} GB (16 KB + 6 KB x degree per "
                                  "node)",
                                  kMaxProblemBytes / 1e9, segment_s, segments, degree, span_s, nodes,
                                  ProblemBytes(nodes, degree) / 1e9));
  }
  return static_cast<int>(segments);
}

}  // namespace cheval::estim

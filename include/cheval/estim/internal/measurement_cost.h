#pragma once
/// \file
/// MeasurementCost: a measurement h(x(t), R(t)) of the state at any time t, or a batch of them in one
/// segment (docs/estimator.md, "Residuals").
///
/// Contract. x(t) = Σ_k w_k(t) X_k through the barycentric row of t in its segment, and
/// R(t) = R̄ Exp(Σ_k w_k(t) φ_k), φ_k = Log(R̄ᵀ R_k). The functor F has
/// `template <class T> bool operator()(const T* x, const Eigen::Matrix<T,3,3>& R, T* h) const` and
/// returns `rows` residuals, already whitened, in groups of `group_rows` rows that share one robust
/// loss ρ (a camera frame: 2 rows per landmark). When the rows outnumber the columns of their
/// Jacobian + 1 they are compressed: with J = Q [T; 0] the QR of their Jacobian (after the IRLS
/// weights √ρ' of the loss), the cost returns [Q₁ᵀ r; sqrt(Σρ − |Q₁ᵀ r|²)] with Jacobian [T; 0] — the
/// same cost, gradient and Gauss–Newton matrix as the original rows, with the loss applied inside
/// (ceres_loss() is then null). Evaluated without Jacobians, a compressed cost returns (sqrt(Σρ), 0,
/// …, 0): only its squared norm is meaningful. One measurement is compressed in the local tangent at
/// t (its Jacobian has the used tangent's columns); a batch — several times of one segment, each with
/// its own functor, e.g. every sample of one sensor in the segment — is always compressed, in the
/// nodes' tangent ((N + 1) × the used tangent columns), so that it is one small residual block
/// whatever the number of samples. Parameter blocks: per node of the segment (point order), the used
/// vector blocks, then the quaternion (models with a rotation, unless the measurement is declared not
/// to use it: then h's R is the identity, and the node's rotation is none of its blocks). h is
/// differentiated by ceres::Jet in the local tangent at t and carried to the nodes through the row
/// (rotation: J_r(φ(t)) J_r⁻¹(φ_k)); without Jacobians (Ceres pricing a step) h is evaluated in
/// doubles.

#include <algorithm>
#include <cmath>
#include <vector>

#include <ceres/jet.h>
#include <Eigen/Core>

#include "cheval/common/error.h"
#include "cheval/estim/internal/block_cost.h"
#include "cheval/estim/internal/compressed_rows.h"
#include "cheval/estim/internal/segment.h"
#include "cheval/estim/manifold.h"
#include "cheval/lie/so3.h"

namespace cheval::estim::internal {

template <class Model, class F>
class MeasurementCost : public BlockCost {
  using Dim = Dims<Model>;
  static constexpr int kVector = Dim::kVector, kBlock = Dim::kBlock, kBlocks = Dim::kBlocks,
                       kTangent = Dim::kTangent;
  static constexpr bool kRotation = Dim::kRotation;
  using Vector = Eigen::Matrix<double, kVector, 1>;

 public:
  /// One measurement of a batch: where its time falls in the segment, and its functor.
  struct Sample {
    TimeRow row;
    F functor;
  };

  /// Measurements in `segment` (one or a batch), `rows` each (the loss applies per group of each).
  /// `used`: the vector blocks h depends on (the others are read from the segment's storage and
  /// held); `uses_rotation`: whether h depends on R (models with a rotation). `loss` may be null; it
  /// is not owned. Throws UsageError for rows that are not a positive multiple of group_rows, a block
  /// that does not exist, no samples or a sample of another segment.
  MeasurementCost(const Segment& segment, std::vector<Sample> samples, int rows, int group_rows,
                  std::vector<int> used, const ceres::LossFunction* loss, bool uses_rotation = true)
      : storage_(segment.vector), reference_(segment.reference), samples_(std::move(samples)), rows_(rows),
        group_rows_(group_rows), used_(std::move(used)), loss_(loss), rotation_(kRotation && uses_rotation) {
    CheckBatch("measurement", rows_, group_rows_, used_, kBlocks, samples_);
    local_dim_ = static_cast<int>(used_.size()) * kBlock + (rotation_ ? 3 : 0);
    batch_ = samples_.size() > 1;
    columns_ = batch_ ? (segment.degree() + 1) * local_dim_ : local_dim_;
    const int total_rows = rows_ * static_cast<int>(samples_.size());
    compress_ = batch_ || total_rows > local_dim_ + 1;
    set_num_residuals(compress_ ? std::min(total_rows, columns_) + 1 : rows_);
    for (int k = 0; k <= segment.degree(); ++k) {
      for (int b : used_) AddBlock(segment.vector[k] + b * kBlock, kBlock);
      if (rotation_) AddBlock(segment.quaternion[k], 4);
    }
  }
  int segment() const { return samples_.front().row.segment; }
  /// Every measurement's rows, compressed or not.
  int represented_rows() const override { return rows_ * static_cast<int>(samples_.size()); }
  /// The loss Ceres applies: only when the rows are not compressed (then the loss is per block).
  ceres::LossFunction* ceres_loss() const { return compress_ ? nullptr : const_cast<ceres::LossFunction*>(loss_); }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const int N = static_cast<int>(storage_.size()) - 1;
    const int per_node = static_cast<int>(used_.size()) + (rotation_ ? 1 : 0);
    // The nodes: used blocks from the parameters, the others from the problem's storage.
    std::vector<Vector> nodes(N + 1);
    std::vector<Eigen::Vector3d> phis(rotation_ ? N + 1 : 0);
    for (int k = 0; k <= N; ++k) {
      nodes[k] = NodeVector<Model>(storage_, used_, parameters, k, per_node);
      if (rotation_) phis[k] = ChartVector(reference_, parameters[k * per_node + per_node - 1]);
    }
    const int total_rows = rows_ * static_cast<int>(samples_.size());
    if (jacobians == nullptr) {
      // Residual only (a step's cost): h in doubles. Compressed, a residual vector with the same
      // squared norm, (sqrt(Σ ρ), 0, ..., 0).
      std::vector<double> h(rows_);
      double cost = 0.0;
      for (const Sample& sample : samples_) {
        Vector x;
        Eigen::Vector3d phi;
        Interpolate(sample.row, nodes, phis, &x, &phi);
        Eigen::Matrix3d R_t = Eigen::Matrix3d::Identity();
        if (rotation_) R_t = reference_ * lie::SO3d::Exp(phi).Matrix();
        if (!compress_) return sample.functor(x.data(), R_t, residuals);
        if (!sample.functor(x.data(), R_t, h.data())) return false;
        cost += GroupedCost(h.data(), rows_, group_rows_, loss_);
      }
      std::fill_n(residuals, num_residuals(), 0.0);
      residuals[0] = std::sqrt(cost);
      return true;
    }
    // The rows and their Jacobian: in the local tangent at t for one measurement, in the nodes'
    // tangents for a batch.
    Eigen::VectorXd r(total_rows);
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(total_rows, columns_);
    std::vector<Eigen::Matrix3d> jr_inv(rotation_ ? N + 1 : 0);
    for (int k = 0; k < static_cast<int>(jr_inv.size()); ++k) jr_inv[k] = lie::SO3d::InverseRightJacobian(phis[k]);
    Eigen::Matrix3d jr_t = Eigen::Matrix3d::Identity();  // of the one measurement (not a batch)
    Eigen::MatrixXd A(rows_, local_dim_);
    for (size_t i = 0; i < samples_.size(); ++i) {
      const Sample& sample = samples_[i];
      if (!LocalJacobian(sample, nodes, phis, r.segment(static_cast<Eigen::Index>(i) * rows_, rows_), &A, &jr_t)) {
        return false;
      }
      if (!batch_) {
        J = A;
        continue;
      }
      const int vector_columns = static_cast<int>(used_.size()) * kBlock;
      for (int k = 0; k <= N; ++k) {
        auto node = J.block(static_cast<Eigen::Index>(i) * rows_, k * local_dim_, rows_, local_dim_);
        node.leftCols(vector_columns) = sample.row.w[k] * A.leftCols(vector_columns);
        if (rotation_) node.rightCols(3) = sample.row.w[k] * A.rightCols(3) * jr_t * jr_inv[k];
      }
    }
    Eigen::VectorXd out_r;
    Eigen::MatrixXd out_J;
    if (!compress_) {
      out_r = r;
      out_J = J;
    } else {
      CompressRows(group_rows_, loss_, &r, &J, &out_r, &out_J);
    }
    Eigen::Map<Eigen::VectorXd>(residuals, out_r.size()) = out_r;
    const int m = static_cast<int>(out_r.size());
    for (int k = 0; k <= N; ++k) {
      // A batch's columns are the node's already; one measurement's are carried through its row.
      const int first = batch_ ? k * local_dim_ : 0;
      const double w = batch_ ? 1.0 : samples_.front().row.w[k];
      int c = first;
      for (size_t ub = 0; ub < used_.size(); ++ub, c += kBlock) {
        double* jac = jacobians[k * per_node + static_cast<int>(ub)];
        if (jac == nullptr) continue;
        Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, kBlock, Eigen::RowMajor>>(jac, m, kBlock) =
            w * out_J.middleCols(c, kBlock);
      }
      if (rotation_) {
        double* jac = jacobians[k * per_node + per_node - 1];
        if (jac == nullptr) continue;
        Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> Jd = out_J.middleCols(c, 3);
        if (!batch_) Jd = w * Jd * jr_t * jr_inv[k];
        LiftRotationJacobian(parameters[k * per_node + per_node - 1], Jd.data(), m, jac);
      }
    }
    return true;
  }

 private:
  // x(t) and φ(t) through the sample's row.
  void Interpolate(const TimeRow& row, const std::vector<Vector>& nodes, const std::vector<Eigen::Vector3d>& phis,
                   Vector* x, Eigen::Vector3d* phi) const {
    x->setZero();
    phi->setZero();
    for (size_t k = 0; k < nodes.size(); ++k) {
      *x += row.w[static_cast<Eigen::Index>(k)] * nodes[k];
      if (rotation_) *phi += row.w[static_cast<Eigen::Index>(k)] * phis[k];
    }
  }

  // h at the sample and its Jacobian A in the local tangent (x's used blocks, then δ); jr_t = J_r(φ(t)).
  template <class Rows>
  bool LocalJacobian(const Sample& sample, const std::vector<Vector>& nodes, const std::vector<Eigen::Vector3d>& phis,
                     Rows r, Eigen::MatrixXd* A, Eigen::Matrix3d* jr_t) const {
    Vector x;
    Eigen::Vector3d phi;
    Interpolate(sample.row, nodes, phis, &x, &phi);
    using Jet = ceres::Jet<double, kTangent>;
    Jet xj[kVector];
    for (int i = 0; i < kVector; ++i) xj[i] = Jet(x[i], i);
    Eigen::Matrix<Jet, 3, 3> R = Eigen::Matrix<Jet, 3, 3>::Identity();
    if constexpr (kRotation) {  // (a model without a rotation has no δ in its tangent)
      if (rotation_) {
        Eigen::Matrix<Jet, 3, 1> delta;
        for (int i = 0; i < 3; ++i) delta[i] = Jet(0.0, kVector + i);
        const Eigen::Matrix3d R_t = reference_ * lie::SO3d::Exp(phi).Matrix();
        R = R_t.cast<Jet>() * lie::SO3<Jet>::Exp(delta).Matrix();
        *jr_t = lie::SO3d::RightJacobian(phi);
      }
    }
    std::vector<Jet> h(rows_);
    if (!sample.functor(xj, R, h.data())) return false;
    for (int i = 0; i < rows_; ++i) {
      r[i] = h[i].a;
      int c = 0;
      for (int b : used_) {
        for (int e = 0; e < kBlock; ++e) (*A)(i, c++) = h[i].v[b * kBlock + e];
      }
      if (rotation_) {
        for (int e = 0; e < 3; ++e) (*A)(i, c++) = h[i].v[kVector + e];
      }
    }
    return true;
  }

  std::vector<double*> storage_;  // every node's vector part (point order): the blocks h does not use
  Eigen::Matrix3d reference_;
  std::vector<Sample> samples_;
  int rows_, group_rows_;
  std::vector<int> used_;
  const ceres::LossFunction* loss_;
  bool rotation_;
  int local_dim_ = 0, columns_ = 0;
  bool batch_ = false, compress_ = false;
};

}  // namespace cheval::estim::internal

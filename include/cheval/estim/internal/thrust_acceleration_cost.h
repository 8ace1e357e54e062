#pragma once
/// \file
/// ThrustAccelerationCost: rows linear in the world-frame thrust acceleration of a set of nodes — the
/// residual of the quadrotor estimator's Matérn prior on the collective (docs/estimator.md, "The
/// algorithm", step 5).
///
/// Contract. With f_k = (k_F/m) Σ_i Ω_ik² R_k e3 the thrust acceleration of node k (rotor speeds Ω_k,
/// R_k from the quaternion block (x, y, z, w), world frame), coefficient rows C_a per world axis a
/// (rows × nodes) and offsets o (rows × 3), the residual (row q, axis a) is
/// w (Σ_k C_a(q, k) f_k[a] + o(q, a)), stored (q, a) row-major. Parameter blocks: per node its rotor
/// speeds (4) and quaternion (4). Jacobians are analytic in the rotor speeds and in the quaternion's
/// ambient coordinates (Ceres applies the manifold). With C_a the Gauss–Legendre rows of
/// (D + λ_a)² over a segment, o = −λ_a² ḡ_a (the rows' sums) and w = 1/σ, the squared norm is
/// ∫_s |(D + λ_a)² (f_a − ḡ_a)|² dt / σ², exactly.

#include <array>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "cheval/estim/internal/block_cost.h"

namespace cheval::estim::internal {

class ThrustAccelerationCost : public BlockCost {
 public:
  /// `controls`, `quaternions`: the nodes' blocks (C's columns, in order). Empty offsets: zero.
  ThrustAccelerationCost(const std::vector<double*>& controls, const std::vector<double*>& quaternions,
                         std::array<Eigen::MatrixXd, 3> coefficients, Eigen::MatrixXd offsets, double k_over_m)
      : coefficients_(std::move(coefficients)), offsets_(std::move(offsets)), k_over_m_(k_over_m) {
    for (size_t k = 0; k < controls.size(); ++k) {
      AddBlock(controls[k], 4);
      AddBlock(quaternions[k], 4);
    }
    if (offsets_.size() == 0) offsets_ = Eigen::MatrixXd::Zero(coefficients_[0].rows(), 3);
    set_num_residuals(3 * static_cast<int>(coefficients_[0].rows()));
  }
  /// The same rows C on every axis, no offsets.
  ThrustAccelerationCost(const std::vector<double*>& controls, const std::vector<double*>& quaternions,
                         const Eigen::MatrixXd& coefficients, double k_over_m)
      : ThrustAccelerationCost(controls, quaternions, {coefficients, coefficients, coefficients}, Eigen::MatrixXd(),
                               k_over_m) {}
  /// w (1/σ).
  void set_weight(double w) { weight_ = w; }

  /// f = k_over_m |u|² R(q) e3 for rotor speeds u and a quaternion q (x, y, z, w).
  static Eigen::Vector3d ThrustAcceleration(const double* u, const double* q, double k_over_m) {
    const double x = q[0], y = q[1], z = q[2], w = q[3];
    const Eigen::Vector3d b3(2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y));
    return k_over_m * (u[0] * u[0] + u[1] * u[1] + u[2] * u[2] + u[3] * u[3]) * b3;
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const int rows = static_cast<int>(coefficients_[0].rows()), nodes = static_cast<int>(coefficients_[0].cols());
    Eigen::Map<Eigen::VectorXd> r(residuals, 3 * rows);
    for (int row = 0; row < rows; ++row) r.segment<3>(3 * row) = weight_ * offsets_.row(row).transpose();
    for (int k = 0; k < nodes; ++k) {
      const double* u = parameters[2 * k];
      const double* q = parameters[2 * k + 1];
      const Eigen::Vector3d f = ThrustAcceleration(u, q, k_over_m_);
      for (int row = 0; row < rows; ++row) {
        for (int a = 0; a < 3; ++a) r[3 * row + a] += weight_ * coefficients_[a](row, k) * f[a];
      }
      if (!jacobians) continue;
      const double x = q[0], y = q[1], z = q[2], w = q[3];
      const double t = k_over_m_ * (u[0] * u[0] + u[1] * u[1] + u[2] * u[2] + u[3] * u[3]);
      const Eigen::Vector3d b3(2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y));
      Eigen::Matrix<double, 3, 4> df_du = (2 * k_over_m_) * b3 * Eigen::Map<const Eigen::RowVector4d>(u);
      Eigen::Matrix<double, 3, 4> df_dq;
      df_dq.col(0) = Eigen::Vector3d(2 * z, -2 * w, -4 * x);
      df_dq.col(1) = Eigen::Vector3d(2 * w, 2 * z, -4 * y);
      df_dq.col(2) = Eigen::Vector3d(2 * x, 2 * y, 0);
      df_dq.col(3) = Eigen::Vector3d(2 * y, -2 * x, 0);
      df_dq *= t;
      for (int b = 0; b < 2; ++b) {
        if (!jacobians[2 * k + b]) continue;
        Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor>> J(jacobians[2 * k + b], 3 * rows, 4);
        const Eigen::Matrix<double, 3, 4>& df = b == 0 ? df_du : df_dq;
        for (int row = 0; row < rows; ++row) {
          for (int a = 0; a < 3; ++a) J.row(3 * row + a) = weight_ * coefficients_[a](row, k) * df.row(a);
        }
      }
    }
    return true;
  }

 private:
  std::array<Eigen::MatrixXd, 3> coefficients_;
  Eigen::MatrixXd offsets_;
  double k_over_m_;
  double weight_ = 1.0;
};

}  // namespace cheval::estim::internal

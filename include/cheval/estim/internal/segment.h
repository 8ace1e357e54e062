#pragma once
/// \file
/// What the cost classes of the pseudo-spectral problem (problem.h) share: the dimensions of a model,
/// the interpolation rows at a time, the parameter blocks of one segment and its rotation charts.
/// Internal (installed because PseudoSpectralProblem is a template): the contract of each cost is at
/// the top of its own header in this folder.
///
/// Point order: the N + 1 nodes of a segment are numbered k = 0..N in descending Chebyshev order
/// (k = 0 is the segment's end), as the rows of cheb::ChebyshevBasis.

#include <algorithm>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "cheval/lie/so3.h"

namespace cheval::estim::internal {

/// The dimensions of a model (models.h) as the costs use them.
template <class Model>
struct Dims {
  static constexpr int kVector = Model::kVectorDim;
  static constexpr int kBlock = Model::kBlockSize;
  static constexpr int kBlocks = kVector / kBlock;
  static constexpr bool kRotation = Model::kHasRotation;
  static constexpr int kControl = Model::kControlDim;
  /// Tangent dimension of the state: vector part + 3 for the rotation.
  static constexpr int kTangent = kVector + (kRotation ? 3 : 0);
  static_assert(kVector % kBlock == 0, "kBlockSize must divide kVectorDim");
};

/// Where a time falls: its segment and the interpolation / derivative rows there (derivative in t).
struct TimeRow {
  int segment = 0;
  Eigen::RowVectorXd w;   ///< x(t) = Σ_k w_k X_k
  Eigen::RowVectorXd dw;  ///< x'(t) = Σ_k dw_k X_k (already scaled by 2 / (t1 - t0))
};

/// The rotation matrix of a quaternion block (x, y, z, w), normalised.
inline Eigen::Matrix3d QuaternionMatrix(const double* q) {
  return Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized().toRotationMatrix();
}

/// The chart vector φ = Log(R̄ᵀ R(q)) of a quaternion block in the chart of reference R̄.
inline Eigen::Vector3d ChartVector(const Eigen::Matrix3d& reference, const double* q) {
  return lie::SO3d(Eigen::Matrix3d(reference.transpose() * QuaternionMatrix(q))).Log();
}

/// One segment as its costs see it: the storage of its nodes in point order, the chart reference
/// R̄_s and d/dt = derivative_scale · d/dx on the unit interval.
struct Segment {
  int index = 0;
  double derivative_scale = 1;
  Eigen::Matrix3d reference = Eigen::Matrix3d::Identity();
  std::vector<double*> vector, quaternion, control;  ///< per point k = 0..N
  int degree() const { return static_cast<int>(vector.size()) - 1; }
};

/// The vector part of node k (point order) for a cost that reads only some vector blocks: the blocks in
/// `used` from Evaluate's `parameters` (`per_node` blocks per node, the used ones first, in the order
/// of `used`), the others from the problem's `storage` (held).
template <class Model>
Eigen::Matrix<double, Dims<Model>::kVector, 1> NodeVector(const std::vector<double*>& storage,
                                                        const std::vector<int>& used,
                                                        double const* const* parameters, int k, int per_node) {
  constexpr int kBlock = Dims<Model>::kBlock;
  Eigen::Matrix<double, Dims<Model>::kVector, 1> x;
  for (int b = 0; b < Dims<Model>::kBlocks; ++b) {
    const auto it = std::find(used.begin(), used.end(), b);
    const double* src =
        it == used.end() ? storage[k] + b * kBlock : parameters[k * per_node + static_cast<int>(it - used.begin())];
    x.template segment<kBlock>(b * kBlock) = Eigen::Map<const Eigen::Matrix<double, kBlock, 1>>(src);
  }
  return x;
}

/// φ_k and J_r⁻¹(φ_k) of the rotations of a segment's nodes (k = 0..N) in its chart.
struct Charts {
  std::vector<Eigen::Vector3d> phi;
  std::vector<Eigen::Matrix3d> jr_inv;
  Charts(const Eigen::Matrix3d& reference, double const* const* quaternions, int points)
      : phi(points), jr_inv(points) {
    for (int k = 0; k < points; ++k) {
      phi[k] = ChartVector(reference, quaternions[k]);
      jr_inv[k] = lie::SO3d::InverseRightJacobian(phi[k]);
    }
  }
  Charts() = default;
};

}  // namespace cheval::estim::internal

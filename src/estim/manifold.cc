#include "cheval/estim/manifold.h"

#include <Eigen/Geometry>

#include "cheval/lie/so3.h"

namespace cheval::estim {

Eigen::Matrix<double, 4, 3> QuaternionPlusJacobian(const double* q) {
  const double x = q[0], y = q[1], z = q[2], w = q[3];
  Eigen::Matrix<double, 4, 3> m;
  m << w, -z, y,  //
      z, w, -x,   //
      -y, x, w,   //
      -x, -y, -z;
  return 0.5 * m;
}

void LiftRotationJacobian(const double* q, const double* J_delta, int rows, double* J_q) {
  const Eigen::Matrix<double, 3, 4> pinv = 4.0 * QuaternionPlusJacobian(q).transpose();
  Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>> in(J_delta, rows, 3);
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor>> out(J_q, rows, 4);
  out.noalias() = in * pinv;
}

bool RightQuaternionManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  const lie::SO3d r(Eigen::Quaterniond(x[3], x[0], x[1], x[2]));
  const Eigen::Quaterniond q = r.Plus(Eigen::Vector3d(delta[0], delta[1], delta[2])).quaternion();
  Eigen::Map<Eigen::Vector4d>{x_plus_delta} = q.coeffs();
  return true;
}

bool RightQuaternionManifold::PlusJacobian(const double* x, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 4, 3, Eigen::RowMajor>>{jacobian} = QuaternionPlusJacobian(x);
  return true;
}

bool RightQuaternionManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  const lie::SO3d ry(Eigen::Quaterniond(y[3], y[0], y[1], y[2]));
  const lie::SO3d rx(Eigen::Quaterniond(x[3], x[0], x[1], x[2]));
  Eigen::Map<Eigen::Vector3d>{y_minus_x} = ry.Minus(rx);
  return true;
}

bool RightQuaternionManifold::MinusJacobian(const double* x, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 3, 4, Eigen::RowMajor>>{jacobian} = 4.0 * QuaternionPlusJacobian(x).transpose();
  return true;
}

}  // namespace cheval::estim

#include "cheval/traj/trajectory.h"

#include <cassert>
#include <cmath>
#include <stdexcept>

namespace cheval::traj {

int OrientationStride(OrientationKind kind) {
  switch (kind) {
    case OrientationKind::kNone: return 0;
    case OrientationKind::kQuaternion: return 4;
    case OrientationKind::kMatrix: return 9;
  }
  return 0;
}

Eigen::Matrix3d RotationFromQuaternion(double x, double y, double z, double w) {
  // evo (transformations.quaternion_matrix): n = q·q; identity below 4·machine-eps; otherwise
  // q *= sqrt(2/n) and R from the outer product q qᵀ.
  const double n = x * x + y * y + z * z + w * w;
  if (n < 8.881784197001252e-16) return Eigen::Matrix3d::Identity();
  const double s = std::sqrt(2.0 / n);
  x *= s, y *= s, z *= s, w *= s;
  Eigen::Matrix3d R;
  R << 1.0 - (y * y + z * z), x * y - z * w, x * z + y * w,  //
      x * y + z * w, 1.0 - (x * x + z * z), y * z - x * w,   //
      x * z - y * w, y * z + x * w, 1.0 - (x * x + y * y);
  return R;
}

TrajectoryView::TrajectoryView(Channels channels, std::span<const int64_t> stamps_ns, const double* positions,
                               const double* orientations, const double* velocities,
                               const double* angular_velocities)
    : channels_(channels),
      stamps_ns_(stamps_ns),
      positions_(positions),
      orientations_(orientations),
      velocities_(velocities),
      angular_velocities_(angular_velocities) {}

TrajectoryView::ConstMap4X TrajectoryView::quaternions() const {
  if (channels_.orientation != OrientationKind::kQuaternion) {
    throw std::logic_error("TrajectoryView::quaternions: orientations are not stored as quaternions");
  }
  return ConstMap4X(orientations_, 4, size());
}

Eigen::Matrix3d TrajectoryView::Rotation(Eigen::Index i) const {
  assert(i >= 0 && i < size());
  switch (channels_.orientation) {
    case OrientationKind::kQuaternion: {
      const double* q = orientations_ + 4 * i;
      return RotationFromQuaternion(q[0], q[1], q[2], q[3]);
    }
    case OrientationKind::kMatrix:
      return ConstRotationMap(orientations_ + 9 * i);
    case OrientationKind::kNone:
      break;
  }
  throw std::logic_error("TrajectoryView::Rotation: the trajectory has no orientation");
}

Eigen::Quaterniond TrajectoryView::UnitQuaternion(Eigen::Index i) const {
  assert(i >= 0 && i < size());
  if (channels_.orientation == OrientationKind::kQuaternion) {
    const double* q = orientations_ + 4 * i;
    Eigen::Quaterniond quaternion(q[3], q[0], q[1], q[2]);
    const double norm = quaternion.norm();
    if (norm < std::sqrt(8.881784197001252e-16)) return Eigen::Quaterniond::Identity();
    quaternion.coeffs() /= norm;
    return quaternion;
  }
  Eigen::Quaterniond quaternion(Rotation(i));
  quaternion.normalize();
  return quaternion;
}

TrajectoryView::ConstMap3X TrajectoryView::velocities() const {
  if (!channels_.velocity) throw std::logic_error("TrajectoryView::velocities: no velocity channel");
  return ConstMap3X(velocities_, 3, size());
}

TrajectoryView::ConstMap3X TrajectoryView::angular_velocities() const {
  if (!channels_.angular_velocity) {
    throw std::logic_error("TrajectoryView::angular_velocities: no angular-velocity channel");
  }
  return ConstMap3X(angular_velocities_, 3, size());
}

TrajectoryView TrajectoryView::Slice(Eigen::Index begin, Eigen::Index end) const {
  if (begin < 0 || end < begin || end > size()) throw std::out_of_range("TrajectoryView::Slice: bad range");
  const int stride = OrientationStride(channels_.orientation);
  auto offset = [begin](const double* base, int per_pose) { return base ? base + per_pose * begin : nullptr; };
  return TrajectoryView(channels_, stamps_ns_.subspan(begin, end - begin), offset(positions_, 3),
                        offset(orientations_, stride), offset(velocities_, 3), offset(angular_velocities_, 3));
}

Trajectory::Trajectory(Channels channels) : channels_(channels) {}

void Trajectory::Reserve(Eigen::Index n) {
  stamps_ns_.reserve(n);
  positions_.reserve(3 * n);
  orientations_.reserve(OrientationStride(channels_.orientation) * n);
  if (channels_.velocity) velocities_.reserve(3 * n);
  if (channels_.angular_velocity) angular_velocities_.reserve(3 * n);
}

void Trajectory::Append(int64_t stamp_ns, const double* position, const double* orientation, const double* velocity,
                        const double* angular_velocity) {
  stamps_ns_.push_back(stamp_ns);
  positions_.insert(positions_.end(), position, position + 3);
  const int stride = OrientationStride(channels_.orientation);
  if (stride > 0) orientations_.insert(orientations_.end(), orientation, orientation + stride);
  if (channels_.velocity) velocities_.insert(velocities_.end(), velocity, velocity + 3);
  if (channels_.angular_velocity) {
    angular_velocities_.insert(angular_velocities_.end(), angular_velocity, angular_velocity + 3);
  }
}

void Trajectory::SetVelocities(const Eigen::Ref<const Eigen::Matrix3Xd>& velocities) {
  if (velocities.cols() != size()) throw std::invalid_argument("Trajectory::SetVelocities: wrong number of columns");
  velocities_.resize(3 * size());
  Eigen::Map<Eigen::Matrix3Xd>(velocities_.data(), 3, size()) = velocities;
  channels_.velocity = true;
}

void Trajectory::SetAngularVelocities(const Eigen::Ref<const Eigen::Matrix3Xd>& angular_velocities) {
  if (angular_velocities.cols() != size()) {
    throw std::invalid_argument("Trajectory::SetAngularVelocities: wrong number of columns");
  }
  angular_velocities_.resize(3 * size());
  Eigen::Map<Eigen::Matrix3Xd>(angular_velocities_.data(), 3, size()) = angular_velocities;
  channels_.angular_velocity = true;
}

void Trajectory::SetStamps(std::vector<int64_t> stamps_ns) {
  if (static_cast<Eigen::Index>(stamps_ns.size()) != size()) {
    throw std::invalid_argument("Trajectory::SetStamps: wrong number of stamps");
  }
  stamps_ns_ = std::move(stamps_ns);
}

TrajectoryView Trajectory::View() const {
  auto data_or_null = [](const std::vector<double>& v) { return v.empty() ? nullptr : v.data(); };
  return TrajectoryView(channels_, stamps_ns_, data_or_null(positions_), data_or_null(orientations_),
                        channels_.velocity ? data_or_null(velocities_) : nullptr,
                        channels_.angular_velocity ? data_or_null(angular_velocities_) : nullptr);
}

}  // namespace cheval::traj

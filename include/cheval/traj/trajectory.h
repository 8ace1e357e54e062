#pragma once
/// \file
/// A stamped trajectory: stamps (int64 ns), positions, optional orientations, optional linear and
/// angular velocities. Storage is one contiguous std::vector<double> per channel, pose after pose,
/// so a channel is an Eigen::Map (3 x n, column i = pose i) and, for the Python face, a numpy array
/// of shape (n, 3) (or (n, 4) / (n, 3, 3) for orientations) without a copy. A TrajectoryView is a
/// cheap, non-owning slice of consecutive poses.
///
/// Frames and units: positions p_world_body in metres, velocities in the world frame in m/s (as
/// EuRoC's v_RS_R), angular velocities in the body frame in rad/s, rotations R_world_body.

#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace cheval::traj {

/// How a trajectory stores its orientations.
enum class OrientationKind {
  kNone,        ///< position only (e.g. motion capture of a single marker)
  kQuaternion,  ///< quaternions (x, y, z, w) exactly as read; Rotation() normalises them like evo
  kMatrix,      ///< 3x3 matrices, row-major, exactly as read (KITTI; may be slightly non-orthonormal)
};

/// Which channels a trajectory has. Stamps are always stored; `has_stamps` is false for files that
/// have none (KITTI without a times file), whose stamps are then the pose indices in seconds.
struct Channels {
  OrientationKind orientation = OrientationKind::kQuaternion;
  bool velocity = false;
  bool angular_velocity = false;
  bool has_stamps = true;

  bool operator==(const Channels&) const = default;
};

/// Rotation matrix of the quaternion (x, y, z, w) exactly as evo computes it (docs/formats.md): with
/// n = q·q, identity when n < 8.88e-16, else q scaled by sqrt(2/n) in the standard formula, so
/// non-unit quaternions are normalised.
Eigen::Matrix3d RotationFromQuaternion(double x, double y, double z, double w);

/// A non-owning view of poses [begin, end) of a Trajectory. Valid while the trajectory lives and
/// is not modified.
class TrajectoryView {
 public:
  using ConstMap3X = Eigen::Map<const Eigen::Matrix3Xd>;
  using ConstMap4X = Eigen::Map<const Eigen::Matrix4Xd>;
  using ConstRotationMap = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>;

  TrajectoryView(Channels channels, std::span<const int64_t> stamps_ns, const double* positions,
                 const double* orientations, const double* velocities, const double* angular_velocities);

  /// Number of poses.
  Eigen::Index size() const { return static_cast<Eigen::Index>(stamps_ns_.size()); }
  bool empty() const { return stamps_ns_.empty(); }
  const Channels& channels() const { return channels_; }
  bool has_orientation() const { return channels_.orientation != OrientationKind::kNone; }
  bool has_velocity() const { return channels_.velocity; }
  bool has_angular_velocity() const { return channels_.angular_velocity; }
  bool has_stamps() const { return channels_.has_stamps; }

  /// Stamps in nanoseconds, in file order (not necessarily increasing: readers keep what they read).
  std::span<const int64_t> stamps_ns() const { return stamps_ns_; }
  /// Positions, 3 x n; column i is p_world_body of pose i in metres.
  ConstMap3X positions() const { return ConstMap3X(positions_, 3, size()); }
  /// Quaternions (x, y, z, w) as read, 4 x n. Precondition: orientation kind is kQuaternion.
  ConstMap4X quaternions() const;
  /// Rotation matrix R_world_body of pose i: from the quaternion with evo's normalisation, or the
  /// stored matrix as read. Precondition: has_orientation().
  Eigen::Matrix3d Rotation(Eigen::Index i) const;
  /// Unit quaternion of pose i (the stored one normalised, or the matrix's, w >= 0 not enforced).
  /// Precondition: has_orientation().
  Eigen::Quaterniond UnitQuaternion(Eigen::Index i) const;
  /// World-frame linear velocities, 3 x n, m/s. Precondition: has_velocity().
  ConstMap3X velocities() const;
  /// Body-frame angular velocities, 3 x n, rad/s. Precondition: has_angular_velocity().
  ConstMap3X angular_velocities() const;

  /// Poses [begin, end) of this view, without copying. Precondition: 0 <= begin <= end <= size().
  TrajectoryView Slice(Eigen::Index begin, Eigen::Index end) const;

 private:
  Channels channels_;
  std::span<const int64_t> stamps_ns_;
  const double* positions_;
  const double* orientations_;
  const double* velocities_;
  const double* angular_velocities_;
};

/// An owning trajectory. Build it by Append()-ing poses in order, or read it from a file
/// (traj/io.h). Poses are kept in the order given; stamps are not required to increase.
class Trajectory {
 public:
  /// An empty trajectory with the given channels.
  explicit Trajectory(Channels channels = {});

  const Channels& channels() const { return channels_; }
  Eigen::Index size() const { return static_cast<Eigen::Index>(stamps_ns_.size()); }
  bool empty() const { return stamps_ns_.empty(); }

  /// Reserves room for `n` poses in every channel.
  void Reserve(Eigen::Index n);

  /// Appends one pose. `orientation` holds 4 values (x, y, z, w) for kQuaternion, 9 (row-major R)
  /// for kMatrix and is ignored for kNone; `velocity` / `angular_velocity` are read only when the
  /// channel exists. Callers validate values; this only stores them.
  void Append(int64_t stamp_ns, const double* position, const double* orientation = nullptr,
              const double* velocity = nullptr, const double* angular_velocity = nullptr);

  /// Replaces (or adds) the velocity channel; `velocities` is 3 x size().
  void SetVelocities(const Eigen::Ref<const Eigen::Matrix3Xd>& velocities);
  /// Replaces (or adds) the angular-velocity channel; 3 x size().
  void SetAngularVelocities(const Eigen::Ref<const Eigen::Matrix3Xd>& angular_velocities);
  /// Marks whether the stamps are real (false for KITTI without times).
  void SetHasStamps(bool has_stamps) { channels_.has_stamps = has_stamps; }
  /// Replaces all stamps; `stamps_ns.size()` must equal size().
  void SetStamps(std::vector<int64_t> stamps_ns);

  /// A view of all poses, or of poses [begin, end).
  TrajectoryView View() const;
  TrajectoryView View(Eigen::Index begin, Eigen::Index end) const { return View().Slice(begin, end); }

  // Convenience accessors, identical to those of View().
  std::span<const int64_t> stamps_ns() const { return stamps_ns_; }
  TrajectoryView::ConstMap3X positions() const { return View().positions(); }
  Eigen::Matrix3d Rotation(Eigen::Index i) const { return View().Rotation(i); }

  /// Raw channel storage, pose after pose (for zero-copy hand-off, e.g. to numpy).
  const std::vector<double>& raw_positions() const { return positions_; }
  const std::vector<double>& raw_orientations() const { return orientations_; }
  const std::vector<double>& raw_velocities() const { return velocities_; }
  const std::vector<double>& raw_angular_velocities() const { return angular_velocities_; }

 private:
  Channels channels_;
  std::vector<int64_t> stamps_ns_;
  std::vector<double> positions_;
  std::vector<double> orientations_;
  std::vector<double> velocities_;
  std::vector<double> angular_velocities_;
};

/// Values per pose of an orientation kind: 0, 4 or 9.
int OrientationStride(OrientationKind kind);

}  // namespace cheval::traj

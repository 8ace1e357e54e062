#pragma once
/// \file
/// Real flights with measured per-rotor speeds in the layout of the IDSIA Crazyflie 2.1 Brushless
/// data (shared/data/crazyflie_brushless_idsia/SOURCE.md; docs/estimator_real_data.md): a CSV with a
/// header naming its columns. The columns used (any order, others ignored):
/// `t`, `x_mocap,y_mocap,z_mocap` (motion-capture position, world, m), `qw,qx,qy,qz` (onboard
/// attitude R_world_body, normalised here: the stored ones are not unit), `wx,wy,wz` (body rate,
/// rad/s), `m1_erpm..m4_erpm` (ESC electrical rpm), `ax,ay,az` (accelerometer: the specific force in the
/// world frame, m/s², although SOURCE.md says body; docs/estimator_real_data.md, "The accelerometer"),
/// `is_flying` (0/1).

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace cheval::estim {

/// Electrical revolutions per mechanical revolution of the Crazyflie Brushless motors (as the data's
/// authors convert: ω = eRPM · 2π / (6 · 60)).
inline constexpr double kCrazyflieElectricalPerMechanical = 6.0;

/// The most bytes a flight CSV may have (a minute at 100 Hz is ~2 MB).
inline constexpr uint64_t kMaxRotorFlightBytes = uint64_t{1} << 30;

/// The columns a flight CSV must have, in the order of RotorSample's fields.
const std::vector<std::string>& RotorFlightColumns();

/// One row of a flight.
struct RotorSample {
  double t = 0;                                           ///< s
  Eigen::Vector3d p = Eigen::Vector3d::Zero();            ///< motion-capture position, world, m
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();  ///< R_world_body, unit
  Eigen::Vector3d w = Eigen::Vector3d::Zero();            ///< body rate, rad/s
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();        ///< accelerometer (specific force), world frame, m/s²
  Eigen::Vector4d rotor = Eigen::Vector4d::Zero();        ///< measured rotor speeds m1..m4, rad/s
  bool flying = false;                                    ///< is_flying
  /// The motion-capture position differs from the previous row's: the capture system delivers
  /// fewer fresh positions than rows (10–22 % of the rows repeat the previous one), so a repeated
  /// position is not a measurement at this row's time.
  bool fresh_position = true;
};

/// A flight as read.
struct RotorFlight {
  std::string path;
  std::vector<RotorSample> samples;  ///< strictly increasing t, rows with a missing value dropped
  /// File lines (1-based) of the rows dropped because a used column held NaN or nothing.
  std::vector<int64_t> dropped_lines;
  /// [first, last] time of each run of consecutive is_flying = 1 rows.
  std::vector<std::pair<double, double>> flying_spans;
};

/// Reads a flight CSV. Throws InputError (`path:line:column: error: ...`) when the file cannot be read
/// or exceeds kMaxRotorFlightBytes, has no header, lacks a used column (naming it and listing the
/// missing ones), a row has another number of fields than the header, a used field is not a number,
/// times do not increase, a quaternion has squared norm <= 1e-12, a rotor speed is negative,
/// is_flying is not 0 or 1, or fewer than 3 rows remain. Rows where a used field is NaN or empty are
/// dropped and listed in dropped_lines (never zero-filled).
RotorFlight ReadRotorFlight(const std::string& path);

/// The samples to score: flying, at least `margin_s` after the start and before the end of their
/// flying span (the "flying samples less 0.5 s at each end"). Indices into flight.samples.
std::vector<size_t> ScoredSamples(const RotorFlight& flight, double margin_s = 0.5);

}  // namespace cheval::estim

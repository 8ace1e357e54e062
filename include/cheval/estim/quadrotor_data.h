#pragma once
/// \file
/// The quadrotor estimator's input as a data folder (docs/estimator.md, "Data folder"): the vehicle,
/// the landmarks, the camera's pixel measurements, the front end's initial poses and, for
/// evaluation only, the ground truth. `cheval sim quadrotor` writes one (sim::SimulateQuadrotor
/// produces a QuadrotorData); `cheval estimate quadrotor --data` reads one.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "cheval/estim/quadrotor_estimator.h"
#include "cheval/estim/vehicle.h"

namespace cheval::estim {

/// The files of a data folder, in the order WriteQuadrotorData writes them (truth.csv is optional).
inline constexpr std::array<std::string_view, 5> kQuadrotorDataFiles = {"vehicle.json", "landmarks.csv",
                                                                     "measurements.csv", "initial.csv", "truth.csv"};

/// Bounds of a data folder's values (docs/estimator.md, "Data folder"): beyond them a value is an
/// InputError naming the file and line. Each CSV file is at most kMaxDataFileBytes bytes.
inline constexpr uint64_t kMaxDataFileBytes = uint64_t{1} << 30;
inline constexpr double kMaxDataTime = 1e10;        ///< |t|, s (epoch seconds fit)
inline constexpr double kMaxDataCoordinate = 1e6;   ///< |x|, |y|, |z| of landmarks and positions, m
inline constexpr double kMaxDataPixel = 1e6;        ///< |u|, |v|, px
inline constexpr double kMaxDataRate = 1e6;         ///< truth.csv: |velocity|, |body rate| per axis; rotor speed

/// The state of the vehicle at one time, as truth.csv holds it: the exact state in a simulated
/// folder, an estimate's state when EstimatedStates (quadrotor_scoring.h) converts one.
struct QuadrotorTruth {
  double t = 0;                    ///< s
  Eigen::Vector3d p;               ///< position, world, m
  Eigen::Quaterniond q;            ///< R_world_body
  Eigen::Vector3d v;               ///< velocity, world, m/s
  Eigen::Vector3d w;               ///< body rate, rad/s
  Eigen::Vector4d rotor;           ///< rotor speeds Ω_0..3, rad/s
};

/// Everything the estimator gets (vehicle, landmarks, measurements, initial poses) and, for
/// evaluation only, the ground truth (empty when a data folder has none).
struct QuadrotorData {
  Vehicle vehicle;
  std::vector<Eigen::Vector3d> landmarks;
  std::vector<PixelObservation> pixels;  ///< sorted by time; landmark indexes into `landmarks`
  std::vector<PoseSample> initial;       ///< one per camera frame
  std::vector<QuadrotorTruth> truth;     ///< at the simulator's truth rate; empty if none
  int saturated_steps = 0;               ///< simulator only: RK4 steps where a rotor command hit 0 or the limit
};

/// The CSV text of states as truth.csv holds them (docs/estimator.md): header
/// `t,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz,rotor0,rotor1,rotor2,rotor3`, numbers with 17
/// significant digits. `cheval estimate quadrotor -o FILE` writes an estimate this way.
std::string QuadrotorStatesCsv(const std::vector<QuadrotorTruth>& states);

/// Writes a data folder (docs/estimator.md): vehicle.json, landmarks.csv, measurements.csv,
/// initial.csv and, when `data.truth` is not empty, truth.csv. Written whole or not at all
/// (common/output.h, StagedFolder): the files go to a staging folder beside `folder` that is renamed
/// into place. An existing folder that holds only data-folder files (an earlier run) is replaced
/// whole; any other non-empty existing folder is refused, so two runs are never mixed and unrelated
/// files are never deleted. OutputError when the folder cannot be written or is refused.
void WriteQuadrotorData(const QuadrotorData& data, const std::string& folder);

/// Reads a data folder. truth.csv is optional; every other file is required. Lines end in LF or
/// CRLF; a first line that does not start with a number is a header. InputError `FILE:LINE:COLUMN:
/// error: ...` for a missing, unreadable or too large file, a path that is a directory, a row without
/// exactly the file's columns of finite numbers, a value beyond the bounds above, landmark ids not
/// 0, 1, 2, ..., a measurement of an unknown landmark, measurement times that decrease, initial or
/// truth times that do not increase, a zero (or overflowing) quaternion, a negative rotor speed, or
/// fewer than 2 initial poses.
QuadrotorData ReadQuadrotorData(const std::string& folder);

}  // namespace cheval::estim

#pragma once
/// \file
/// A quadrotor vehicle and its camera, read from a JSON file (docs/estimator.md has the keys).
/// Vehicle parameters always come from a file: the shipped default is
/// data/vehicles/flightgoggles.json (FlightGoggles' drone, docs/estimator.md).

#include <string>

#include <Eigen/Core>

#include "cheval/estim/models.h"

namespace cheval::estim {

/// The highest camera rate a vehicle file may give (`camera.rate_hz`), Hz: the simulator makes one
/// frame per period, and faster cameras than this do not fly on quadrotors.
inline constexpr double kMaxCameraRateHz = 1000.0;

/// A pinhole camera rigidly mounted on the body, looking forward: optical axis z_c = body x,
/// x_c = −body y (image right), y_c = −body z (image down); optical centre at the body origin.
/// Pixel (u, v) = (fx X/Z + cx, fy Y/Z + cy) for a point (X, Y, Z) in the camera frame, Z > 0.
struct PinholeCamera {
  double fx = 0, fy = 0, cx = 0, cy = 0;  ///< intrinsics, pixels (fx, fy > 0)
  int width = 0, height = 0;              ///< image size, pixels (> 0)
  double rate_hz = 0;                     ///< frame rate of the simulator, > 0
  double pixel_noise_px = 0;              ///< σ of the simulator's Gaussian pixel noise, >= 0

  /// R_body_camera of the mounting described above.
  static Eigen::Matrix3d BodyFromCamera();
};

/// A vehicle file: the quadrotor's physics and its camera.
struct Vehicle {
  std::string name;  ///< "name" in the file (may be empty)
  QuadrotorParameters quadrotor;
  PinholeCamera camera;
};

/// Reads and validates a vehicle JSON file (at most 1 MiB). Throws InputError (`path:0:0: error:
/// ...`) when the path is a directory, the file cannot be read or parsed, a number is beyond a double
/// (naming its key), a key is unknown, missing or not a number, or a value is outside its documented
/// range (docs/estimator.md, "Vehicle file": e.g. mass in (0, 1e4] kg, camera.rate_hz in (0, 1000],
/// camera.width and height integers in [1, 1e5]); the inertia must satisfy the triangle
/// inequalities of a rigid body (J_x + J_y >= J_z, ...), and the hover speed must be below the rotor
/// speed limit.
Vehicle ReadVehicle(const std::string& path);

/// Validates a vehicle built in code; throws InputError with `path` as the location (may be
/// "<vehicle>").
void ValidateVehicle(const Vehicle& vehicle, const std::string& path);

/// The vehicle as JSON text, readable by ReadVehicle (used to write a simulated data folder).
std::string VehicleToJson(const Vehicle& vehicle);

}  // namespace cheval::estim

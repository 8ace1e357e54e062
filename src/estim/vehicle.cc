#include "cheval/estim/vehicle.h"

#include <fmt/format.h>

#include <cmath>
#include <algorithm>
#include <initializer_list>
#include <utility>
#include <nlohmann/json.hpp>

#include "cheval/common/error.h"
#include "cheval/common/input_file.h"

namespace cheval::estim {
namespace {

using nlohmann::json;

// A vehicle file is a few hundred bytes; anything beyond this is not one.
constexpr uint64_t kMaxVehicleFileBytes = 1 << 20;

void Require(bool ok, const std::string& path, const std::string& what) {
  if (!ok) throw InputError(path, 0, 0, what);
}

// The documented range of each number (docs/estimator.md, "Vehicle file"): wide enough for any
// real multirotor, narrow enough that nothing computed from them overflows.
struct Range {
  const char* key;
  double low;
  bool low_open;  // (low, ...] instead of [low, ...]
  double high;
};

constexpr Range kMass{"mass_kg", 0, true, 1e4};
constexpr Range kInertia{"inertia_kgm2", 0, true, 1e4};
constexpr Range kArm{"arm_m", 0, true, 100};
constexpr Range kThrustCoefficient{"thrust_coefficient", 0, true, 1};
constexpr Range kMomentCoefficient{"moment_coefficient", 0, false, 1};
constexpr Range kMotorTimeConstant{"motor_time_constant_s", 0, true, 10};
constexpr Range kMaxRotorSpeed{"max_rotor_speed_radps", 0, true, 1e5};
constexpr Range kDrag{"drag_coefficient", 0, false, 1e3};
constexpr Range kGravity{"gravity_mps2", 0, true, 100};
constexpr Range kFocal{"", 0, true, 1e6};
constexpr Range kCentre{"", -1e6, false, 1e6};
constexpr Range kImageSize{"", 1, false, 1e5};
constexpr Range kRate{"camera.rate_hz", 0, true, kMaxCameraRateHz};
constexpr Range kPixelNoise{"camera.pixel_noise_px", 0, false, 1e3};

bool InRange(double value, const Range& range) {
  return std::isfinite(value) && (range.low_open ? value > range.low : value >= range.low) && value <= range.high;
}

std::string RangeText(const Range& range) {
  if (range.low == 0 && range.low_open) return fmt::format("a finite number > 0 and <= {}", range.high);
  if (range.low == 0) return fmt::format("a finite number >= 0 and <= {}", range.high);
  return fmt::format("a finite number in [{}, {}]", range.low, range.high);
}

void Check(double value, const Range& range, const std::string& key, const std::string& path) {
  Require(InRange(value, range), path, fmt::format("\"{}\" must be {}, got {}", key, RangeText(range), value));
}

const json& Member(const json& object, const std::string& key, const std::string& path, const std::string& where) {
  if (!object.contains(key)) throw InputError(path, 0, 0, fmt::format("missing key \"{}{}\"", where, key));
  return object.at(key);
}

double Number(const json& object, const std::string& key, const std::string& path, const std::string& where) {
  const json& value = Member(object, key, path, where);
  if (!value.is_number()) throw InputError(path, 0, 0, fmt::format("\"{}{}\" must be a number", where, key));
  return value.get<double>();
}

// An integer-valued number within `range` (checked here, before the conversion to int).
int Integer(const json& object, const std::string& key, const std::string& path, const std::string& where,
            const Range& range) {
  const double value = Number(object, key, path, where);
  Require(InRange(value, range) && value == std::floor(value), path,
          fmt::format("\"{}{}\" must be an integer in [{}, {}], got {}", where, key, range.low, range.high, value));
  return static_cast<int>(value);
}

// Keys of the object other than `allowed`: a misspelt optional key would otherwise be ignored.
void CheckKeys(const json& object, std::initializer_list<const char*> allowed, const std::string& where,
               const std::string& path) {
  for (const auto& item : object.items()) {
    const std::string& key = item.key();
    if (std::find_if(allowed.begin(), allowed.end(), [&](const char* a) { return key == a; }) == allowed.end()) {
      std::string names;
      for (const char* a : allowed) names += (names.empty() ? "" : ", ") + std::string(a);
      std::string shown = key.substr(0, 40);
      for (char& c : shown) c = (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) ? '?' : c;
      throw InputError(path, 0, 0,
                       fmt::format("unknown key \"{}{}\"{}; expected only {}", where, shown,
                                   key.size() > 40 ? "..." : "", names));
    }
  }
}

}  // namespace

Eigen::Matrix3d PinholeCamera::BodyFromCamera() {
  Eigen::Matrix3d r;
  // Columns: the camera axes x_c, y_c, z_c in body coordinates.
  r << 0, 0, 1,  //
      -1, 0, 0,  //
      0, -1, 0;
  return r;
}

void ValidateVehicle(const Vehicle& vehicle, const std::string& path) {
  const QuadrotorParameters& q = vehicle.quadrotor;
  Check(q.mass_kg, kMass, kMass.key, path);
  for (int i = 0; i < 3; ++i) {
    Require(InRange(q.inertia_kgm2[i], kInertia), path,
            fmt::format("\"inertia_kgm2\" must hold 3 finite numbers > 0 and <= {} (a singular or negative inertia "
                        "is not a rigid body), got [{}, {}, {}]",
                        kInertia.high, q.inertia_kgm2[0], q.inertia_kgm2[1], q.inertia_kgm2[2]));
  }
  const Eigen::Vector3d& J = q.inertia_kgm2;
  Require(J[0] + J[1] >= J[2] && J[1] + J[2] >= J[0] && J[0] + J[2] >= J[1], path,
          fmt::format("\"inertia_kgm2\" [{}, {}, {}] violates the triangle inequality of a rigid body's principal "
                      "moments (J_x + J_y >= J_z, ...)",
                      J[0], J[1], J[2]));
  const std::pair<double, const Range*> quadrotor[] = {
      {q.arm_m, &kArm},
      {q.thrust_coefficient, &kThrustCoefficient},
      {q.moment_coefficient, &kMomentCoefficient},
      {q.motor_time_constant_s, &kMotorTimeConstant},
      {q.max_rotor_speed_radps, &kMaxRotorSpeed},
      {q.drag_coefficient, &kDrag},
      {q.gravity_mps2, &kGravity}};
  for (const auto& [value, range] : quadrotor) Check(value, *range, range->key, path);
  Require(q.HoverRotorSpeed() < q.max_rotor_speed_radps, path,
          fmt::format("the hover rotor speed sqrt(m g / 4 k_F) = {:.4g} rad/s is not below \"max_rotor_speed_radps\" "
                      "= {}: this vehicle cannot fly",
                      q.HoverRotorSpeed(), q.max_rotor_speed_radps));
  const PinholeCamera& c = vehicle.camera;
  Check(c.fx, kFocal, "camera.fx", path);
  Check(c.fy, kFocal, "camera.fy", path);
  Check(c.cx, kCentre, "camera.cx", path);
  Check(c.cy, kCentre, "camera.cy", path);
  Check(c.width, kImageSize, "camera.width", path);
  Check(c.height, kImageSize, "camera.height", path);
  Check(c.rate_hz, kRate, kRate.key, path);
  Check(c.pixel_noise_px, kPixelNoise, kPixelNoise.key, path);
}

Vehicle ReadVehicle(const std::string& path) {
  const std::string text = ReadInputFile(path, kMaxVehicleFileBytes, "a vehicle JSON file");
  const json root = ParseJsonInput(text, path, "a vehicle file");
  Require(root.is_object(), path, "expected a JSON object (a vehicle file)");
  CheckKeys(root,
            {"name", "source", "mass_kg", "inertia_kgm2", "arm_m", "thrust_coefficient", "moment_coefficient",
             "motor_time_constant_s", "max_rotor_speed_radps", "drag_coefficient", "gravity_mps2", "camera"},
            "", path);
  Vehicle vehicle;
  if (root.contains("name")) {
    Require(root["name"].is_string(), path, "\"name\" must be a string");
    vehicle.name = root["name"].get<std::string>();
  }
  QuadrotorParameters& q = vehicle.quadrotor;
  q.mass_kg = Number(root, "mass_kg", path, "");
  const json& inertia = Member(root, "inertia_kgm2", path, "");
  Require(inertia.is_array() && inertia.size() == 3, path,
          "\"inertia_kgm2\" must be an array of 3 numbers (the diagonal, body x y z)");
  for (size_t i = 0; i < 3; ++i) {
    Require(inertia[i].is_number(), path, "\"inertia_kgm2\" must be an array of 3 numbers");
    q.inertia_kgm2[static_cast<Eigen::Index>(i)] = inertia[i].get<double>();
  }
  q.arm_m = Number(root, "arm_m", path, "");
  q.thrust_coefficient = Number(root, "thrust_coefficient", path, "");
  q.moment_coefficient = Number(root, "moment_coefficient", path, "");
  q.motor_time_constant_s = Number(root, "motor_time_constant_s", path, "");
  q.max_rotor_speed_radps = Number(root, "max_rotor_speed_radps", path, "");
  q.drag_coefficient = Number(root, "drag_coefficient", path, "");
  if (root.contains("gravity_mps2")) q.gravity_mps2 = Number(root, "gravity_mps2", path, "");
  Require(root.contains("camera") && root["camera"].is_object(), path, "missing object \"camera\"");
  const json& cam = root["camera"];
  CheckKeys(cam, {"fx", "fy", "cx", "cy", "width", "height", "rate_hz", "pixel_noise_px"}, "camera.", path);
  PinholeCamera& c = vehicle.camera;
  c.fx = Number(cam, "fx", path, "camera.");
  c.fy = Number(cam, "fy", path, "camera.");
  c.cx = Number(cam, "cx", path, "camera.");
  c.cy = Number(cam, "cy", path, "camera.");
  c.width = Integer(cam, "width", path, "camera.", kImageSize);
  c.height = Integer(cam, "height", path, "camera.", kImageSize);
  c.rate_hz = Number(cam, "rate_hz", path, "camera.");
  c.pixel_noise_px = Number(cam, "pixel_noise_px", path, "camera.");
  ValidateVehicle(vehicle, path);
  return vehicle;
}

std::string VehicleToJson(const Vehicle& vehicle) {
  const QuadrotorParameters& q = vehicle.quadrotor;
  const PinholeCamera& c = vehicle.camera;
  json root = {{"name", vehicle.name},
               {"mass_kg", q.mass_kg},
               {"inertia_kgm2", {q.inertia_kgm2[0], q.inertia_kgm2[1], q.inertia_kgm2[2]}},
               {"arm_m", q.arm_m},
               {"thrust_coefficient", q.thrust_coefficient},
               {"moment_coefficient", q.moment_coefficient},
               {"motor_time_constant_s", q.motor_time_constant_s},
               {"max_rotor_speed_radps", q.max_rotor_speed_radps},
               {"drag_coefficient", q.drag_coefficient},
               {"gravity_mps2", q.gravity_mps2},
               {"camera",
                {{"fx", c.fx},
                 {"fy", c.fy},
                 {"cx", c.cx},
                 {"cy", c.cy},
                 {"width", c.width},
                 {"height", c.height},
                 {"rate_hz", c.rate_hz},
                 {"pixel_noise_px", c.pixel_noise_px}}}};
  return root.dump(2) + "\n";
}

}  // namespace cheval::estim

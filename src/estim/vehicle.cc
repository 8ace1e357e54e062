#include "cheval/estim/vehicle.h"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cheval/common/error.h"

namespace cheval::estim {
namespace {

using nlohmann::json;

double Number(const json& object, const std::string& key, const std::string& path, const std::string& where) {
  if (!object.contains(key)) throw InputError(path, 0, 0, fmt::format("missing key \"{}{}\"", where, key));
  const json& value = object.at(key);
  if (!value.is_number()) throw InputError(path, 0, 0, fmt::format("\"{}{}\" must be a number", where, key));
  return value.get<double>();
}

void Require(bool ok, const std::string& path, const std::string& what) {
  if (!ok) throw InputError(path, 0, 0, what);
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
  auto positive = [&](double value, const char* key) {
    Require(std::isfinite(value) && value > 0, path, fmt::format("\"{}\" must be a finite number > 0, got {}", key, value));
  };
  auto non_negative = [&](double value, const char* key) {
    Require(std::isfinite(value) && value >= 0, path, fmt::format("\"{}\" must be a finite number >= 0, got {}", key, value));
  };
  positive(q.mass_kg, "mass_kg");
  for (int i = 0; i < 3; ++i) {
    Require(std::isfinite(q.inertia_kgm2[i]) && q.inertia_kgm2[i] > 0, path,
            fmt::format("\"inertia_kgm2\" must hold 3 finite numbers > 0 (a singular or negative inertia is not a "
                        "rigid body), got [{}, {}, {}]",
                        q.inertia_kgm2[0], q.inertia_kgm2[1], q.inertia_kgm2[2]));
  }
  const Eigen::Vector3d& J = q.inertia_kgm2;
  Require(J[0] + J[1] >= J[2] && J[1] + J[2] >= J[0] && J[0] + J[2] >= J[1], path,
          fmt::format("\"inertia_kgm2\" [{}, {}, {}] violates the triangle inequality of a rigid body's principal "
                      "moments (J_x + J_y >= J_z, ...)",
                      J[0], J[1], J[2]));
  positive(q.arm_m, "arm_m");
  positive(q.thrust_coefficient, "thrust_coefficient");
  non_negative(q.moment_coefficient, "moment_coefficient");
  positive(q.motor_time_constant_s, "motor_time_constant_s");
  positive(q.max_rotor_speed_radps, "max_rotor_speed_radps");
  non_negative(q.drag_coefficient, "drag_coefficient");
  positive(q.gravity_mps2, "gravity_mps2");
  Require(q.HoverRotorSpeed() < q.max_rotor_speed_radps, path,
          fmt::format("the hover rotor speed sqrt(m g / 4 k_F) = {:.1f} rad/s is not below \"max_rotor_speed_radps\" "
                      "= {}: this vehicle cannot fly",
                      q.HoverRotorSpeed(), q.max_rotor_speed_radps));
  const PinholeCamera& c = vehicle.camera;
  positive(c.fx, "camera.fx");
  positive(c.fy, "camera.fy");
  Require(std::isfinite(c.cx) && std::isfinite(c.cy), path, "\"camera.cx\" and \"camera.cy\" must be finite");
  Require(c.width > 0 && c.height > 0, path, "\"camera.width\" and \"camera.height\" must be > 0");
  positive(c.rate_hz, "camera.rate_hz");
  non_negative(c.pixel_noise_px, "camera.pixel_noise_px");
}

Vehicle ReadVehicle(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, 0, 0, "cannot open the vehicle file");
  std::stringstream text;
  text << in.rdbuf();
  json root;
  try {
    root = json::parse(text.str());
  } catch (const json::parse_error& e) {
    throw InputError(path, 0, 0, fmt::format("not valid JSON: {}", e.what()));
  }
  Require(root.is_object(), path, "expected a JSON object");
  Vehicle vehicle;
  if (root.contains("name") && root["name"].is_string()) vehicle.name = root["name"].get<std::string>();
  QuadrotorParameters& q = vehicle.quadrotor;
  q.mass_kg = Number(root, "mass_kg", path, "");
  Require(root.contains("inertia_kgm2") && root["inertia_kgm2"].is_array() && root["inertia_kgm2"].size() == 3, path,
          "\"inertia_kgm2\" must be an array of 3 numbers (the diagonal, body x y z)");
  for (int i = 0; i < 3; ++i) {
    Require(root["inertia_kgm2"][i].is_number(), path, "\"inertia_kgm2\" must be an array of 3 numbers");
    q.inertia_kgm2[i] = root["inertia_kgm2"][i].get<double>();
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
  PinholeCamera& c = vehicle.camera;
  c.fx = Number(cam, "fx", path, "camera.");
  c.fy = Number(cam, "fy", path, "camera.");
  c.cx = Number(cam, "cx", path, "camera.");
  c.cy = Number(cam, "cy", path, "camera.");
  c.width = static_cast<int>(Number(cam, "width", path, "camera."));
  c.height = static_cast<int>(Number(cam, "height", path, "camera."));
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

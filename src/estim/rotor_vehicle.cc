// The rotor vehicle file (rotor_estimator.h; keys in docs/estimator_real_data.md).
#include <fmt/format.h>

#include <cmath>
#include <set>

#include <nlohmann/json.hpp>

#include "cheval/common/error.h"
#include "cheval/common/input_file.h"
#include "cheval/estim/rotor_estimator.h"

namespace cheval::estim {
namespace {

using nlohmann::json;

void Require(bool ok, const std::string& path, const std::string& what) {
  if (!ok) throw InputError(path, 0, 0, what);
}

double Positive(const json& root, const std::string& key, const std::string& path, double high) {
  Require(root.contains(key), path, fmt::format("missing key \"{}\"", key));
  Require(root[key].is_number(), path, fmt::format("\"{}\" must be a number", key));
  const double x = root[key].get<double>();
  Require(std::isfinite(x) && x > 0 && x <= high, path,
          fmt::format("\"{}\" must be a finite number > 0 and <= {}, got {}", key, high, x));
  return x;
}

// An array of `size` finite numbers, each |x| <= bound (and > 0 when `positive`).
Eigen::VectorXd Numbers(const json& value, const std::string& key, const std::string& path, int size, double bound,
                        bool positive) {
  Require(value.is_array() && static_cast<int>(value.size()) == size, path,
          fmt::format("\"{}\" must be an array of {} numbers", key, size));
  Eigen::VectorXd out(size);
  for (int i = 0; i < size; ++i) {
    Require(value[i].is_number(), path, fmt::format("\"{}\"[{}] must be a number", key, i));
    out[i] = value[i].get<double>();
    Require(std::isfinite(out[i]) && std::abs(out[i]) <= bound && (!positive || out[i] > 0), path,
            fmt::format("\"{}\"[{}] must be a finite number {}within ±{}, got {}", key, i, positive ? "> 0 " : "",
                        bound, out[i]));
  }
  return out;
}

// One row of the human-readable parameter table: name, value, σ, published value, unit.
json Parameter(const std::string& name, double value, double sigma, double published, const std::string& unit) {
  return json{{"name", name}, {"value", value}, {"sigma", sigma}, {"published", published}, {"unit", unit}};
}

}  // namespace

RotorVehicle ReadRotorVehicle(const std::string& path) {
  const std::string text = ReadInputFile(path, 1 << 20, "a rotor vehicle JSON file");
  const json root = ParseJsonInput(text, path, "a rotor vehicle file");
  Require(root.is_object(), path, "expected a JSON object (a rotor vehicle file)");
  static const std::set<std::string> keys = {"name",        "source",       "mass_kg",      "arm_m",
                                             "thrust_coefficient", "moment_coefficient", "inertia_kgm2",
                                             "gravity_mps2", "identified"};
  for (const auto& item : root.items()) {
    Require(keys.count(item.key()) > 0, path, fmt::format("unknown key \"{}\"", item.key()));
  }
  RotorVehicle v;
  for (const char* key : {"name", "source"}) {
    if (!root.contains(key)) continue;
    Require(root[key].is_string(), path, fmt::format("\"{}\" must be a string", key));
    (std::string(key) == "name" ? v.name : v.source) = root[key].get<std::string>();
  }
  v.nominal.mass_kg = Positive(root, "mass_kg", path, 1e4);
  v.nominal.arm_m = Positive(root, "arm_m", path, 100);
  v.nominal.thrust_coefficient = Positive(root, "thrust_coefficient", path, 1);
  v.nominal.moment_coefficient = Positive(root, "moment_coefficient", path, 1);
  Require(root.contains("inertia_kgm2"), path, "missing key \"inertia_kgm2\"");
  v.nominal.inertia_kgm2 = Numbers(root["inertia_kgm2"], "inertia_kgm2", path, 3, 1e4, true);
  if (root.contains("gravity_mps2")) v.nominal.gravity_mps2 = Positive(root, "gravity_mps2", path, 100);
  if (root.contains("identified")) {
    const json& id = root["identified"];
    Require(id.is_object() && id.contains("theta") && id.contains("theta_sigma"), path,
            "\"identified\" must be an object with \"theta\" and \"theta_sigma\"");
    v.theta = Numbers(id["theta"], "identified.theta", path, kRotorThetaSize, 1e6, false);
    v.theta_sigma = Numbers(id["theta_sigma"], "identified.theta_sigma", path, kRotorThetaSize, 1e6, false);
    for (int i = 0; i < 3; ++i) {
      Require(v.theta[kThetaInertiaX + i] > 0, path, "identified inertia scales must be > 0");
    }
    if (id.contains("training") && id["training"].is_array()) {
      for (const json& t : id["training"]) {
        if (t.is_string()) v.training.push_back(t.get<std::string>());
      }
    }
  }
  return v;
}

std::string RotorVehicleToJson(const RotorVehicle& v) {
  const RotorNominal& n = v.nominal;
  json root = {{"name", v.name},
               {"source", v.source},
               {"mass_kg", n.mass_kg},
               {"arm_m", n.arm_m},
               {"thrust_coefficient", n.thrust_coefficient},
               {"moment_coefficient", n.moment_coefficient},
               {"inertia_kgm2", {n.inertia_kgm2.x(), n.inertia_kgm2.y(), n.inertia_kgm2.z()}},
               {"gravity_mps2", n.gravity_mps2}};
  if (v.theta_sigma.isZero()) return root.dump(2) + "\n";
  const RotorThetaVector& t = v.theta;
  const RotorThetaVector& s = v.theta_sigma;
  json params = json::array();
  for (int i = 0; i < 4; ++i) {
    params.push_back(Parameter(fmt::format("thrust_coefficient_m{}", i + 1), n.thrust_coefficient * t[i],
                               n.thrust_coefficient * s[i], n.thrust_coefficient, "N/(rad/s)^2"));
  }
  const char* axes = "xyz";
  for (int i = 0; i < 3; ++i) {
    params.push_back(Parameter(fmt::format("inertia_{}", axes[i]), n.inertia_kgm2[i] * t[kThetaInertiaX + i],
                               n.inertia_kgm2[i] * s[kThetaInertiaX + i], n.inertia_kgm2[i], "kg m^2"));
  }
  params.push_back(Parameter("moment_coefficient", n.moment_coefficient * t[kThetaMoment],
                             n.moment_coefficient * s[kThetaMoment], n.moment_coefficient, "N m/(rad/s)^2"));
  const double jx = n.inertia_kgm2.x() * t[kThetaInertiaX];
  params.push_back(Parameter("inertia_ratio_y_x", n.inertia_kgm2.y() * t[kThetaInertiaX + 1] / jx, std::nan(""),
                             n.inertia_kgm2.y() / n.inertia_kgm2.x(), "1"));
  params.push_back(Parameter("inertia_ratio_z_x", n.inertia_kgm2.z() * t[kThetaInertiaX + 2] / jx, std::nan(""),
                             n.inertia_kgm2.z() / n.inertia_kgm2.x(), "1"));
  for (int i = 0; i < 3; ++i) {
    params.push_back(Parameter(fmt::format("torque_offset_{}", axes[i]), kRotorTorqueUnit * t[kThetaTorqueX + i],
                               kRotorTorqueUnit * s[kThetaTorqueX + i], 0, "N m"));
  }
  params.push_back(Parameter("rotor_drag_xy", kRotorDragUnit * t[kThetaDragXY], kRotorDragUnit * s[kThetaDragXY], 0,
                             "(m/s^2)/((rad/s)(m/s))"));
  params.push_back(Parameter("rotor_drag_z", kRotorDragUnit * t[kThetaDragZ], kRotorDragUnit * s[kThetaDragZ], 0,
                             "(m/s^2)/((rad/s)(m/s))"));
  params.push_back(Parameter("rotor_moment_x", kRotorFlapUnit * t[kThetaFlapX], kRotorFlapUnit * s[kThetaFlapX], 0,
                             "N m/((rad/s)(m/s))"));
  params.push_back(Parameter("rotor_moment_y", kRotorFlapUnit * t[kThetaFlapX + 1],
                             kRotorFlapUnit * s[kThetaFlapX + 1], 0, "N m/((rad/s)(m/s))"));
  params.push_back(Parameter("rotor_inertia", kRotorInertiaUnit * t[kThetaRotorInertia],
                             kRotorInertiaUnit * s[kThetaRotorInertia], 0, "kg m^2"));
  for (json& p : params) {
    if (std::isnan(p["sigma"].get<double>())) p["sigma"] = nullptr;
  }
  root["identified"] = {{"theta", std::vector<double>(t.data(), t.data() + kRotorThetaSize)},
                        {"theta_sigma", std::vector<double>(s.data(), s.data() + kRotorThetaSize)},
                        {"training", v.training},
                        {"parameters", params}};
  return root.dump(2) + "\n";
}

}  // namespace cheval::estim

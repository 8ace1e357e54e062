#include "estim_fuzz_checks.h"

#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cheval/cheb/model.h"
#include "cheval/common/error.h"
#include "cheval/estim/quadrotor_data.h"
#include "cheval/estim/vehicle.h"
#include "cheval/sim/quadrotor.h"

namespace cheval::fuzz {
namespace {

namespace fs = std::filesystem;

std::string Printable(std::string_view data) {
  std::string out;
  for (char c : data.substr(0, 400)) {
    const auto u = static_cast<unsigned char>(c);
    out += (u >= 0x20 && u < 0x7f) || c == '\n' ? std::string(1, c) : fmt::format("\\x{:02x}", u);
  }
  return out;
}

std::string Violation(const char* property, int line, std::string_view data, const std::string& detail = "") {
  return fmt::format("property violated: {} (fuzz/estim_fuzz_checks.cc:{}){}{}\ninput: {}", property, line,
                     detail.empty() ? "" : ": ", detail, Printable(data));
}

// A folder of this process for the targets' files.
const fs::path& Scratch() {
  static const fs::path dir = [] {
    const fs::path d = fs::temp_directory_path() / fmt::format("cheval_fuzz_estim_{}", ::getpid());
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

void WriteFile(const fs::path& path, std::string_view data) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(data.data(), static_cast<std::streamsize>(data.size()));
}

bool StartsWith(const std::string& text, const std::string& prefix) { return text.rfind(prefix, 0) == 0; }

bool Finite(const estim::Vehicle& v) {
  const estim::QuadrotorParameters& q = v.quadrotor;
  const estim::PinholeCamera& c = v.camera;
  return q.inertia_kgm2.allFinite() && std::isfinite(q.mass_kg + q.arm_m + q.thrust_coefficient +
                                                    q.moment_coefficient + q.motor_time_constant_s +
                                                    q.max_rotor_speed_radps + q.drag_coefficient + q.gravity_mps2) &&
         std::isfinite(c.fx + c.fy + c.cx + c.cy + c.rate_hz + c.pixel_noise_px) && std::isfinite(q.HoverRotorSpeed());
}

bool SameVehicle(const estim::Vehicle& a, const estim::Vehicle& b) {
  return a.name == b.name && a.quadrotor.mass_kg == b.quadrotor.mass_kg &&
         a.quadrotor.inertia_kgm2 == b.quadrotor.inertia_kgm2 && a.quadrotor.arm_m == b.quadrotor.arm_m &&
         a.quadrotor.thrust_coefficient == b.quadrotor.thrust_coefficient &&
         a.quadrotor.moment_coefficient == b.quadrotor.moment_coefficient &&
         a.quadrotor.motor_time_constant_s == b.quadrotor.motor_time_constant_s &&
         a.quadrotor.max_rotor_speed_radps == b.quadrotor.max_rotor_speed_radps &&
         a.quadrotor.drag_coefficient == b.quadrotor.drag_coefficient &&
         a.quadrotor.gravity_mps2 == b.quadrotor.gravity_mps2 && a.camera.fx == b.camera.fx &&
         a.camera.fy == b.camera.fy && a.camera.cx == b.camera.cx && a.camera.cy == b.camera.cy &&
         a.camera.width == b.camera.width && a.camera.height == b.camera.height &&
         a.camera.rate_hz == b.camera.rate_hz && a.camera.pixel_noise_px == b.camera.pixel_noise_px;
}

// The texts of a small valid data folder (20 landmarks, 0.2 s), made once.
const std::vector<std::string>& BaseFolder() {
  static const std::vector<std::string> files = [] {
    estim::Vehicle vehicle;
    vehicle.name = "fuzz";
    vehicle.quadrotor.mass_kg = 1.0;
    vehicle.quadrotor.inertia_kgm2 = Eigen::Vector3d(0.0049, 0.0049, 0.0069);
    vehicle.quadrotor.arm_m = 0.08;
    vehicle.quadrotor.thrust_coefficient = 1.91e-6;
    vehicle.quadrotor.moment_coefficient = 2.6e-7;
    vehicle.quadrotor.motor_time_constant_s = 0.02;
    vehicle.quadrotor.max_rotor_speed_radps = 2200;
    vehicle.quadrotor.drag_coefficient = 0.1;
    vehicle.camera = {400, 400, 320, 240, 640, 480, 30, 1.0};
    sim::QuadrotorSimOptions options;
    options.duration_s = 0.2;
    options.landmarks = 20;
    options.truth_rate_hz = 20;
    const fs::path dir = Scratch() / "base";
    fs::remove_all(dir);
    estim::WriteQuadrotorData(sim::SimulateQuadrotor(vehicle, options), dir.string());
    std::vector<std::string> texts;
    for (std::string_view name : estim::kQuadrotorDataFiles) {
      std::ifstream in(dir / name, std::ios::binary);
      texts.emplace_back(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    fs::remove_all(dir);
    return texts;
  }();
  return files;
}

bool UnitQuaternion(const Eigen::Quaterniond& q) { return std::abs(q.norm() - 1.0) < 1e-9; }

}  // namespace

std::optional<std::string> CheckVehicleInput(std::string_view data) {
  const std::string path = (Scratch() / "vehicle.json").string();
  WriteFile(path, data);
  estim::Vehicle vehicle;
  try {
    vehicle = estim::ReadVehicle(path);
  } catch (const InputError& e) {
    if (!StartsWith(e.what(), path + ":")) return Violation("the InputError begins with the path", __LINE__, data, e.what());
    return std::nullopt;
  }
  if (!Finite(vehicle)) return Violation("an accepted vehicle is finite", __LINE__, data);
  try {
    estim::ValidateVehicle(vehicle, path);
  } catch (const InputError& e) {
    return Violation("an accepted vehicle validates", __LINE__, data, e.what());
  }
  const std::string again = (Scratch() / "vehicle_again.json").string();
  WriteFile(again, estim::VehicleToJson(vehicle));
  try {
    if (!SameVehicle(estim::ReadVehicle(again), vehicle)) {
      return Violation("VehicleToJson reads back to the same values", __LINE__, data);
    }
  } catch (const InputError& e) {
    return Violation("VehicleToJson reads back", __LINE__, data, e.what());
  }
  return std::nullopt;
}

std::optional<std::string> CheckQuadrotorDataInput(std::string_view data) {
  if (data.empty()) return std::nullopt;
  const std::vector<std::string>& base = BaseFolder();
  const size_t replaced = static_cast<unsigned char>(data[0]) % base.size();
  const fs::path dir = Scratch() / "folder";
  fs::create_directories(dir);
  for (size_t i = 0; i < base.size(); ++i) {
    WriteFile(dir / estim::kQuadrotorDataFiles[i], i == replaced ? data.substr(1) : std::string_view(base[i]));
  }
  estim::QuadrotorData read;
  try {
    read = estim::ReadQuadrotorData(dir.string());
  } catch (const InputError& e) {
    if (!StartsWith(e.what(), dir.string() + "/")) {
      return Violation("the InputError begins with the folder's file", __LINE__, data, e.what());
    }
    return std::nullopt;
  }
  if (read.initial.size() < 2) return Violation("at least 2 initial poses", __LINE__, data);
  for (const Eigen::Vector3d& x : read.landmarks) {
    if (!(x.cwiseAbs().maxCoeff() <= estim::kMaxDataCoordinate)) return Violation("landmarks within bounds", __LINE__, data);
  }
  for (size_t i = 0; i < read.pixels.size(); ++i) {
    const estim::PixelObservation& m = read.pixels[i];
    if (m.landmark < 0 || m.landmark >= static_cast<int>(read.landmarks.size()) || !m.uv.allFinite() ||
        !std::isfinite(m.t) || (i > 0 && m.t < read.pixels[i - 1].t)) {
      return Violation("measurements in range and in time order", __LINE__, data, fmt::format("row {}", i));
    }
  }
  for (size_t i = 0; i < read.initial.size(); ++i) {
    const estim::PoseSample& s = read.initial[i];
    if (!UnitQuaternion(s.q) || !s.p.allFinite() || (i > 0 && !(s.t > read.initial[i - 1].t))) {
      return Violation("initial poses finite, unit, in increasing time", __LINE__, data, fmt::format("row {}", i));
    }
  }
  for (size_t i = 0; i < read.truth.size(); ++i) {
    const estim::QuadrotorTruth& s = read.truth[i];
    if (!UnitQuaternion(s.q) || !s.p.allFinite() || !s.v.allFinite() || !s.w.allFinite() ||
        !(s.rotor.minCoeff() >= 0) || (i > 0 && !(s.t > read.truth[i - 1].t))) {
      return Violation("truth finite, unit, rotor >= 0, in increasing time", __LINE__, data, fmt::format("row {}", i));
    }
  }
  return std::nullopt;
}

std::optional<std::string> CheckModelMutationInput(std::string_view data) {
  nlohmann::json root = nlohmann::json::parse(data.begin(), data.end(), nullptr, false);
  if (root.is_discarded() || !root.is_object()) return std::nullopt;
  root["version"] = 1;
  root.erase("checksum");
  cheb::TrajectoryModel model;
  try {
    model = cheb::ParseModelJson(root.dump(), "fuzz.json");
  } catch (const InputError&) {
    return std::nullopt;  // CheckModelInput checks the messages
  }
  const std::string text = cheb::WriteModelJson(model);
  std::vector<int64_t> stamps;
  for (const cheb::ModelSegment& segment : model.segments) {
    for (int64_t s : {segment.first_ns, segment.first_ns + (segment.last_ns - segment.first_ns) / 2, segment.last_ns}) {
      stamps.push_back(s);
    }
  }
  Eigen::MatrixXd original;
  cheb::CurveFromModel(model).EvaluateMany(stamps, 0, &original);
  // The position and the new byte from the input's last three bytes.
  uint32_t pick = 0;
  for (size_t i = data.size() >= 3 ? data.size() - 3 : 0; i < data.size(); ++i) {
    pick = pick * 256 + static_cast<unsigned char>(data[i]);
  }
  std::string mutated = text;
  mutated[(pick >> 8) % mutated.size()] = static_cast<char>(pick & 0xff);
  if (mutated == text) return std::nullopt;
  cheb::TrajectoryModel read;
  try {
    read = cheb::ParseModelJson(mutated, "fuzz.json");
  } catch (const InputError&) {
    return std::nullopt;
  }
  Eigen::MatrixXd back;
  try {
    cheb::CurveFromModel(read).EvaluateMany(stamps, 0, &back);
  } catch (const ComputeError& e) {
    return Violation("an accepted mutation of a written model covers its stamps", __LINE__, mutated, e.what());
  }
  if (back.rows() != original.rows() || back.cols() != original.cols() ||
      std::memcmp(back.data(), original.data(), sizeof(double) * static_cast<size_t>(back.size())) != 0) {
    return Violation("an accepted mutation of a written model evaluates bit-identically", __LINE__, mutated);
  }
  return std::nullopt;
}

}  // namespace cheval::fuzz

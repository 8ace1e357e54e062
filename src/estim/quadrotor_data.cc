#include "cheval/estim/quadrotor_data.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <system_error>

#include "cheval/common/error.h"
#include "cheval/common/output.h"

namespace cheval::estim {
namespace {

std::string Num(double x) { return fmt::format("{:.17g}", x); }

// Rows of a CSV file with a header line; every row must have `columns` numbers.
std::vector<std::vector<double>> ReadCsv(const std::filesystem::path& path, size_t columns) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string(), 0, 0, "cannot open (required file of a quadrotor data folder)");
  std::vector<std::vector<double>> rows;
  std::string line;
  int64_t number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line[0] == '#' || (number == 1 && !std::isdigit(static_cast<unsigned char>(line[0])) &&
                                           line[0] != '-' && line[0] != '.')) {
      continue;
    }
    std::vector<double> row;
    const char* p = line.data();
    const char* end = line.data() + line.size();
    while (p < end) {
      double value = 0;
      const auto [next, ec] = std::from_chars(p, end, value);
      if (ec != std::errc() || !std::isfinite(value)) {
        throw InputError(path.string(), number, p - line.data() + 1, "expected a finite number");
      }
      row.push_back(value);
      p = next;
      if (p < end && *p == ',') ++p;
      else if (p < end) throw InputError(path.string(), number, p - line.data() + 1, "expected ','");
    }
    if (row.size() != columns) {
      throw InputError(path.string(), number, 1, fmt::format("expected {} fields, got {}", columns, row.size()));
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

}  // namespace

std::string QuadrotorStatesCsv(const std::vector<QuadrotorTruth>& states) {
  std::string text = "t,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz,rotor0,rotor1,rotor2,rotor3\n";
  for (const QuadrotorTruth& s : states) {
    text += fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", Num(s.t), Num(s.p.x()), Num(s.p.y()),
                        Num(s.p.z()), Num(s.q.w()), Num(s.q.x()), Num(s.q.y()), Num(s.q.z()), Num(s.v.x()),
                        Num(s.v.y()), Num(s.v.z()), Num(s.w.x()), Num(s.w.y()), Num(s.w.z()), Num(s.rotor[0]),
                        Num(s.rotor[1]), Num(s.rotor[2]), Num(s.rotor[3]));
  }
  return text;
}

namespace {

// True when `folder` exists and holds nothing but files named like those of a data folder (so it is
// one, from an earlier run): such a folder is replaced whole; any other non-empty folder is refused.
bool IsDataFolder(const std::string& folder) {
  std::error_code ec;
  if (!std::filesystem::is_directory(folder, ec)) return false;
  for (const auto& entry : std::filesystem::directory_iterator(folder, ec)) {
    const std::string name = entry.path().filename().string();
    const bool known = std::find(kQuadrotorDataFiles.begin(), kQuadrotorDataFiles.end(), name) != kQuadrotorDataFiles.end();
    if (!entry.is_regular_file(ec) || !known) {
      return false;
    }
  }
  return !ec;
}

}  // namespace

void WriteQuadrotorData(const QuadrotorData& data, const std::string& folder) {
  StagedFolder staged(folder);
  staged.Write(std::string(kQuadrotorDataFiles[0]), VehicleToJson(data.vehicle));
  std::string text = "id,x,y,z\n";
  for (size_t i = 0; i < data.landmarks.size(); ++i) {
    const Eigen::Vector3d& x = data.landmarks[i];
    text += fmt::format("{},{},{},{}\n", i, Num(x.x()), Num(x.y()), Num(x.z()));
  }
  staged.Write(std::string(kQuadrotorDataFiles[1]), text);
  text = "t,landmark,u,v\n";
  for (const PixelObservation& m : data.pixels) {
    text += fmt::format("{},{},{},{}\n", Num(m.t), m.landmark, Num(m.uv.x()), Num(m.uv.y()));
  }
  staged.Write(std::string(kQuadrotorDataFiles[2]), text);
  text = "t,px,py,pz,qw,qx,qy,qz\n";
  for (const PoseSample& s : data.initial) {
    text += fmt::format("{},{},{},{},{},{},{},{}\n", Num(s.t), Num(s.p.x()), Num(s.p.y()), Num(s.p.z()), Num(s.q.w()),
                        Num(s.q.x()), Num(s.q.y()), Num(s.q.z()));
  }
  staged.Write(std::string(kQuadrotorDataFiles[3]), text);
  if (!data.truth.empty()) staged.Write(std::string(kQuadrotorDataFiles[4]), QuadrotorStatesCsv(data.truth));
  staged.Publish(IsDataFolder(folder) ? FolderExisting::kReplace : FolderExisting::kRefuse);
}

QuadrotorData ReadQuadrotorData(const std::string& folder) {
  const std::filesystem::path dir(folder);
  if (!std::filesystem::is_directory(dir)) throw InputError(folder, 0, 0, "not a folder (expected a quadrotor data folder)");
  QuadrotorData data;
  data.vehicle = ReadVehicle((dir / "vehicle.json").string());
  for (const auto& row : ReadCsv(dir / "landmarks.csv", 4)) {
    if (row[0] != static_cast<double>(data.landmarks.size())) {
      throw InputError((dir / "landmarks.csv").string(), static_cast<int64_t>(data.landmarks.size()) + 2, 1,
                       "landmark ids must be 0, 1, 2, ... in order");
    }
    data.landmarks.emplace_back(row[1], row[2], row[3]);
  }
  int64_t line = 1;
  for (const auto& row : ReadCsv(dir / "measurements.csv", 4)) {
    ++line;
    const int id = static_cast<int>(row[1]);
    if (row[1] != id || id < 0 || id >= static_cast<int>(data.landmarks.size())) {
      throw InputError((dir / "measurements.csv").string(), line, 1, fmt::format("unknown landmark id {}", row[1]));
    }
    if (!data.pixels.empty() && row[0] < data.pixels.back().t) {
      throw InputError((dir / "measurements.csv").string(), line, 1, "measurement times must not decrease");
    }
    data.pixels.push_back({row[0], id, Eigen::Vector2d(row[2], row[3])});
  }
  for (const auto& row : ReadCsv(dir / "initial.csv", 8)) {
    data.initial.push_back({row[0], Eigen::Vector3d(row[1], row[2], row[3]),
                            Eigen::Quaterniond(row[4], row[5], row[6], row[7]).normalized()});
  }
  if (data.initial.size() < 2) throw InputError((dir / "initial.csv").string(), 0, 0, "needs at least 2 poses");
  if (std::filesystem::exists(dir / "truth.csv")) {
    for (const auto& r : ReadCsv(dir / "truth.csv", 18)) {
      data.truth.push_back({r[0], Eigen::Vector3d(r[1], r[2], r[3]), Eigen::Quaterniond(r[4], r[5], r[6], r[7]).normalized(),
                            Eigen::Vector3d(r[8], r[9], r[10]), Eigen::Vector3d(r[11], r[12], r[13]),
                            Eigen::Vector4d(r[14], r[15], r[16], r[17])});
    }
  }
  return data;
}

}  // namespace cheval::estim

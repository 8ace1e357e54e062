#include "cheval/estim/quadrotor_data.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <string_view>
#include <system_error>

#include "cheval/common/error.h"
#include "cheval/common/input_file.h"
#include "cheval/common/output.h"

namespace cheval::estim {
namespace {

std::string Num(double x) { return fmt::format("{:.17g}", x); }

// The rows of a CSV file with an optional header line (a first line not starting with a number),
// each with its 1-based line number; every row must have `columns` finite numbers. Lines may end in
// LF or CRLF; empty lines and lines starting with '#' are skipped.
struct CsvRows {
  std::string path;
  std::vector<std::vector<double>> rows;
  std::vector<int64_t> lines;

  [[noreturn]] void Fail(size_t row, int64_t column, const std::string& what) const {
    throw InputError(path, lines[row], column, what);
  }
  // Fails unless |rows[row][column]| <= bound (the value is finite already).
  void Bounded(size_t row, size_t column, double bound, const char* name, const char* unit) const {
    const double value = rows[row][column];
    if (!(std::abs(value) <= bound)) {
      Fail(row, 0, fmt::format("{} must be within [-{:g}, {:g}] {}, got {}", name, bound, bound, unit, value));
    }
  }
};

CsvRows ReadCsv(const std::filesystem::path& file, size_t columns) {
  CsvRows out{file.string(), {}, {}};
  const std::string text = ReadInputFile(out.path, kMaxDataFileBytes, "a CSV file of a quadrotor data folder");
  int64_t number = 0;
  size_t start = 0;
  while (start < text.size()) {
    const size_t newline = text.find('\n', start);
    const size_t stop = newline == std::string::npos ? text.size() : newline;
    std::string_view line(text.data() + start, stop - start);
    start = stop + 1;
    ++number;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
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
        throw InputError(out.path, number, p - line.data() + 1, "expected a finite number");
      }
      row.push_back(value);
      p = next;
      if (p < end && *p == ',') {
        ++p;
        if (p == end) throw InputError(out.path, number, p - line.data() + 1, "expected a number after ','");
      } else if (p < end) {
        throw InputError(out.path, number, p - line.data() + 1, "expected ','");
      }
    }
    if (row.size() != columns) {
      throw InputError(out.path, number, 1, fmt::format("expected {} fields, got {}", columns, row.size()));
    }
    out.rows.push_back(std::move(row));
    out.lines.push_back(number);
  }
  return out;
}

// The unit quaternion of (w, x, y, z) = row[at..at+3]; fails for a zero or overflowing one.
Eigen::Quaterniond RowQuaternion(const CsvRows& csv, size_t row, size_t at) {
  const std::vector<double>& r = csv.rows[row];
  const Eigen::Quaterniond q(r[at], r[at + 1], r[at + 2], r[at + 3]);
  const double n = q.squaredNorm();
  if (!(n > 1e-12) || !std::isfinite(n)) {
    csv.Fail(row, 0,
             fmt::format("expected a rotation: the quaternion (qw, qx, qy, qz) = ({}, {}, {}, {}) has a squared norm "
                         "{} (it must be > 1e-12 and finite)",
                         r[at], r[at + 1], r[at + 2], r[at + 3], n));
  }
  return q.normalized();
}

// Fails unless the time in column 0 is within the documented bound and, with `strict`, after the
// previous row's (else not before it).
void CheckTime(const CsvRows& csv, size_t row, bool strict) {
  csv.Bounded(row, 0, kMaxDataTime, "the time t", "s");
  if (row == 0) return;
  const double t = csv.rows[row][0], previous = csv.rows[row - 1][0];
  if (strict ? !(t > previous) : t < previous) {
    csv.Fail(row, 1, fmt::format("times must {}: {} after {}", strict ? "increase" : "not decrease", t, previous));
  }
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
  const CsvRows landmarks = ReadCsv(dir / "landmarks.csv", 4);
  for (size_t i = 0; i < landmarks.rows.size(); ++i) {
    const std::vector<double>& row = landmarks.rows[i];
    if (row[0] != static_cast<double>(i)) {
      landmarks.Fail(i, 1, fmt::format("expected landmark id {} (ids are 0, 1, 2, ... in order), got {}", i, row[0]));
    }
    for (size_t c = 1; c <= 3; ++c) landmarks.Bounded(i, c, kMaxDataCoordinate, "a landmark coordinate", "m");
    data.landmarks.emplace_back(row[1], row[2], row[3]);
  }
  const CsvRows measurements = ReadCsv(dir / "measurements.csv", 4);
  for (size_t i = 0; i < measurements.rows.size(); ++i) {
    const std::vector<double>& row = measurements.rows[i];
    CheckTime(measurements, i, false);
    if (!(row[1] >= 0 && row[1] < static_cast<double>(data.landmarks.size()) && row[1] == std::floor(row[1]))) {
      measurements.Fail(i, 1, fmt::format("unknown landmark id {} (landmarks.csv has ids 0 to {})", row[1],
                                          static_cast<int64_t>(data.landmarks.size()) - 1));
    }
    measurements.Bounded(i, 2, kMaxDataPixel, "the pixel u", "px");
    measurements.Bounded(i, 3, kMaxDataPixel, "the pixel v", "px");
    data.pixels.push_back({row[0], static_cast<int>(row[1]), Eigen::Vector2d(row[2], row[3])});
  }
  const CsvRows initial = ReadCsv(dir / "initial.csv", 8);
  for (size_t i = 0; i < initial.rows.size(); ++i) {
    const std::vector<double>& row = initial.rows[i];
    CheckTime(initial, i, true);
    for (size_t c = 1; c <= 3; ++c) initial.Bounded(i, c, kMaxDataCoordinate, "a position coordinate", "m");
    data.initial.push_back({row[0], Eigen::Vector3d(row[1], row[2], row[3]), RowQuaternion(initial, i, 4)});
  }
  if (data.initial.size() < 2) throw InputError(initial.path, 0, 0, "needs at least 2 poses");
  if (std::filesystem::exists(dir / "truth.csv")) {
    const CsvRows truth = ReadCsv(dir / "truth.csv", 18);
    for (size_t i = 0; i < truth.rows.size(); ++i) {
      const std::vector<double>& r = truth.rows[i];
      CheckTime(truth, i, true);
      for (size_t c = 1; c <= 3; ++c) truth.Bounded(i, c, kMaxDataCoordinate, "a position coordinate", "m");
      for (size_t c = 8; c <= 13; ++c) truth.Bounded(i, c, kMaxDataRate, "a velocity or body rate", "m/s or rad/s");
      for (size_t c = 14; c <= 17; ++c) {
        if (!(r[c] >= 0 && r[c] <= kMaxDataRate)) {
          truth.Fail(i, 0, fmt::format("a rotor speed must be within [0, {:g}] rad/s, got {}", kMaxDataRate, r[c]));
        }
      }
      data.truth.push_back({r[0], Eigen::Vector3d(r[1], r[2], r[3]), RowQuaternion(truth, i, 4),
                            Eigen::Vector3d(r[8], r[9], r[10]), Eigen::Vector3d(r[11], r[12], r[13]),
                            Eigen::Vector4d(r[14], r[15], r[16], r[17])});
    }
  }
  return data;
}

}  // namespace cheval::estim

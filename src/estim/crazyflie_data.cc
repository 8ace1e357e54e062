#include "cheval/estim/crazyflie_data.h"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <string_view>
#include <system_error>

#include "cheval/common/error.h"
#include "cheval/common/input_file.h"

namespace cheval::estim {
namespace {

// The fields of one line split at commas (no quoting: the layout has numbers only).
std::vector<std::string_view> Split(std::string_view line) {
  std::vector<std::string_view> fields;
  size_t start = 0;
  while (true) {
    const size_t comma = line.find(',', start);
    fields.push_back(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return fields;
}

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

// A field as a number; NaN for an empty field or NaN text (a missing value). Fails for anything else.
double Field(std::string_view field, const std::string& path, int64_t line, int64_t column, const std::string& name) {
  const std::string_view s = Trim(field);
  if (s.empty()) return std::nan("");
  double value = 0;
  const auto [next, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (ec != std::errc() || next != s.data() + s.size() || std::isinf(value)) {
    throw InputError(path, line, column,
                     fmt::format("column \"{}\": expected a finite number (or NaN / empty for a missing value), got "
                                 "\"{}\"",
                                 name, std::string(s.substr(0, 40))));
  }
  return value;
}

}  // namespace

const std::vector<std::string>& RotorFlightColumns() {
  static const std::vector<std::string> columns = {
      "t",       "x_mocap", "y_mocap", "z_mocap", "qw", "qx", "qy", "qz", "wx", "wy", "wz",
      "m1_erpm", "m2_erpm", "m3_erpm", "m4_erpm", "ax", "ay", "az", "is_flying"};
  return columns;
}

RotorFlight ReadRotorFlight(const std::string& path) {
  const std::string text = ReadInputFile(path, kMaxRotorFlightBytes, "a flight CSV file");
  RotorFlight flight;
  flight.path = path;
  const std::vector<std::string>& used = RotorFlightColumns();
  std::vector<int> index(used.size(), -1);  // column of each used name
  std::vector<size_t> column_start;         // 1-based character column of each field, per line
  size_t header_fields = 0;
  int64_t number = 0;
  size_t start = 0;
  const double erpm_to_radps = 2.0 * M_PI / (kCrazyflieElectricalPerMechanical * 60.0);
  while (start < text.size()) {
    const size_t newline = text.find('\n', start);
    const size_t stop = newline == std::string::npos ? text.size() : newline;
    std::string_view line(text.data() + start, stop - start);
    start = stop + 1;
    ++number;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line.empty() || line[0] == '#') continue;
    const std::vector<std::string_view> fields = Split(line);
    if (header_fields == 0) {  // the header
      header_fields = fields.size();
      for (size_t f = 0; f < fields.size(); ++f) {
        for (size_t u = 0; u < used.size(); ++u) {
          if (Trim(fields[f]) == used[u]) index[u] = static_cast<int>(f);
        }
      }
      std::string missing;
      for (size_t u = 0; u < used.size(); ++u) {
        if (index[u] < 0) missing += (missing.empty() ? "" : ", ") + used[u];
      }
      if (!missing.empty()) {
        throw InputError(path, number, 1,
                         fmt::format("the header lacks the column(s) {} (a flight CSV needs {})", missing,
                                     fmt::join(used, ",")));
      }
      continue;
    }
    if (fields.size() != header_fields) {
      throw InputError(path, number, 1, fmt::format("expected {} fields as in the header, got {}", header_fields,
                                                    fields.size()));
    }
    std::vector<double> v(used.size());
    bool missing = false;
    for (size_t u = 0; u < used.size(); ++u) {
      int64_t column = 1;
      for (int f = 0; f < index[u]; ++f) column += static_cast<int64_t>(fields[f].size()) + 1;
      v[u] = Field(fields[index[u]], path, number, column, used[u]);
      missing = missing || std::isnan(v[u]);
    }
    if (missing) {
      flight.dropped_lines.push_back(number);
      continue;
    }
    RotorSample s;
    s.t = v[0];
    s.p = Eigen::Vector3d(v[1], v[2], v[3]);
    const Eigen::Quaterniond q(v[4], v[5], v[6], v[7]);
    const double norm = q.squaredNorm();
    if (!(norm > 1e-12) || !std::isfinite(norm)) {
      throw InputError(path, number, 1,
                       fmt::format("expected a rotation: the quaternion (qw, qx, qy, qz) = ({}, {}, {}, {}) has a "
                                   "squared norm {} (it must be > 1e-12 and finite)",
                                   v[4], v[5], v[6], v[7], norm));
    }
    s.q = q.normalized();
    s.w = Eigen::Vector3d(v[8], v[9], v[10]);
    for (int i = 0; i < 4; ++i) {
      if (!(v[11 + i] >= 0)) {
        throw InputError(path, number, 1, fmt::format("column \"{}\": a rotor speed must be >= 0, got {}", used[11 + i],
                                                      v[11 + i]));
      }
      s.rotor[i] = v[11 + i] * erpm_to_radps;
    }
    s.accel = Eigen::Vector3d(v[15], v[16], v[17]);
    if (v[18] != 0 && v[18] != 1) {
      throw InputError(path, number, 1, fmt::format("column \"is_flying\": expected 0 or 1, got {}", v[18]));
    }
    s.flying = v[18] == 1;
    if (!flight.samples.empty()) {
      const RotorSample& previous = flight.samples.back();
      if (!(s.t > previous.t)) {
        throw InputError(path, number, 1, fmt::format("times must increase: {} after {}", s.t, previous.t));
      }
      s.fresh_position = s.p != previous.p;
    }
    flight.samples.push_back(s);
  }
  if (header_fields == 0) throw InputError(path, 0, 0, "empty file; expected a header line naming the columns");
  if (flight.samples.size() < 3) {
    throw InputError(path, 0, 0, fmt::format("expected at least 3 complete rows, got {} ({} dropped for missing values)",
                                             flight.samples.size(), flight.dropped_lines.size()));
  }
  for (size_t i = 0; i < flight.samples.size(); ++i) {
    const bool flying = flight.samples[i].flying;
    if (flying && (i == 0 || !flight.samples[i - 1].flying)) flight.flying_spans.push_back({flight.samples[i].t, 0});
    if (flying) flight.flying_spans.back().second = flight.samples[i].t;
  }
  return flight;
}

std::vector<size_t> ScoredSamples(const RotorFlight& flight, double margin_s) {
  std::vector<size_t> out;
  for (size_t i = 0; i < flight.samples.size(); ++i) {
    const RotorSample& s = flight.samples[i];
    if (!s.flying) continue;
    for (const auto& [first, last] : flight.flying_spans) {
      if (s.t >= first + margin_s && s.t <= last - margin_s) {
        out.push_back(i);
        break;
      }
    }
  }
  return out;
}

}  // namespace cheval::estim

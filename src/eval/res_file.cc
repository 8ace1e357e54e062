#include "cheval/eval/res_file.h"

#include <array>
#include <cstring>
#include <limits>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cheval/common/error.h"
#include "cheval/eval/associate.h"

namespace cheval::eval {
namespace {

void Put16(std::string* out, uint32_t v) {
  out->push_back(static_cast<char>(v & 0xff));
  out->push_back(static_cast<char>((v >> 8) & 0xff));
}
void Put32(std::string* out, uint32_t v) {
  Put16(out, v & 0xffff);
  Put16(out, v >> 16);
}

constexpr std::array<uint32_t, 256> CrcTable() {
  std::array<uint32_t, 256> table{};
  for (uint32_t n = 0; n < 256; ++n) {
    uint32_t c = n;
    for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    table[n] = c;
  }
  return table;
}

// evo's title, label ("APE (m)") and statistics of a result.
nlohmann::ordered_json Stats(const ErrorStatistics& s) {
  return {{"rmse", s.rmse}, {"mean", s.mean}, {"median", s.median}, {"std", s.std},
          {"min", s.min},   {"max", s.max},   {"sse", s.sse}};
}

}  // namespace

uint32_t Crc32(std::string_view bytes) {
  static constexpr std::array<uint32_t, 256> kTable = CrcTable();
  uint32_t c = 0xFFFFFFFFu;
  for (char b : bytes) c = kTable[(c ^ static_cast<unsigned char>(b)) & 0xff] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

std::string NpyFloat64(std::span<const double> values) {
  std::string header = fmt::format("{{'descr': '<f8', 'fortran_order': False, 'shape': ({},), }}", values.size());
  // numpy pads the header with spaces so that the data starts at a multiple of 64, then a newline.
  while ((10 + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  std::string out("\x93NUMPY\x01\x00", 8);
  Put16(&out, static_cast<uint32_t>(header.size()));
  out += header;
  const size_t start = out.size();
  out.resize(start + 8 * values.size());
  if (!values.empty()) std::memcpy(out.data() + start, values.data(), 8 * values.size());  // little-endian host
  return out;
}

std::string StoredZip(const std::vector<std::pair<std::string, std::string>>& members) {
  std::string out, directory;
  const uint32_t kDosTime = 0, kDosDate = (1 << 5) | 1;  // 1980-01-01 00:00, as a fixed stamp
  for (const auto& [name, data] : members) {
    if (data.size() >= std::numeric_limits<uint32_t>::max() || out.size() >= std::numeric_limits<uint32_t>::max()) {
      throw ComputeError(fmt::format("the result zip member {} is larger than a zip without zip64 holds (4 GiB)", name));
    }
    const uint32_t crc = Crc32(data), offset = static_cast<uint32_t>(out.size());
    const auto size = static_cast<uint32_t>(data.size());
    Put32(&out, 0x04034b50);  // local file header
    Put16(&out, 20);          // version needed: 2.0
    Put16(&out, 0);           // flags
    Put16(&out, 0);           // method: stored
    Put16(&out, kDosTime);
    Put16(&out, kDosDate);
    Put32(&out, crc);
    Put32(&out, size);
    Put32(&out, size);
    Put16(&out, static_cast<uint32_t>(name.size()));
    Put16(&out, 0);  // extra length
    out += name;
    out += data;
    Put32(&directory, 0x02014b50);  // central directory entry
    Put16(&directory, 20);          // made by: 2.0
    Put16(&directory, 20);
    Put16(&directory, 0);
    Put16(&directory, 0);
    Put16(&directory, kDosTime);
    Put16(&directory, kDosDate);
    Put32(&directory, crc);
    Put32(&directory, size);
    Put32(&directory, size);
    Put16(&directory, static_cast<uint32_t>(name.size()));
    Put16(&directory, 0);  // extra
    Put16(&directory, 0);  // comment
    Put16(&directory, 0);  // disk
    Put16(&directory, 0);  // internal attributes
    Put32(&directory, 0);  // external attributes
    Put32(&directory, offset);
    directory += name;
  }
  const auto directory_offset = static_cast<uint32_t>(out.size());
  out += directory;
  Put32(&out, 0x06054b50);  // end of central directory
  Put16(&out, 0);
  Put16(&out, 0);
  Put16(&out, static_cast<uint32_t>(members.size()));
  Put16(&out, static_cast<uint32_t>(members.size()));
  Put32(&out, static_cast<uint32_t>(directory.size()));
  Put32(&out, directory_offset);
  Put16(&out, 0);  // comment length
  return out;
}

std::string EvoResultZip(const EvaluationReport& report) {
  const EvaluationResult& r = report.result;
  const std::string metric = report.options.metric == MetricKind::kApe   ? "APE"
                             : report.options.metric == MetricKind::kRpe ? "RPE"
                                                                         : "ASE";
  nlohmann::ordered_json info = {
      {"title", r.title},
      {"ref_name", report.reference_path},
      {"est_name", report.estimate_label.empty() ? report.estimate_path : report.estimate_label},
      {"label", r.unit.empty() ? metric : fmt::format("{} ({})", metric, r.unit)}};
  std::vector<double> stamps, from_start;
  // evo: the estimate's float seconds of each error, and those minus the first, in float.
  for (int64_t ns : r.stamps_ns) stamps.push_back(EvoSeconds(ns, report.options.association.est_seconds));
  for (double s : stamps) from_start.push_back(s - stamps.front());
  std::vector<std::pair<std::string, std::string>> members = {
      {"info.json", info.dump()},
      {"stats.json", Stats(r.stats).dump()},
      {"error_array.npz", NpyFloat64(r.errors)},
      {"timestamps.npz", NpyFloat64(stamps)},
      {"seconds_from_start.npz", NpyFloat64(from_start)}};
  if (r.ase) {  // cheval's ASE parts, as further arrays (evo_res ignores them, load_res_file keeps them)
    if (r.ase->has_rotation) members.push_back({"ase_rotation.npz", NpyFloat64(r.ase->rotation)});
    members.push_back({"ase_position.npz", NpyFloat64(r.ase->position)});
    if (r.ase->has_velocity) members.push_back({"ase_velocity.npz", NpyFloat64(r.ase->velocity)});
  }
  return StoredZip(members);
}

}  // namespace cheval::eval

#include "cheval/eval/res_read.h"

#include <filesystem>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cheval/common/error.h"
#include "cheval/common/input_file.h"
#include "cheval/common/zip.h"

namespace cheval::eval {
namespace {

constexpr uint64_t kMaxFileBytes = uint64_t{2} << 30;

[[noreturn]] void Fail(const std::string& path, const std::string& what) { throw InputError(path, 0, 0, what); }

bool EndsWith(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

std::string Text(const nlohmann::json& v) { return v.is_string() ? v.get<std::string>() : v.dump(); }

}  // namespace

std::string ResultFile::Info(std::string_view key) const {
  for (const auto& [k, v] : info) {
    if (k == key) return v;
  }
  return "";
}

const NpyArray* ResultFile::Array(std::string_view name) const {
  for (const auto& [k, v] : arrays) {
    if (k == name) return &v;
  }
  return nullptr;
}

ResultFile ParseResultZip(std::string_view bytes, const std::string& path) {
  ResultFile r;
  r.path = path;
  const std::vector<ZipMember> members = ReadZip(bytes, path);
  const ZipMember *info = nullptr, *stats = nullptr;
  for (const ZipMember& m : members) {
    if (m.name == "info.json") info = &m;
    if (m.name == "stats.json") stats = &m;
  }
  for (const char* required : {"info.json", "stats.json"}) {
    if ((required[0] == 'i' ? info : stats) == nullptr) {
      Fail(path, fmt::format("member {} is missing: not an evo result file (expected info.json, stats.json and "
                             "error_array.npy)", required));
    }
  }
  // ordered_json keeps the members' key order, which is the order evo_res prints them in.
  const auto info_json = nlohmann::ordered_json::parse(info->data, nullptr, false);
  if (info_json.is_discarded() || !info_json.is_object()) Fail(path, "member info.json: expected a JSON object");
  for (const auto& [k, v] : info_json.items()) r.info.emplace_back(k, Text(v));
  const auto stats_json = nlohmann::ordered_json::parse(stats->data, nullptr, false);
  if (stats_json.is_discarded() || !stats_json.is_object()) Fail(path, "member stats.json: expected a JSON object");
  for (const auto& [k, v] : stats_json.items()) {
    if (!v.is_number()) Fail(path, fmt::format("member stats.json: \"{}\" is {}, expected a number", k, v.dump()));
    r.stats.emplace_back(k, v.get<double>());
  }
  for (const ZipMember& m : members) {
    if (EndsWith(m.name, ".npy") || EndsWith(m.name, ".npz")) {
      const std::string name = std::filesystem::path(m.name).stem().string();
      NpyArray a = ParseNpy(m.data, path, "member " + m.name);
      bool replaced = false;
      for (auto& [k, v] : r.arrays) {
        if (k == name) {
          v = std::move(a);
          replaced = true;
          break;
        }
      }
      if (!replaced) r.arrays.emplace_back(name, std::move(a));
    } else if (EndsWith(m.name, ".tum") || EndsWith(m.name, ".kitti")) {
      r.trajectories.push_back(m.name);
    }
  }
  const NpyArray* errors = r.Array("error_array");
  if (errors == nullptr) Fail(path, "member error_array.npy is missing: evo_res needs the error array");
  if (errors->shape.size() != 1) {
    Fail(path, fmt::format("member error_array: {}-D array, expected 1-D (one error per pose or pair)", errors->shape.size()));
  }
  for (const char* index : {"timestamps", "seconds_from_start", "sec_from_start"}) {
    const NpyArray* a = r.Array(index);
    if (a != nullptr && (a->shape.size() != 1 || a->values.size() != errors->values.size())) {
      Fail(path, fmt::format("member {}: {} values, expected one per error ({}, as error_array has)", index,
                             a->values.size(), errors->values.size()));
    }
  }
  return r;
}

std::vector<ResultFile> ParseResultJson(std::string_view bytes, const std::string& path) {
  const nlohmann::json j = ParseJsonInput(bytes, path, "cheval's --json output of ape, rpe or ase");
  std::vector<nlohmann::json> reports;
  if (j.is_array()) {
    reports.assign(j.begin(), j.end());
  } else {
    reports.push_back(j);
  }
  if (reports.empty()) Fail(path, "an empty JSON array: expected the output of cheval ape|rpe|ase --json");
  std::vector<ResultFile> out;
  for (size_t k = 0; k < reports.size(); ++k) {
    const nlohmann::json& r = reports[k];
    const std::string at = j.is_array() ? fmt::format("[{}].", k) : "";
    auto need = [&](const char* key) -> const nlohmann::json& {
      if (!r.is_object() || !r.contains(key) || !r[key].is_object()) {
        Fail(path, fmt::format("{}{}: missing; expected the output of cheval ape|rpe|ase --json (an object with "
                               "\"estimate\", \"reference\", \"metric\" and \"stats\")", at, key));
      }
      return r[key];
    };
    const nlohmann::json &estimate = need("estimate"), &reference = need("reference"), &metric = need("metric"),
                         &stats = need("stats");
    ResultFile f;
    f.path = path;
    const std::string name = estimate.contains("label") ? Text(estimate["label"])
                                                        : estimate.contains("path") ? Text(estimate["path"]) : "";
    const std::string unit = metric.contains("unit") ? Text(metric["unit"]) : "";
    const std::string label = metric.contains("name") ? Text(metric["name"]) : "";
    f.info = {{"ref_name", reference.contains("path") ? Text(reference["path"]) : ""},
              {"est_name", name},
              {"label", unit.empty() ? label : fmt::format("{} ({})", label, unit)}};
    for (const char* key : {"rmse", "mean", "median", "std", "min", "max", "sse"}) {
      if (!stats.contains(key) || !stats[key].is_number()) {
        Fail(path, fmt::format("{}stats.{}: {}; expected a number", at, key,
                               stats.contains(key) ? stats[key].dump() : std::string("missing")));
      }
      f.stats.emplace_back(key, stats[key].get<double>());
    }
    out.push_back(std::move(f));
  }
  return out;
}

std::vector<ResultFile> ReadResultFile(const std::string& path) {
  const std::string bytes = ReadInputFile(path, kMaxFileBytes, "a result file (evo's or cheval's .zip, or cheval's --json)");
  if (bytes.rfind("PK", 0) == 0) return {ParseResultZip(bytes, path)};
  const size_t first = bytes.find_first_not_of(" \t\r\n");
  if (first != std::string::npos && (bytes[first] == '{' || bytes[first] == '[')) return ParseResultJson(bytes, path);
  Fail(path, "neither a zip archive (evo's or cheval's result file) nor JSON (cheval's --json output)");
}

}  // namespace cheval::eval

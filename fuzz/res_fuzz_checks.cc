#include "res_fuzz_checks.h"

#include <cmath>
#include <cstring>
#include <exception>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cheval/common/error.h"
#include "cheval/common/npy.h"
#include "cheval/eval/res_file.h"
#include "cheval/eval/res_read.h"
#include "cheval/eval/res_table.h"

namespace cheval::fuzz {
namespace {

constexpr const char* kPath = "res.zip";

std::string Violation(const std::string& what, std::string_view data) {
  std::string shown;
  for (size_t k = 0; k < data.size() && k < 256; ++k) shown += fmt::format("{:02x}", static_cast<unsigned char>(data[k]));
  return fmt::format("{} (input {} bytes: {}{})", what, data.size(), shown, data.size() > 256 ? "..." : "");
}

uint64_t Elements(const NpyArray& a) {
  uint64_t n = 1;
  for (uint64_t d : a.shape) n *= d;
  return n;
}

bool SameBits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), 8 * a.size()) == 0);
}

// An InputError from `run` must start with the path; other exceptions are violations. nullopt when
// `run` returned or threw such an InputError.
template <typename Run>
std::optional<std::string> Refused(Run run, const std::string& what, std::string_view data, bool* ok) {
  *ok = false;
  try {
    run();
    *ok = true;
  } catch (const InputError& e) {
    const std::string m = e.what();
    if (m.rfind(fmt::format("{}:0:0: error: ", kPath), 0) != 0) return Violation(what + ": message without the path: " + m, data);
    if (m.find("member") == std::string::npos && m.find("zip") == std::string::npos &&
        m.find("array") == std::string::npos) {
      return Violation(what + ": message names no member or array: " + m, data);
    }
  } catch (const std::exception& e) {
    return Violation(fmt::format("{}: unexpected exception {}", what, e.what()), data);
  }
  return std::nullopt;
}

}  // namespace

std::optional<std::string> CheckResultFileInput(std::string_view data) {
  bool ok = false;
  NpyArray array;
  if (auto v = Refused([&] { array = ParseNpy(data, kPath, "array"); }, "ParseNpy", data, &ok)) return v;
  if (ok && array.values.size() != Elements(array)) return Violation("ParseNpy: values do not fill the shape", data);

  eval::ResultFile r;
  if (auto v = Refused([&] { r = eval::ParseResultZip(data, kPath); }, "ParseResultZip", data, &ok)) return v;
  if (!ok) return std::nullopt;
  const NpyArray* errors = r.Array("error_array");
  if (errors == nullptr || errors->shape.size() != 1) return Violation("a result without a 1-D error_array", data);
  for (const auto& [name, a] : r.arrays) {
    if (a.values.size() != Elements(a)) return Violation("array " + name + " does not fill its shape", data);
  }
  try {
    const eval::ResTable t = eval::BuildResTable({r}, {});
    (void)eval::EvoResText(t);
    (void)eval::ResTableMarkdown(t);
    (void)eval::ResTableLatex(t);
    (void)eval::ResTableCsv(t);
  } catch (const std::exception& e) {
    return Violation(fmt::format("the table of a read result threw {}", e.what()), data);
  }
  try {
    nlohmann::ordered_json info = nlohmann::ordered_json::object(), stats = nlohmann::ordered_json::object();
    for (const auto& [k, v] : r.info) info[k] = v;
    bool finite = true;  // json.dumps would write inf as Infinity, nlohmann as null: compare finite stats only
    for (const auto& [k, v] : r.stats) finite = finite && std::isfinite(v);
    for (const auto& [k, v] : r.stats) stats[k] = v;
    if (!finite) stats = nlohmann::ordered_json::object();
    const std::string again = eval::StoredZip({{"info.json", info.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace)},
                                               {"stats.json", stats.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace)},
                                               {"error_array.npy", eval::NpyFloat64(errors->values)}});
    const eval::ResultFile back = eval::ParseResultZip(again, kPath);
    if (!SameBits(back.Array("error_array")->values, errors->values)) {
      return Violation("error_array written and read again differs", data);
    }
    if (finite && back.stats != r.stats) return Violation("stats written and read again differ", data);
  } catch (const std::exception& e) {
    return Violation(fmt::format("a read error_array written again does not read back: {}", e.what()), data);
  }
  return std::nullopt;
}

}  // namespace cheval::fuzz

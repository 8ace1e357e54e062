// The JSON form of a TrajectoryModel (docs/compress.md, "Schema"): a hand-laid writer that keeps a
// window per few lines, and a validating reader that names the element at fault.
#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cheval/cheb/model.h"
#include "cheval/common/error.h"
#include "cheval/common/input_file.h"

namespace cheval::cheb {
namespace {

constexpr const char* kFormat = "cheval-trajectory-model";
constexpr int kVersion = 2;         // written; carries a checksum
constexpr int kLegacyVersion = 1;   // read: models written before the checksum existed
constexpr const char* kChecksumPrefix = "fnv1a64:";
// A model file beyond this is refused before it is read (compressing a day at 1 kHz gives ~10 MB).
constexpr uint64_t kMaxModelFileBytes = uint64_t{1} << 30;

std::string ChecksumText(uint64_t checksum) { return fmt::format("{}{:016x}", kChecksumPrefix, checksum); }
// Stamps are differenced in int64 and converted to seconds in a double, which is exact up to 2^53 ns
// (about 104 days): a model may span no more than that from its origin.
constexpr int64_t kMaxSpanNs = int64_t{1} << 53;

// A finite double in the shortest form that reads back to the same double (fmt's default). fmt
// writes -0.0 as "-0", which JSON readers take for the integer 0: write it as "-0.0" (found by
// fuzz_model; tests/data/fuzz/model/negative_zero_value.json).
std::string Number(double x) {
  if (!std::isfinite(x)) {
    throw ComputeError("the model holds a number that is not finite: the values are too large to fit");
  }
  if (x == 0 && std::signbit(x)) return "-0.0";
  return fmt::format("{}", x);
}

std::string NumberArray(const Eigen::Ref<const Eigen::VectorXd>& v) {
  std::string out = "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    if (i > 0) out += ", ";
    out += Number(v[i]);
  }
  return out + "]";
}

using Json = nlohmann::json;

// A short description of a JSON value for "got ..." in messages.
std::string Describe(const Json& value) {
  switch (value.type()) {
    case Json::value_t::object:
      return "an object";
    case Json::value_t::array:
      return fmt::format("an array of {} element{}", value.size(), value.size() == 1 ? "" : "s");
    case Json::value_t::null:
      return "null";
    default: {
      std::string text = value.dump();
      if (text.size() > 40) text = text.substr(0, 37) + "...";
      return text;
    }
  }
}

// Reads a parsed model, throwing InputError(path, 0, 0, "<element>: expected ..., got ...").
class ModelReader {
 public:
  explicit ModelReader(std::string path) : path_(std::move(path)) {}

  TrajectoryModel Read(const Json& root) const {
    if (!root.is_object()) Fail("model", "expected a JSON object (a cheval trajectory model), got " + Describe(root));
    if (!root.contains("format") || root["format"] != kFormat) {
      Fail("format", fmt::format("expected \"{}\", got {}", kFormat,
                                 root.contains("format") ? Describe(root["format"]) : "no such key"));
    }
    CheckKeys(root, "model",
              {"format", "version", "dimension", "origin_ns", "noise_sigma", "residual_rms", "reconstruction",
               "tolerance", "segments", "checksum"});
    const Json& version = Require(root, "version", "");
    if (!version.is_number_integer() ||
        (version.get<int64_t>() != kVersion && version.get<int64_t>() != kLegacyVersion)) {
      Fail("version", fmt::format("expected {} or {} (the versions this cheval reads), got {}", kLegacyVersion,
                                  kVersion, Describe(version)));
    }
    const bool checked = version.get<int64_t>() == kVersion;
    if (!checked && root.contains("checksum")) {
      Fail("checksum", fmt::format("unexpected in a version {} model (version {} models have none)", kLegacyVersion,
                                   kLegacyVersion));
    }
    if (checked && !root.contains("checksum")) {
      Fail("checksum", fmt::format("missing; expected \"{}<16 hex digits>\" in a version {} model", kChecksumPrefix,
                                   kVersion));
    }
    TrajectoryModel model;
    const Json& dimension = Require(root, "dimension", "");
    if (!dimension.is_number_integer() || dimension.get<int64_t>() < 1 || dimension.get<int64_t>() > 4) {
      Fail("dimension", "expected an integer from 1 to 4 (coordinates per sample), got " + Describe(dimension));
    }
    model.dimension = dimension.get<int>();
    model.origin_ns = Stamp(Require(root, "origin_ns", ""), "origin_ns");
    if (root.contains("noise_sigma")) {
      model.noise_sigma = Diagnostic(root["noise_sigma"], "noise_sigma", model.dimension);
    }
    if (root.contains("residual_rms")) {
      model.residual_rms = Diagnostic(root["residual_rms"], "residual_rms", model.dimension);
    }
    if (root.contains("reconstruction")) model.reconstruction = Reconstruction(root["reconstruction"]);
    if (root.contains("tolerance")) {
      const Json& tolerance = root["tolerance"];
      if (!tolerance.is_number() || !(tolerance.get<double>() > 0.0) || !std::isfinite(tolerance.get<double>())) {
        Fail("tolerance", "expected a positive finite number, got " + Describe(tolerance));
      }
      model.tolerance = tolerance.get<double>();
    }
    const Json& segments = Require(root, "segments", "");
    if (!segments.is_array() || segments.empty()) {
      Fail("segments", "expected a non-empty array, got " + Describe(segments));
    }
    for (size_t k = 0; k < segments.size(); ++k) {
      model.segments.push_back(Segment(segments[k], fmt::format("segments[{}]", k), model, k));
    }
    if (checked) {
      const Json& stored = root["checksum"];
      const std::string expected = ChecksumText(ModelChecksum(model));
      if (!stored.is_string() || stored.get<std::string>() != expected) {
        Fail("checksum", fmt::format("checksum mismatch: the file says {}, its numbers give {}; the model is "
                                     "corrupted or was edited (docs/compress.md, \"Checksum\")",
                                     Describe(stored), expected));
      }
    }
    try {
      (void)CurveFromModel(model);  // every check FromParts makes has been made above; this is a backstop
    } catch (const std::invalid_argument& e) {
      Fail("model", fmt::format("expected a consistent model, got one that does not make a curve ({})", e.what()));
    }
    return model;
  }

 private:
  [[noreturn]] void Fail(const std::string& where, const std::string& what) const {
    throw InputError(path_, 0, 0, where + ": " + what);
  }

  const Json& Require(const Json& object, const char* key, const std::string& where) const {
    if (!object.contains(key)) {
      Fail(where.empty() ? key : where + "." + key, "missing; expected it in " + (where.empty() ? "the model" : where));
    }
    return object[key];
  }

  void CheckKeys(const Json& object, const std::string& where, std::initializer_list<const char*> allowed) const {
    for (const auto& item : object.items()) {
      const std::string& key = item.key();  // not a structured binding: clang 14 cannot capture one
      if (std::find_if(allowed.begin(), allowed.end(), [&](const char* a) { return key == a; }) == allowed.end()) {
        std::string names;
        for (const char* a : allowed) names += (names.empty() ? "" : ", ") + std::string(a);
        Fail(where, fmt::format("unknown key \"{}\"; expected only {}", key, names));
      }
    }
  }

  int64_t Stamp(const Json& value, const std::string& where) const {
    if (!value.is_number_integer() ||
        (value.is_number_unsigned() &&
         value.get<uint64_t>() > static_cast<uint64_t>(std::numeric_limits<int64_t>::max()))) {
      Fail(where, "expected an integer stamp in nanoseconds, got " + Describe(value));
    }
    return value.get<int64_t>();
  }

  double Finite(const Json& value, const std::string& where, const char* expectation = "a finite number") const {
    if (!value.is_number() || !std::isfinite(value.get<double>())) {
      Fail(where, fmt::format("expected {}, got {}", expectation, Describe(value)));
    }
    return value.get<double>();
  }

  double NonNegative(const Json& value, const std::string& where) const {
    const double x = Finite(value, where, "a finite non-negative number");
    if (x < 0.0) Fail(where, "expected a finite non-negative number, got " + Describe(value));
    return x;
  }

  Eigen::VectorXd Diagnostic(const Json& value, const std::string& where, int dimension) const {
    if (!value.is_array() || static_cast<int>(value.size()) != dimension) {
      Fail(where, fmt::format("expected an array of {} non-negative numbers (one per coordinate), got {}", dimension,
                              Describe(value)));
    }
    Eigen::VectorXd v(dimension);
    for (int c = 0; c < dimension; ++c) {
      v[c] = NonNegative(value[static_cast<size_t>(c)], fmt::format("{}[{}]", where, c));
    }
    return v;
  }

  ReconstructionError Reconstruction(const Json& value) const {
    const std::string where = "reconstruction";
    if (!value.is_object()) Fail(where, "expected an object, got " + Describe(value));
    CheckKeys(value, where, {"samples", "max_error", "rms_error", "worst_stamp_ns"});
    ReconstructionError error;
    const Json& samples = Require(value, "samples", where);
    if (!samples.is_number_integer() || samples.get<int64_t>() < 0) {
      Fail(where + ".samples", "expected a non-negative integer, got " + Describe(samples));
    }
    error.samples = samples.get<Eigen::Index>();
    error.max = NonNegative(Require(value, "max_error", where), where + ".max_error");
    error.rms = NonNegative(Require(value, "rms_error", where), where + ".rms_error");
    error.worst_stamp_ns = Stamp(Require(value, "worst_stamp_ns", where), where + ".worst_stamp_ns");
    return error;
  }

  // [begin, end] in seconds from the origin, begin < end.
  std::pair<double, double> Interval(const Json& value, const std::string& where) const {
    const char* expectation =
        "expected [begin, end], two finite numbers (seconds from origin_ns) with begin < end, got ";
    if (!value.is_array() || value.size() != 2 || !value[0].is_number() || !value[1].is_number()) {
      Fail(where, expectation + Describe(value));
    }
    const double a = value[0].get<double>(), b = value[1].get<double>();
    if (!std::isfinite(a) || !std::isfinite(b) || !(a < b)) Fail(where, expectation + value.dump());
    return {a, b};
  }

  ModelSegment Segment(const Json& value, const std::string& where, const TrajectoryModel& model, size_t k) const {
    if (!value.is_object()) {
      Fail(where, "expected an object with first_ns, last_ns and windows, got " + Describe(value));
    }
    CheckKeys(value, where, {"first_ns", "last_ns", "windows"});
    ModelSegment segment;
    segment.first_ns = Stamp(Require(value, "first_ns", where), where + ".first_ns");
    segment.last_ns = Stamp(Require(value, "last_ns", where), where + ".last_ns");
    if (k == 0 && segment.first_ns < model.origin_ns) {
      Fail(where + ".first_ns",
           fmt::format("expected a stamp not before origin_ns ({}), got {}", model.origin_ns, segment.first_ns));
    }
    if (k > 0 && segment.first_ns <= model.segments.back().last_ns) {
      Fail(where + ".first_ns", fmt::format("expected a stamp after segments[{}].last_ns ({}), got {}", k - 1,
                                            model.segments.back().last_ns, segment.first_ns));
    }
    if (segment.last_ns < segment.first_ns) {
      Fail(where + ".last_ns",
           fmt::format("expected a stamp not before first_ns ({}), got {}", segment.first_ns, segment.last_ns));
    }
    // first_ns >= origin_ns here, so the difference cannot overflow unless it exceeds the span limit.
    if (static_cast<uint64_t>(segment.last_ns) - static_cast<uint64_t>(model.origin_ns) >
        static_cast<uint64_t>(kMaxSpanNs)) {
      Fail(where + ".last_ns",
           fmt::format("expected a stamp at most 2^53 ns (about 104 days) after origin_ns ({}), got {}",
                       model.origin_ns, segment.last_ns));
    }
    const double begin = static_cast<double>(segment.first_ns - model.origin_ns) * 1e-9;
    const double end = static_cast<double>(segment.last_ns - model.origin_ns) * 1e-9;
    const Json& windows = Require(value, "windows", where);
    if (!windows.is_array() || windows.empty()) {
      Fail(where + ".windows", "expected a non-empty array, got " + Describe(windows));
    }
    for (size_t j = 0; j < windows.size(); ++j) {
      const std::string at = fmt::format("{}.windows[{}]", where, j);
      ModelWindow window = Window(windows[j], at, model.dimension);
      if (j == 0 && !(window.core_begin <= begin)) {
        Fail(at + ".core",
             fmt::format("expected to begin at or before the segment's first stamp ({} s from origin_ns), "
                         "got {}",
                         Number(begin), Number(window.core_begin)));
      }
      if (j > 0 && window.core_begin != segment.windows.back().core_end) {
        Fail(at + ".core", fmt::format("expected to begin where windows[{}].core ends ({}), got {}", j - 1,
                                       Number(segment.windows.back().core_end), Number(window.core_begin)));
      }
      if (j + 1 == windows.size() && !(window.core_end >= end)) {
        Fail(at + ".core", fmt::format("expected to end at or after the segment's last stamp ({} s from origin_ns), "
                                       "got {}",
                                       Number(end), Number(window.core_end)));
      }
      segment.windows.push_back(std::move(window));
    }
    return segment;
  }

  ModelWindow Window(const Json& value, const std::string& where, int dimension) const {
    if (!value.is_object()) Fail(where, "expected an object with core, fit and values, got " + Describe(value));
    CheckKeys(value, where, {"core", "fit", "values"});
    ModelWindow window;
    std::tie(window.core_begin, window.core_end) = Interval(Require(value, "core", where), where + ".core");
    std::tie(window.fit_begin, window.fit_end) = Interval(Require(value, "fit", where), where + ".fit");
    if (!(window.fit_begin <= window.core_begin && window.core_end <= window.fit_end)) {
      Fail(where + ".fit",
           fmt::format("expected an interval containing core [{}, {}], got [{}, {}]", Number(window.core_begin),
                       Number(window.core_end), Number(window.fit_begin), Number(window.fit_end)));
    }
    const Json& values = Require(value, "values", where);
    if (!values.is_array() || static_cast<int>(values.size()) != dimension) {
      Fail(where + ".values",
           fmt::format("expected an array of {} arrays (one per coordinate), got {}", dimension, Describe(values)));
    }
    for (int c = 0; c < dimension; ++c) {
      const Json& column = values[static_cast<size_t>(c)];
      const std::string at = fmt::format("{}.values[{}]", where, c);
      if (!column.is_array() || column.empty()) {
        Fail(at, "expected a non-empty array of finite numbers (the values at the Chebyshev points), got " +
                     Describe(column));
      }
      Eigen::VectorXd v(static_cast<Eigen::Index>(column.size()));
      for (size_t j = 0; j < column.size(); ++j) {
        v[static_cast<Eigen::Index>(j)] = Finite(column[j], fmt::format("{}[{}]", at, j));
      }
      window.values.push_back(std::move(v));
    }
    return window;
  }

  std::string path_;
};

}  // namespace

std::string WriteModelJson(const TrajectoryModel& model) {
  std::string out =
      fmt::format("{{\n  \"format\": \"{}\",\n  \"version\": {},\n  \"dimension\": {},\n  \"origin_ns\": {},\n",
                  kFormat, kVersion, model.dimension, model.origin_ns);
  if (model.noise_sigma.size() > 0) out += fmt::format("  \"noise_sigma\": {},\n", NumberArray(model.noise_sigma));
  if (model.residual_rms.size() > 0) out += fmt::format("  \"residual_rms\": {},\n", NumberArray(model.residual_rms));
  if (model.reconstruction) {
    const ReconstructionError& e = *model.reconstruction;
    out += fmt::format(
        "  \"reconstruction\": {{\"samples\": {}, \"max_error\": {}, \"rms_error\": {}, \"worst_stamp_ns\": {}}},\n",
        e.samples, Number(e.max), Number(e.rms), e.worst_stamp_ns);
  }
  if (model.tolerance) out += fmt::format("  \"tolerance\": {},\n", Number(*model.tolerance));
  out += "  \"segments\": [";
  for (size_t k = 0; k < model.segments.size(); ++k) {
    const ModelSegment& segment = model.segments[k];
    out += fmt::format("{}\n    {{\"first_ns\": {}, \"last_ns\": {}, \"windows\": [", k > 0 ? "," : "",
                       segment.first_ns, segment.last_ns);
    for (size_t j = 0; j < segment.windows.size(); ++j) {
      const ModelWindow& w = segment.windows[j];
      out += fmt::format("{}\n      {{\"core\": [{}, {}], \"fit\": [{}, {}], \"values\": [", j > 0 ? "," : "",
                         Number(w.core_begin), Number(w.core_end), Number(w.fit_begin), Number(w.fit_end));
      for (size_t c = 0; c < w.values.size(); ++c) {
        out += fmt::format("{}\n        {}", c > 0 ? "," : "", NumberArray(w.values[c]));
      }
      out += "]}";
    }
    out += "]}";
  }
  return out + fmt::format("\n  ],\n  \"checksum\": \"{}\"\n}}\n", ChecksumText(ModelChecksum(model)));
}

TrajectoryModel ParseModelJson(std::string_view text, const std::string& path) {
  return ModelReader(path).Read(ParseJsonInput(text, path, "a cheval trajectory model"));
}

TrajectoryModel ReadModel(const std::string& path) {
  return ParseModelJson(ReadInputFile(path, kMaxModelFileBytes, "a model JSON file from cheval compress"), path);
}

}  // namespace cheval::cheb

#pragma once
/// \file
/// What the libFuzzer targets of fuzz/ run on one input and the properties they check, in one place.
/// The targets (*_fuzzer.cc) trap on a violation (TrapOnViolation); the regression test
/// (tests/traj/fuzz_regression_test.cc) replays tests/data/fuzz/<target>/ through the same functions,
/// so a kept input is checked exactly as the fuzzer checked it. Needs the cheval library only: no
/// libFuzzer, no GoogleTest. The properties are listed in docs/fuzzing.md.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace cheval::fuzz {

/// The targets that read trajectories (fuzz/CMakeLists.txt builds fuzz_<target> for each): a
/// format given to ParseTrajectory, `auto` (DetectFormat, then kAuto), or `column_map`.
inline constexpr std::array<std::string_view, 8> kTrajectoryTargets{
    {"tum", "tumv", "euroc", "kitti", "vins", "csv", "auto", "column_map"}};

/// The column maps of the csv target; byte 0 of an input picks one (modulo the count).
inline constexpr std::array<std::string_view, 6> kCsvColumnMaps{{
    "t,px,py,pz,qx,qy,qz,qw",                       // TUM as csv (either separator)
    "t_ns,px,py,pz,qw,qx,qy,qz,vx,vy,vz",           // EuRoC/VINS with velocity
    "t,px,py,pz,roll,pitch,yaw",                    // Euler angles (iCub)
    "t_ms,_,px,py,pz",                              // position only, a skipped column
    "t_us,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz",  // everything (crazyflie/DIDO)
    "t_ns,_,_,px,py,pz,skip",                       // position only, trailing skip
}};

/// Runs trajectory target `target` (one of kTrajectoryTargets) on `data`, the fuzzer's input, and
/// checks what it must satisfy. For `csv`, byte 0 picks one of kCsvColumnMaps and the rest is the
/// file; for `column_map`, the first line is a `--columns` spec and the rest a csv file read with it.
///
/// Fine: the input parses and the trajectory has every property of docs/fuzzing.md (sizes, finite
/// values, the promised channels, rotations that are rotations, TUM/EuRoC write -> read round trips),
/// or the reader throws cheval::InputError whose message begins with `path:` (a `--columns` spec:
/// UsageError beginning with `--columns:`).
///
/// Returns nullopt when everything holds, else a description of the first property violated (the
/// condition, where it was checked and the pose or text concerned). Exceptions not derived from
/// cheval::Error escape: they are bugs too, and libFuzzer and GoogleTest both report them.
/// Throws std::invalid_argument for an unknown target.
std::optional<std::string> CheckTrajectoryInput(std::string_view target, std::string_view data);

/// Runs the stamp target on `data`: byte 0 holds the options (bit 0: require_integer; bit 1 set: the
/// scale is byte 1 as a signed char and the text starts at byte 2; else the scale is 9, 6, 3 or 0 by
/// bits 2-3 and the text starts at byte 1); ParseDecimalStamp(text, scale, require_integer) must
/// agree with FormatSeconds (scale 9) and with strtold (plain decimal text). Inputs shorter than two
/// bytes are skipped. Returns nullopt or a description of the violated property, with the text.
std::optional<std::string> CheckStampInput(std::string_view data);

/// Runs the model target on `data` (a `cheval compress` model file's text, docs/compress.md): either
/// cheb::ParseModelJson throws InputError whose message begins with `fuzz.json:`, or the model
/// written back (WriteModelJson) reads back to the same text, CurveFromModel accepts it, and the
/// curve evaluates at every segment's ends and middle (finite values when every stored value and
/// interval end is below 1e100 in magnitude). Returns nullopt or the violated property.
std::optional<std::string> CheckModelInput(std::string_view data);

/// Runs the curve target on `data`: byte 0 gives the dimension d = 1 + byte0 % 3, and every further
/// record of 1 + d bytes is one sample — a stamp step (0: the same stamp again; 1..250: that many
/// 50 µs; 251..255: a gap of (code − 250) · 0.1 s) and d signed bytes of noise (× 0.1 mm) on a smooth
/// 2.3 Hz gait-like motion (DecodeCurveSamples). FitCurve on them, with and without the end caps,
/// must either both throw cheval::ComputeError or both give curves whose windows tile each segment,
/// that Curve::FromParts accepts, and whose value, velocity and acceleration are finite at every
/// sample. Returns nullopt or the violated property.
std::optional<std::string> CheckCurveInput(std::string_view data);

/// libFuzzer's input as the text the checks take.
inline std::string_view AsText(const uint8_t* data, size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

/// What every target does with a check's result: a violated property is printed and trapped on
/// (libFuzzer keeps the input as a crash); otherwise libFuzzer's 0.
int TrapOnViolation(const std::optional<std::string>& violation);

}  // namespace cheval::fuzz

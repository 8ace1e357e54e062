#pragma once
/// \file
/// Reading JSON input files (the vehicle file, a trajectory model): a bounded whole-file read that
/// says what is wrong with the path, and a parse whose every failure is an InputError naming the
/// file and, for a number beyond a double, the key that holds it.

#include <cstdint>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace cheval {

/// The whole content of an input file of at most `max_bytes` bytes. InputError (`path:0:0: error:
/// ...`) when it is a directory ("is a directory; expected WHAT"), cannot be opened or read (the
/// system's reason), or is larger than `max_bytes` (its size and the limit). `what` names the file's
/// role ("a vehicle JSON file").
std::string ReadInputFile(const std::string& path, uint64_t max_bytes, std::string_view what);

/// Parses JSON text. InputError on failure: `path:LINE:COLUMN: error: expected JSON (WHAT): ...` for a
/// syntax error, `path:0:0: error: KEY: the number TEXT is too large for a double (at most 1.8e308 in
/// magnitude)` for a number that overflows (KEY as `camera.rate_hz` or `segments[0].windows[2]`).
nlohmann::json ParseJsonInput(std::string_view text, const std::string& path, std::string_view what);

}  // namespace cheval

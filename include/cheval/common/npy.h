#pragma once
/// \file
/// Reading numpy's `.npy` arrays (format versions 1.0, 2.0 and 3.0), as numpy.save writes them and
/// as evo's result files hold them (docs/cli.md, "cheval res").

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace cheval {

/// A numeric array read from a `.npy` file, its values converted to double in C (row-major) order.
struct NpyArray {
  /// numpy's dtype text as the header gives it ("<f8", "<i8", "|u1", ...).
  std::string dtype;
  /// The shape; empty for a 0-d array (one value).
  std::vector<uint64_t> shape;
  /// Every element, C order. float64 values are the stored bits; float32 and integers convert exactly
  /// (integers beyond 2^53 in magnitude round to the nearest double); bool is 0 or 1.
  std::vector<double> values;
};

/// Parses a `.npy` file. Accepted dtypes: floats `f4`/`f8`, signed and unsigned integers of 1, 2,
/// 4 and 8 bytes and `b1`, little or big endian (`<`, `>`, `|`, `=`), C or Fortran order. Refused with
/// an InputError(`path`, 0, 0, "`what`: ...") naming what is wrong: the magic, the version, a truncated
/// or unparsable header, another dtype (object, strings, complex, structured: "dtype '|O' is not
/// numeric; expected float64 ..."), a shape whose element count overflows, or data shorter or longer
/// than the shape says. `what` names the array in messages (e.g. "member error_array.npy").
NpyArray ParseNpy(std::string_view bytes, const std::string& path, const std::string& what);

}  // namespace cheval

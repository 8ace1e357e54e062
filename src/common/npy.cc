#include "cheval/common/npy.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <limits>

#include <fmt/format.h>

#include "cheval/common/error.h"

namespace cheval {
namespace {

// The value of `key` in numpy's header dict ("{'descr': '<f8', 'fortran_order': False, 'shape': (3,), }"):
// the text from after "'key':" to the next top-level ',' or '}' (a tuple's commas are inside parentheses).
bool HeaderValue(std::string_view header, std::string_view key, std::string* value) {
  const std::string quoted = fmt::format("'{}'", key);
  size_t at = header.find(quoted);
  if (at == std::string_view::npos) return false;
  at = header.find_first_not_of(' ', at + quoted.size());
  if (at == std::string_view::npos || header[at] != ':') return false;
  ++at;
  int depth = 0;
  size_t end = at;
  for (; end < header.size(); ++end) {
    const char c = header[end];
    if (c == '(') ++depth;
    if (c == ')') --depth;
    if (depth == 0 && (c == ',' || c == '}')) break;
  }
  if (depth != 0 || end == header.size()) return false;
  std::string v(header.substr(at, end - at));
  v.erase(std::remove(v.begin(), v.end(), ' '), v.end());
  *value = v;
  return true;
}

struct Dtype {
  char kind = 0;  // 'f', 'i', 'u', 'b'
  size_t size = 0;
  bool big_endian = false;
};

// A numeric dtype text ('<f8', '|u1', '>i4', '=f8'); false for anything else.
bool ParseDtype(const std::string& text, Dtype* d) {
  if (text.size() != 5 || text.front() != '\'' || text.back() != '\'') return false;
  const char order = text[1], kind = text[2], size = text[3];
  if (order != '<' && order != '>' && order != '|' && order != '=') return false;
  d->big_endian = order == '>';
  d->kind = kind;
  d->size = static_cast<size_t>(size - '0');
  if (kind == 'f') return d->size == 4 || d->size == 8;
  if (kind == 'i' || kind == 'u') return d->size == 1 || d->size == 2 || d->size == 4 || d->size == 8;
  if (kind == 'b') return d->size == 1;
  return false;
}

double Element(const unsigned char* p, const Dtype& d) {
  unsigned char b[8];
  std::memcpy(b, p, d.size);
  if (d.big_endian) std::reverse(b, b + d.size);  // to the machine's little-endian order
  uint64_t bits = 0;
  for (size_t k = 0; k < d.size; ++k) bits |= static_cast<uint64_t>(b[k]) << (8 * k);
  switch (d.kind) {
    case 'f':
      if (d.size == 8) return std::bit_cast<double>(bits);
      return static_cast<double>(std::bit_cast<float>(static_cast<uint32_t>(bits)));
    case 'b':
      return bits != 0 ? 1.0 : 0.0;
    case 'u':
      return static_cast<double>(bits);
    default: {  // 'i': sign-extend
      const int shift = static_cast<int>(64 - 8 * d.size);
      return static_cast<double>(static_cast<int64_t>(bits << shift) >> shift);
    }
  }
}

}  // namespace

NpyArray ParseNpy(std::string_view bytes, const std::string& path, const std::string& what) {
  auto fail = [&](const std::string& why) { throw InputError(path, 0, 0, fmt::format("{}: {}", what, why)); };
  if (bytes.size() < 10 || bytes.substr(0, 6) != "\x93NUMPY") {
    fail("not a .npy array: no \\x93NUMPY magic at its start");
  }
  const int major = static_cast<unsigned char>(bytes[6]);
  size_t header_length = 0, offset = 0;
  if (major == 1) {
    header_length = static_cast<unsigned char>(bytes[8]) | (static_cast<size_t>(static_cast<unsigned char>(bytes[9])) << 8);
    offset = 10;
  } else if (major == 2 || major == 3) {
    if (bytes.size() < 12) fail("truncated .npy header");
    for (int k = 0; k < 4; ++k) header_length |= static_cast<size_t>(static_cast<unsigned char>(bytes[8 + k])) << (8 * k);
    offset = 12;
  } else {
    fail(fmt::format(".npy format version {}.{}; expected 1.0, 2.0 or 3.0", major, static_cast<unsigned char>(bytes[7])));
  }
  if (header_length > bytes.size() - offset) {
    fail(fmt::format("truncated .npy header: {} bytes announced, {} present", header_length, bytes.size() - offset));
  }
  const std::string_view header = bytes.substr(offset, header_length);
  if (header.find('{') == std::string_view::npos || header.find('}') == std::string_view::npos) {
    fail("bad .npy header: expected a dict {'descr': ..., 'fortran_order': ..., 'shape': (...)}");
  }
  std::string descr, fortran, shape_text;
  if (!HeaderValue(header, "descr", &descr) || !HeaderValue(header, "fortran_order", &fortran) ||
      !HeaderValue(header, "shape", &shape_text)) {
    fail("bad .npy header: expected the keys 'descr', 'fortran_order' and 'shape'");
  }
  Dtype dtype;
  if (!ParseDtype(descr, &dtype)) {
    fail(fmt::format("dtype {} is not a plain number; expected float64 ('<f8'), or another float, integer or bool "
                     "dtype (object, string, complex and structured arrays are not read)", descr.substr(0, 40)));
  }
  if (fortran != "True" && fortran != "False") fail(fmt::format("bad .npy header: fortran_order is {}", fortran.substr(0, 20)));
  if (shape_text.size() < 2 || shape_text.front() != '(' || shape_text.back() != ')') {
    fail(fmt::format("bad .npy header: shape {} is not a tuple", shape_text.substr(0, 40)));
  }
  NpyArray array;
  array.dtype = descr.substr(1, 3);
  uint64_t count = 1;
  const std::string dims = shape_text.substr(1, shape_text.size() - 2);
  size_t at = 0;
  while (at < dims.size()) {
    size_t end = dims.find(',', at);
    if (end == std::string::npos) end = dims.size();
    const std::string dim = dims.substr(at, end - at);
    if (dim.empty() || dim.size() > 19 || dim.find_first_not_of("0123456789") != std::string::npos) {
      fail(fmt::format("bad .npy header: shape {} has a dimension that is not a whole number", shape_text.substr(0, 40)));
    }
    const uint64_t n = std::stoull(dim);
    if (n != 0 && count > std::numeric_limits<uint64_t>::max() / n) fail("bad .npy header: the shape's element count overflows");
    count *= n;
    array.shape.push_back(n);
    at = end + 1;
  }
  const size_t data_at = offset + header_length, data = bytes.size() - data_at;
  const bool fits = count <= std::numeric_limits<uint64_t>::max() / dtype.size;
  if (!fits || count * dtype.size != data) {
    fail(fmt::format("{} bytes of data, expected {} ({} elements of {} bytes for shape {})", data,
                     fits ? std::to_string(count * dtype.size) : std::string("more than 2^64"), count, dtype.size,
                     shape_text));
  }
  array.values.resize(count);
  const auto* p = reinterpret_cast<const unsigned char*>(bytes.data() + data_at);
  for (uint64_t k = 0; k < count; ++k) array.values[k] = Element(p + k * dtype.size, dtype);
  if (fortran == "True" && array.shape.size() > 1) {  // to C order
    std::vector<double> c(count);
    for (uint64_t k = 0; k < count; ++k) {
      // k is the Fortran index: first dimension fastest.
      uint64_t rest = k, c_index = 0;
      std::vector<uint64_t> index(array.shape.size());
      for (size_t d = 0; d < array.shape.size(); ++d) {
        index[d] = rest % array.shape[d];
        rest /= array.shape[d];
      }
      for (size_t d = 0; d < array.shape.size(); ++d) c_index = c_index * array.shape[d] + index[d];
      c[c_index] = array.values[k];
    }
    array.values = std::move(c);
  }
  return array;
}

}  // namespace cheval

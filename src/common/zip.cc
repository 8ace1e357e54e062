#include "cheval/common/zip.h"

#include <zlib.h>

#include <algorithm>

#include <fmt/format.h>

#include "cheval/common/error.h"

namespace cheval {
namespace {

constexpr uint32_t kLocalHeader = 0x04034b50, kCentralHeader = 0x02014b50, kEndOfDirectory = 0x06054b50;
constexpr uint32_t kZip64EndLocator = 0x07064b50;
constexpr size_t kEndSize = 22, kCentralSize = 46, kLocalSize = 30;

[[noreturn]] void Fail(const std::string& path, const std::string& what) { throw InputError(path, 0, 0, what); }

// Little-endian fields of `bytes` at `at`; the caller has checked the range.
uint32_t Get16(std::string_view bytes, size_t at) {
  return static_cast<uint32_t>(static_cast<unsigned char>(bytes[at])) |
         (static_cast<uint32_t>(static_cast<unsigned char>(bytes[at + 1])) << 8);
}
uint32_t Get32(std::string_view bytes, size_t at) { return Get16(bytes, at) | (Get16(bytes, at + 2) << 16); }

// The end of central directory record: the last signature with a comment that ends at the file's end.
size_t FindEnd(std::string_view bytes, const std::string& path) {
  if (bytes.size() < kEndSize) {
    Fail(path, fmt::format("not a zip archive: {} bytes, shorter than a zip's end record (22 bytes)", bytes.size()));
  }
  const size_t lowest = bytes.size() - kEndSize > 0xffff ? bytes.size() - kEndSize - 0xffff : 0;
  for (size_t at = bytes.size() - kEndSize + 1; at-- > lowest;) {
    if (Get32(bytes, at) == kEndOfDirectory && at + kEndSize + Get16(bytes, at + 20) == bytes.size()) return at;
  }
  Fail(path, "not a zip archive, or a truncated one: no end of central directory record (PK\\5\\6) at its end");
}

std::string Inflate(std::string_view compressed, uint64_t size, const std::string& path, const std::string& member) {
  std::string out(size, '\0');
  z_stream z{};
  if (inflateInit2(&z, -MAX_WBITS) != Z_OK) Fail(path, fmt::format("member {}: zlib could not start inflating", member));
  constexpr size_t kChunk = size_t{1} << 30;  // zlib's counts are 32-bit
  size_t in_at = 0, out_at = 0;
  char spare = 0;  // room to notice bytes beyond the declared size
  std::string error;
  while (error.empty()) {
    const size_t in_chunk = std::min(compressed.size() - in_at, kChunk);
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(compressed.data() + in_at));
    z.avail_in = static_cast<uInt>(in_chunk);
    const bool full = out_at == out.size();
    const size_t out_chunk = full ? 1 : std::min(out.size() - out_at, kChunk);
    z.next_out = reinterpret_cast<Bytef*>(full ? &spare : out.data() + out_at);
    z.avail_out = static_cast<uInt>(out_chunk);
    const int status = inflate(&z, Z_NO_FLUSH);
    in_at += in_chunk - z.avail_in;
    const size_t produced = out_chunk - z.avail_out;
    out_at += full ? 0 : produced;
    if (full && produced > 0) {
      error = fmt::format("inflates to more than its declared {} bytes", size);
    } else if (status == Z_STREAM_END) {
      break;
    } else if (status == Z_DATA_ERROR || status == Z_NEED_DICT) {
      error = fmt::format("bad deflate data ({})", z.msg != nullptr ? z.msg : "corrupt stream");
    } else if (status != Z_OK && !(status == Z_BUF_ERROR && in_at < compressed.size())) {
      error = "bad deflate data (the stream ends before its last block)";
    }
  }
  inflateEnd(&z);
  if (error.empty() && out_at != size) error = fmt::format("inflates to {} bytes, its header says {}", out_at, size);
  if (!error.empty()) Fail(path, fmt::format("member {}: {}", member, error));
  return out;
}

}  // namespace

std::vector<ZipMember> ReadZip(std::string_view bytes, const std::string& path, const ZipLimits& limits) {
  const size_t end = FindEnd(bytes, path);
  if (end >= 20 && Get32(bytes, end - 20) == kZip64EndLocator) {
    Fail(path, "a zip64 archive (over 4 GiB or 65535 members): not supported; result files are never that large");
  }
  if (Get16(bytes, end + 4) != 0 || Get16(bytes, end + 6) != 0 || Get16(bytes, end + 8) != Get16(bytes, end + 10)) {
    Fail(path, "a multi-disk (split) zip archive: not supported");
  }
  const uint64_t count = Get16(bytes, end + 10), directory_size = Get32(bytes, end + 12);
  const uint64_t directory_at = Get32(bytes, end + 16);
  if (directory_at > end || directory_size > end - directory_at) {
    Fail(path, fmt::format("the central directory (offset {}, {} bytes) lies outside the archive's {} bytes before "
                           "its end record: a truncated or damaged zip", directory_at, directory_size, end));
  }
  if (count > limits.max_members) Fail(path, fmt::format("{} members, more than the {} allowed", count, limits.max_members));
  std::vector<ZipMember> members;
  uint64_t total = 0;
  size_t at = directory_at;
  const size_t directory_end = directory_at + directory_size;
  for (uint64_t k = 0; k < count; ++k) {
    if (directory_end - at < kCentralSize || Get32(bytes, at) != kCentralHeader) {
      Fail(path, fmt::format("central directory entry {} of {} is missing or damaged", k + 1, count));
    }
    const uint32_t flags = Get16(bytes, at + 8), method = Get16(bytes, at + 10), crc = Get32(bytes, at + 16);
    const uint64_t compressed = Get32(bytes, at + 20), size = Get32(bytes, at + 24);
    const size_t name_length = Get16(bytes, at + 28), extra = Get16(bytes, at + 30), comment = Get16(bytes, at + 32);
    const uint64_t local_at = Get32(bytes, at + 42);
    if (directory_end - at - kCentralSize < name_length + extra + comment) {
      Fail(path, fmt::format("central directory entry {} of {} is truncated", k + 1, count));
    }
    ZipMember m;
    m.name = std::string(bytes.substr(at + kCentralSize, name_length));
    at += kCentralSize + name_length + extra + comment;
    const std::string& name = m.name;
    if (flags & 1) Fail(path, fmt::format("member {}: encrypted; expected a plain member", name));
    if (compressed == 0xffffffffu || size == 0xffffffffu || local_at == 0xffffffffu) {
      Fail(path, fmt::format("member {}: zip64 sizes; not supported", name));
    }
    if (method != 0 && method != 8) {
      Fail(path, fmt::format("member {}: compression method {}; expected 0 (stored) or 8 (deflate)", name, method));
    }
    if (size > limits.max_member_bytes || total + size > limits.max_total_bytes) {
      Fail(path, fmt::format("member {}: {} bytes uncompressed, more than the {} allowed", name, size,
                             size > limits.max_member_bytes ? limits.max_member_bytes : limits.max_total_bytes - total));
    }
    total += size;
    if (local_at > directory_at || directory_at - local_at < kLocalSize || Get32(bytes, local_at) != kLocalHeader) {
      Fail(path, fmt::format("member {}: no local header at offset {}: a truncated or damaged zip", name, local_at));
    }
    const uint64_t data_at = local_at + kLocalSize + Get16(bytes, local_at + 26) + Get16(bytes, local_at + 28);
    if (data_at > directory_at || compressed > directory_at - data_at) {
      Fail(path, fmt::format("member {}: its {} bytes of data run past the start of the central directory: a "
                             "truncated or damaged zip", name, compressed));
    }
    const std::string_view raw = bytes.substr(data_at, compressed);
    // Deflate gives at most 1032 bytes per byte: a larger claim is a damaged (or hostile) header, refused
    // before the output is allocated.
    if (method == 8 && size > compressed * 1032 + 1024) {
      Fail(path, fmt::format("member {}: claims {} bytes from {} deflated bytes, more than deflate can give", name,
                             size, compressed));
    }
    if (method == 0) {
      if (compressed != size) {
        Fail(path, fmt::format("member {}: stored with {} bytes, its header says {}", name, compressed, size));
      }
      m.data = std::string(raw);
    } else {
      m.data = Inflate(raw, size, path, name);
    }
    uLong check = crc32(0L, Z_NULL, 0);
    for (size_t done = 0; done < m.data.size();) {
      const size_t chunk = std::min<size_t>(m.data.size() - done, 1u << 30);
      check = crc32(check, reinterpret_cast<const Bytef*>(m.data.data() + done), static_cast<uInt>(chunk));
      done += chunk;
    }
    if (static_cast<uint32_t>(check) != crc) {
      Fail(path, fmt::format("member {}: CRC-32 {:08x}, its header says {:08x}: damaged data", name,
                             static_cast<uint32_t>(check), crc));
    }
    members.push_back(std::move(m));
  }
  return members;
}

}  // namespace cheval

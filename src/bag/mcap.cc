// MCAP (https://mcap.dev/spec): magic, records (opcode u8, length u64, content), magic. Schemas give
// the message type, channels the topic and message encoding; messages are top-level or inside chunks
// (uncompressed, zstd or lz4 frames; the chunk's CRC-32 is checked when it is not 0). The summary
// section after DataEnd is not needed and not read.
#include <array>
#include <algorithm>
#include <map>

#include "container.h"

namespace cheval::bag {
namespace {

constexpr std::string_view kMagic("\x89MCAP0\r\n", 8);

enum Op : uint8_t {
  kHeader = 0x01, kFooter = 0x02, kSchema = 0x03, kChannel = 0x04, kMessage = 0x05, kChunk = 0x06, kDataEnd = 0x0F,
};

uint32_t Crc32(std::string_view bytes) {
  static const std::array<uint32_t, 256> table = [] {
    std::array<uint32_t, 256> t{};
    for (uint32_t i = 0; i < 256; ++i) {
      uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) != 0 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  uint32_t crc = 0xFFFFFFFFu;
  for (const char ch : bytes) crc = table[(crc ^ static_cast<uint8_t>(ch)) & 0xFFu] ^ (crc >> 8);
  return crc ^ 0xFFFFFFFFu;
}

std::string_view String(Cursor& c) { return c.Bytes(c.Read<uint32_t>()); }

class McapReader {
 public:
  McapReader(const std::string& path, const Visitor& visitor) : path_(path), visitor_(visitor) {}

  void Read(std::string_view bytes) {
    if (bytes.substr(0, kMagic.size()) != kMagic) {
      throw InputError(path_, 0, 0, "not an MCAP file: expected the magic 89 4D 43 41 50 30 0D 0A at byte 0");
    }
    Records(bytes.substr(kMagic.size()), kMagic.size(), "");
    if (start_ns_ >= 0 && visitor_.on_start_time) visitor_.on_start_time(start_ns_);
  }

 private:
  // Reads records until the end of `bytes` (or DataEnd at the top level). Returns false at DataEnd.
  bool Records(std::string_view bytes, size_t base, const std::string& where) {
    Cursor cursor(bytes, path_, "records");
    while (!cursor.done()) {
      const size_t offset = base + cursor.position();
      if (where.empty() && bytes.size() - cursor.position() == kMagic.size() &&
          bytes.substr(cursor.position()) == kMagic) {
        return false;  // the closing magic of a file without DataEnd/footer
      }
      Cursor head(bytes.substr(cursor.position()), path_, "record at byte", static_cast<int64_t>(offset), where);
      const uint8_t op = head.Read<uint8_t>();
      const uint64_t length = head.Read<uint64_t>();
      Cursor content(head.Bytes(length), path_, "record at byte", static_cast<int64_t>(offset), where);
      cursor.Skip(9 + length);
      switch (op) {
        case kSchema: {
          const uint16_t id = content.Read<uint16_t>();
          const std::string_view name = String(content);
          String(content);  // encoding
          schemas_[id] = std::string(name);
          break;
        }
        case kChannel: Channel(content); break;
        case kMessage: {
          const uint16_t channel = content.Read<uint16_t>();
          content.Read<uint32_t>();  // sequence
          const uint64_t log_time = content.Read<uint64_t>();
          content.Read<uint64_t>();  // publish time
          const auto it = wanted_.find(channel);
          if (it == wanted_.end()) content.Fail(fmt::format("message on channel {}, which no channel record defines", channel));
          if (log_time > static_cast<uint64_t>(INT64_MAX)) content.Fail("log time beyond int64 nanoseconds");
          const int64_t time = static_cast<int64_t>(log_time);
          start_ns_ = start_ns_ < 0 ? time : std::min(start_ns_, time);
          if (it->second) visitor_.on_message(channel, static_cast<int64_t>(log_time), content.Bytes(content.remaining()));
          break;
        }
        case kChunk: {
          if (!where.empty()) content.Fail("a chunk inside a chunk");
          content.Read<uint64_t>();  // start time
          content.Read<uint64_t>();  // end time
          const uint64_t size = content.Read<uint64_t>();
          const uint32_t crc = content.Read<uint32_t>();
          const std::string_view compression = String(content);
          const std::string_view records = content.Bytes(content.Read<uint64_t>());
          const std::string name = fmt::format("chunk at byte {}", offset);
          std::string buffer;
          std::string_view inner = records;
          if (!compression.empty()) {
            buffer = Decompress(compression, records, size, path_, name);
            inner = buffer;
          } else if (records.size() != size) {
            content.Fail(fmt::format("holds {} bytes, its uncompressed_size says {}", records.size(), size));
          }
          if (crc != 0 && Crc32(inner) != crc) {
            throw InputError(path_, 0, 0, fmt::format("{}: wrong CRC-32 of the records ({:#010x}, recorded {:#010x})",
                                                      name, Crc32(inner), crc));
          }
          Records(inner, 0, name + ": ");
          break;
        }
        case kDataEnd:
        case kFooter:
          if (where.empty()) return false;
          content.Fail("a data end or footer record inside a chunk");
        default: break;  // header, indexes, attachments, metadata, statistics: not needed
      }
    }
    if (where.empty()) throw InputError(path_, 0, 0, "truncated: the file ends without a data end record or footer");
    return true;
  }

  void Channel(Cursor& content) {
    const uint16_t id = content.Read<uint16_t>();
    const uint16_t schema = content.Read<uint16_t>();
    const std::string_view topic = String(content);
    const std::string_view encoding = String(content);
    if (wanted_.count(id) != 0) return;
    Connection c;
    c.topic = std::string(topic);
    if (schema != 0) {
      const auto it = schemas_.find(schema);
      if (it == schemas_.end()) content.Fail(fmt::format("channel '{}' names schema {}, which no schema record defines", topic, schema));
      c.type = it->second;
    }
    if (encoding == "cdr") {
      c.encoding = Encoding::kCdr;
    } else if (encoding == "ros1") {
      c.encoding = Encoding::kRos1;
    } else {
      c.encoding = Encoding::kUnsupported;
    }
    wanted_[id] = visitor_.on_connection(id, c);
  }

  const std::string& path_;
  const Visitor& visitor_;
  std::map<uint16_t, std::string> schemas_;
  std::map<uint16_t, bool> wanted_;
  int64_t start_ns_ = -1;  // earliest message log time
};

}  // namespace

void ReadMcapBytes(std::string_view bytes, const std::string& path, const Visitor& visitor) {
  McapReader(path, visitor).Read(bytes);
}

void ReadMcap(const std::string& path, const Visitor& visitor) {
  const std::string bytes = ReadFileBytes(path);
  ReadMcapBytes(bytes, path, visitor);
}

}  // namespace cheval::bag

// ROS 1 bag v2.0 (http://wiki.ros.org/Bags/Format/2.0): records of a header (name=value fields) and
// data. Top level: the bag header, chunks each followed by their index data records, then (from
// index_pos) the connection records and chunk info records. Inside a chunk: connection and message
// data records. Chunks are read in file order; the index data records after each chunk are checked
// against the messages the chunk held.
#include <algorithm>
#include <future>
#include <map>
#include <set>
#include <unordered_map>
#include <vector>

#include "container.h"

namespace cheval::bag {
namespace {

constexpr std::string_view kMagic = "#ROSBAG V2.0\n";

enum Op : uint8_t {
  kMessageData = 0x02,
  kBagHeader = 0x03,
  kIndexData = 0x04,
  kChunk = 0x05,
  kChunkInfo = 0x06,
  kConnection = 0x07,
};

const char* OpName(int op) {
  switch (op) {
    case kMessageData: return "message data record";
    case kBagHeader: return "bag header record";
    case kIndexData: return "index data record";
    case kChunk: return "chunk record";
    case kChunkInfo: return "chunk info record";
    case kConnection: return "connection record";
    default: return "record";
  }
}

// The fields of a record header (or of a connection record's data), as views into the bytes.
struct Fields {
  std::string_view names[12];
  std::string_view values[12];
  int size = 0;

  std::string_view Get(std::string_view name) const {
    for (int i = 0; i < size; ++i) {
      if (names[i] == name) return values[i];
    }
    return {};
  }
  bool Has(std::string_view name) const {
    for (int i = 0; i < size; ++i) {
      if (names[i] == name) return true;
    }
    return false;
  }
};

// A record: header fields, data, and where it starts (for messages).
struct Record {
  Fields fields;
  std::string_view data;
  size_t offset = 0;
  int op = -1;
};

class RecordReader {
 public:
  RecordReader(std::string_view bytes, size_t base, const std::string& path, std::string where)
      : bytes_(bytes), base_(base), path_(path), where_(std::move(where)) {}

  bool done() const { return position_ >= bytes_.size(); }

  Record Next() {
    Record record;
    record.offset = base_ + position_;
    Cursor cursor(bytes_.substr(position_), path_, "record at byte", static_cast<int64_t>(record.offset), where_);
    const uint32_t header_length = cursor.Read<uint32_t>();
    Cursor header(cursor.Bytes(header_length), path_, "record header at byte", static_cast<int64_t>(record.offset), where_);
    while (!header.done()) {
      const uint32_t field_length = header.Read<uint32_t>();
      const std::string_view field = header.Bytes(field_length);
      const size_t equals = field.find('=');
      if (equals == std::string_view::npos) header.Fail("a header field has no '='");
      if (record.fields.size == 12) header.Fail("more than 12 header fields");
      record.fields.names[record.fields.size] = field.substr(0, equals);
      record.fields.values[record.fields.size] = field.substr(equals + 1);
      ++record.fields.size;
    }
    const std::string_view op = record.fields.Get("op");
    if (op.size() != 1) header.Fail("no 1-byte 'op' field");
    record.op = static_cast<uint8_t>(op[0]);
    const uint32_t data_length = cursor.Read<uint32_t>();
    record.data = cursor.Bytes(data_length);
    position_ += cursor.position();
    return record;
  }

 private:
  std::string_view bytes_;
  size_t base_;
  const std::string& path_;
  std::string where_;
  size_t position_ = 0;
};

template <typename T>
T FieldValue(const Record& record, std::string_view name, const std::string& path, const std::string& where) {
  const std::string_view value = record.fields.Get(name);
  if (value.size() != sizeof(T)) {
    throw InputError(path, 0, 0,
                     fmt::format("{}{} at byte {}: field '{}' {}", where, OpName(record.op), record.offset, name,
                                 value.empty() ? "is missing" : fmt::format("has {} bytes, expected {}", value.size(), sizeof(T))));
  }
  T out;
  std::memcpy(&out, value.data(), sizeof(T));
  return out;
}

int64_t TimeNs(const Record& record, const std::string& path, const std::string& where,
               std::string_view field = "time") {
  const uint64_t time = FieldValue<uint64_t>(record, field, path, where);
  const uint32_t sec = static_cast<uint32_t>(time & 0xffffffffu);
  const uint32_t nsec = static_cast<uint32_t>(time >> 32);
  return static_cast<int64_t>(sec) * 1000000000 + nsec;
}

class Ros1Reader {
 public:
  Ros1Reader(const std::string& path, const Visitor& visitor) : path_(path), visitor_(visitor) {}

  void Read(std::string_view bytes) {
    if (bytes.substr(0, 9) == "#ROSBAG V" && bytes.substr(0, kMagic.size()) != kMagic) {
      const std::string_view version = bytes.substr(9, std::min<size_t>(bytes.find('\n'), 16) - 9);
      throw InputError(path_, 0, 0, fmt::format("ROS 1 bag version {} is not read; expected version 2.0 (rosbag "
                                                "reindex/fix converts older bags)",
                                                version));
    }
    if (bytes.substr(0, kMagic.size()) != kMagic) {
      throw InputError(path_, 0, 0, "not a ROS 1 bag: expected the magic '#ROSBAG V2.0' at byte 0");
    }
    // Pass 1: the top-level records, without opening chunks: connections (index section) and the
    // connections each chunk holds (chunk info).
    std::vector<Record> records;
    RecordReader top(bytes.substr(kMagic.size()), kMagic.size(), path_, "");
    bool header_seen = false;
    while (!top.done()) {
      Record record = top.Next();
      if (record.op == kBagHeader) {
        header_seen = true;
      } else if (!header_seen) {
        throw InputError(path_, 0, 0, fmt::format("{} at byte {}: expected the bag header record first",
                                                  OpName(record.op), record.offset));
      } else if (record.op == kConnection) {
        AddConnection(record, "");
      } else if (record.op == kChunkInfo) {
        const uint64_t chunk_pos = FieldValue<uint64_t>(record, "chunk_pos", path_, "");
        Cursor data(record.data, path_, "chunk info record at byte", static_cast<int64_t>(record.offset));
        std::set<uint32_t>& conns = chunk_connections_[chunk_pos];
        while (!data.done()) {
          conns.insert(data.Read<uint32_t>());
          data.Read<uint32_t>();  // count
        }
        if (!conns.empty()) {
          const int64_t start = TimeNs(record, path_, "", "start_time");
          start_ns_ = start_ns_ < 0 ? start : std::min(start_ns_, start);
        }
      }
      records.push_back(record);
    }
    if (!header_seen) throw InputError(path_, 0, 0, "no bag header record after the magic");

    // Pass 2: chunks in file order, each checked against the index data records that follow it.
    // The next wanted compressed chunk is decompressed on another thread while this one is parsed
    // (its errors surface when its turn comes, in file order).
    std::map<uint32_t, uint32_t> chunk_counts;
    bool chunk_read = false;
    size_t chunk_offset = 0;
    std::future<std::string> next;
    size_t next_index = records.size();
    for (size_t i = 0; i < records.size(); ++i) {
      const Record& record = records[i];
      if (record.op == kChunk) {
        chunk_counts.clear();
        chunk_offset = record.offset;
        chunk_read = Wanted(record.offset);
        if (!chunk_read) continue;
        std::string buffer = next_index == i ? next.get() : Inflate(record);
        next_index = records.size();
        size_t j = i + 1;
        while (j < records.size() && records[j].op != kChunk) ++j;
        if (j < records.size() && Wanted(records[j].offset) && records[j].fields.Get("compression") != "none") {
          next = std::async(std::launch::async, [this, &records, j] { return Inflate(records[j]); });
          next_index = j;
        }
        ReadChunk(record, buffer, &chunk_counts);
      } else if (record.op == kIndexData && chunk_read) {
        const uint32_t conn = FieldValue<uint32_t>(record, "conn", path_, "");
        const uint32_t count = FieldValue<uint32_t>(record, "count", path_, "");
        if (chunk_counts[conn] != count) {
          throw InputError(path_, 0, 0,
                           fmt::format("index data record at byte {}: says the chunk at byte {} holds {} messages of "
                                       "connection {}, the chunk holds {}",
                                       record.offset, chunk_offset, count, conn, chunk_counts[conn]));
        }
      } else if (record.op == kMessageData) {
        throw InputError(path_, 0, 0, fmt::format("message data record at byte {}: outside a chunk", record.offset));
      }
    }
    // The start as rosbags gives it: the earliest chunk info start_time (without chunk infos, the
    // earliest message of the chunks read, which are then all of them).
    if (start_ns_ < 0) start_ns_ = first_message_ns_;
    if (start_ns_ >= 0 && visitor_.on_start_time) visitor_.on_start_time(start_ns_);
  }

 private:
  // Whether a chunk must be opened: yes unless its chunk info says it holds no wanted connection.
  bool Wanted(size_t offset) const {
    const auto it = chunk_connections_.find(offset);
    if (it == chunk_connections_.end()) return true;
    for (uint32_t conn : it->second) {
      const auto c = wanted_.find(conn);
      if (c == wanted_.end() || c->second) return true;  // unknown yet: open
    }
    return false;
  }

  void AddConnection(const Record& record, const std::string& where) {
    const uint32_t conn = FieldValue<uint32_t>(record, "conn", path_, where);
    if (wanted_.count(conn) != 0) return;
    Connection connection;
    connection.topic = std::string(record.fields.Get("topic"));
    // The data is a run of fields like a record header.
    Cursor data(record.data, path_, "connection record at byte", static_cast<int64_t>(record.offset), where);
    while (!data.done()) {
      const uint32_t length = data.Read<uint32_t>();
      const std::string_view field = data.Bytes(length);
      const size_t equals = field.find('=');
      if (equals == std::string_view::npos) data.Fail("a connection header field has no '='");
      if (field.substr(0, equals) == "type") connection.type = std::string(field.substr(equals + 1));
      if (field.substr(0, equals) == "topic" && connection.topic.empty()) connection.topic = std::string(field.substr(equals + 1));
    }
    if (connection.topic.empty() || connection.type.empty()) {
      data.Fail("no 'topic' or no 'type' field");
    }
    connection.encoding = Encoding::kRos1;
    wanted_[conn] = visitor_.on_connection(conn, connection);
  }

  // A compressed chunk's records (empty for an uncompressed chunk, whose data is read in place).
  std::string Inflate(const Record& chunk) const {
    const std::string what = fmt::format("chunk record at byte {}", chunk.offset);
    const std::string_view compression = chunk.fields.Get("compression");
    const uint32_t size = FieldValue<uint32_t>(chunk, "size", path_, "");
    if (compression != "none") {
      return Decompress(compression == "bz2" ? "bz2" : compression == "lz4" ? "lz4-frame" : compression, chunk.data,
                        size, path_, what);
    }
    if (chunk.data.size() != size) {
      throw InputError(path_, 0, 0, fmt::format("{}: holds {} bytes, its header says {}", what, chunk.data.size(), size));
    }
    return {};
  }

  // `buffer`: Inflate(chunk).
  void ReadChunk(const Record& chunk, const std::string& buffer, std::map<uint32_t, uint32_t>* counts) {
    const std::string_view content = chunk.fields.Get("compression") != "none" ? std::string_view(buffer) : chunk.data;
    const std::string where = fmt::format("chunk at byte {}: ", chunk.offset);
    RecordReader inner(content, 0, path_, where);
    while (!inner.done()) {
      const Record record = inner.Next();
      if (record.op == kConnection) {
        AddConnection(record, where);
      } else if (record.op == kMessageData) {
        const uint32_t conn = FieldValue<uint32_t>(record, "conn", path_, where);
        const auto it = wanted_.find(conn);
        if (it == wanted_.end()) {
          throw InputError(path_, 0, 0, fmt::format("{}message data record at byte {}: connection {} has no "
                                                    "connection record",
                                                    where, record.offset, conn));
        }
        ++(*counts)[conn];
        const int64_t time = TimeNs(record, path_, where);
        first_message_ns_ = first_message_ns_ < 0 ? time : std::min(first_message_ns_, time);
        if (it->second) visitor_.on_message(conn, time, record.data);
      } else {
        throw InputError(path_, 0, 0, fmt::format("{}{} at byte {} (op {:#04x}): expected connection or message data "
                                                  "records inside a chunk",
                                                  where, OpName(record.op), record.offset, record.op));
      }
    }
  }

  const std::string& path_;
  const Visitor& visitor_;
  std::unordered_map<uint32_t, bool> wanted_;  // connection -> messages wanted
  std::map<uint64_t, std::set<uint32_t>> chunk_connections_;
  int64_t start_ns_ = -1;          // earliest chunk info start_time
  int64_t first_message_ns_ = -1;  // earliest message read
};

}  // namespace

void ReadRos1Bytes(std::string_view bytes, const std::string& path, const Visitor& visitor) {
  Ros1Reader(path, visitor).Read(bytes);
}

void ReadRos1(const std::string& path, const Visitor& visitor) {
  const std::string bytes = ReadFileBytes(path);
  ReadRos1Bytes(bytes, path, visitor);
}

}  // namespace cheval::bag

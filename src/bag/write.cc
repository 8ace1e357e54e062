// Writing recordings (for tests and benchmarks): ROS 1 bags, MCAP files and ROS 2 sqlite3 folders of
// the trajectory message types, in either encoding.
#include <bzlib.h>
#include <lz4frame.h>
#include <sqlite3.h>
#include <zstd.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <memory>

#include "cheval/bag/bag.h"
#include "cheval/common/output.h"
#include "container.h"
#include "container.h"

namespace cheval::bag {
namespace {

// Serializes fields in ROS 1 (packed) or CDR (4-byte header, aligned from its end).
class MessageWriter {
 public:
  explicit MessageWriter(bool cdr) : cdr_(cdr) {
    if (cdr_) out_.append("\x00\x01\x00\x00", 4);
  }
  void Align(size_t n) {
    if (!cdr_) return;
    while ((out_.size() - 4) % n != 0) out_.push_back('\0');
  }
  template <typename T>
  void Put(T value) {
    Align(sizeof(T));
    out_.append(reinterpret_cast<const char*>(&value), sizeof(T));
  }
  void String(std::string_view s) {
    Put<uint32_t>(static_cast<uint32_t>(s.size() + (cdr_ ? 1 : 0)));
    out_.append(s);
    if (cdr_) out_.push_back('\0');
  }
  void Header(int64_t stamp_ns, std::string_view frame) {
    if (!cdr_) Put<uint32_t>(0);
    Put<uint32_t>(static_cast<uint32_t>(stamp_ns / 1000000000));
    Put<uint32_t>(static_cast<uint32_t>(stamp_ns % 1000000000));
    String(frame);
  }
  void Pose(const PoseMessage& m) {
    for (double v : m.position) Put(v);
    for (double v : m.orientation) Put(v);
  }
  void Zeros(int n) {
    for (int i = 0; i < n; ++i) Put(0.0);
  }
  std::string& bytes() { return out_; }

 private:
  bool cdr_;
  std::string out_;
};

const char* TypeName(MessageType type) {
  switch (type) {
    case MessageType::kPoseStamped: return "geometry_msgs/PoseStamped";
    case MessageType::kPoseWithCovarianceStamped: return "geometry_msgs/PoseWithCovarianceStamped";
    case MessageType::kTransformStamped: return "geometry_msgs/TransformStamped";
    case MessageType::kOdometry: return "nav_msgs/Odometry";
    case MessageType::kPath: return "nav_msgs/Path";
    case MessageType::kTfMessage: return "tf2_msgs/TFMessage";
  }
  return "";
}

std::string Ros2Type(MessageType type) {
  std::string name = TypeName(type);
  return name.insert(name.find('/'), "/msg");
}

std::string Serialize(const TopicToWrite& topic, size_t index, bool cdr) {
  const PoseMessage& m = topic.messages[index];
  MessageWriter w(cdr);
  switch (topic.type) {
    case MessageType::kPoseStamped: w.Header(m.stamp_ns, m.frame_id); w.Pose(m); break;
    case MessageType::kPoseWithCovarianceStamped: w.Header(m.stamp_ns, m.frame_id); w.Pose(m); w.Zeros(36); break;
    case MessageType::kTransformStamped:
      w.Header(m.stamp_ns, m.frame_id); w.String(m.child_frame_id); w.Pose(m); break;
    case MessageType::kOdometry:
      w.Header(m.stamp_ns, m.frame_id);
      w.String(m.child_frame_id);
      w.Pose(m);
      w.Zeros(36);
      for (double v : m.linear) w.Put(v);
      for (double v : m.angular) w.Put(v);
      w.Zeros(36);
      break;
    case MessageType::kPath:
      w.Header(m.stamp_ns, m.frame_id);
      w.Put<uint32_t>(static_cast<uint32_t>(index + 1));
      for (size_t i = 0; i <= index; ++i) {
        w.Header(topic.messages[i].stamp_ns, topic.messages[i].frame_id);
        w.Pose(topic.messages[i]);
      }
      break;
    case MessageType::kTfMessage:
      w.Put<uint32_t>(1);
      w.Header(m.stamp_ns, m.frame_id);
      w.String(m.child_frame_id);
      w.Pose(m);
      break;
  }
  return std::move(w.bytes());
}

struct Entry {
  int64_t time;
  uint32_t topic;
  size_t index;
};

std::vector<Entry> InTimeOrder(const std::vector<TopicToWrite>& topics) {
  std::vector<Entry> entries;
  for (uint32_t t = 0; t < topics.size(); ++t) {
    for (size_t i = 0; i < topics[t].messages.size(); ++i) entries.push_back({topics[t].messages[i].record_time_ns, t, i});
  }
  std::stable_sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) { return a.time < b.time; });
  return entries;
}

std::string Compress(const std::string& compression, const std::string& data) {
  if (compression == "bz2") {
    unsigned int length = static_cast<unsigned int>(data.size() + data.size() / 100 + 600);
    std::string out(length, '\0');
    if (BZ2_bzBuffToBuffCompress(out.data(), &length, const_cast<char*>(data.data()),
                                 static_cast<unsigned int>(data.size()), 9, 0, 0) != BZ_OK) {
      throw OutputError("bz2 compression failed");
    }
    out.resize(length);
    return out;
  }
  if (compression == "lz4") {
    std::string out(LZ4F_compressFrameBound(data.size(), nullptr), '\0');
    const size_t n = LZ4F_compressFrame(out.data(), out.size(), data.data(), data.size(), nullptr);
    if (LZ4F_isError(n)) throw OutputError("lz4 compression failed");
    out.resize(n);
    return out;
  }
  if (compression == "zstd") {
    std::string out(ZSTD_compressBound(data.size()), '\0');
    const size_t n = ZSTD_compress(out.data(), out.size(), data.data(), data.size(), 1);
    if (ZSTD_isError(n)) throw OutputError("zstd compression failed");
    out.resize(n);
    return out;
  }
  if (compression == "none" || compression.empty()) return data;
  throw UsageError("WriteOptions::compression '" + compression + "' is not one of none, bz2, lz4, zstd");
}

template <typename T>
void Append(std::string* out, T value) {
  out->append(reinterpret_cast<const char*>(&value), sizeof(T));
}

// ROS 1 ------------------------------------------------------------------------------------------

void Field(std::string* header, std::string_view name, std::string_view value) {
  Append<uint32_t>(header, static_cast<uint32_t>(name.size() + 1 + value.size()));
  header->append(name);
  header->push_back('=');
  header->append(value);
}
template <typename T>
std::string Bytes(T value) {
  return std::string(reinterpret_cast<const char*>(&value), sizeof(T));
}
void Record(std::string* out, const std::string& header, std::string_view data) {
  Append<uint32_t>(out, static_cast<uint32_t>(header.size()));
  out->append(header);
  Append<uint32_t>(out, static_cast<uint32_t>(data.size()));
  out->append(data);
}
uint64_t Ros1Time(int64_t ns) {
  return static_cast<uint64_t>(ns / 1000000000) | (static_cast<uint64_t>(ns % 1000000000) << 32);
}
void ConnectionRecord(std::string* out, uint32_t conn, const TopicToWrite& topic) {
  std::string header, data;
  Field(&header, "op", std::string(1, '\x07'));
  Field(&header, "conn", Bytes(conn));
  Field(&header, "topic", topic.name);
  Field(&data, "topic", topic.name);
  Field(&data, "type", TypeName(topic.type));
  Field(&data, "md5sum", "*");
  Field(&data, "message_definition", "");
  Record(out, header, data);
}

std::string WriteRos1(const std::vector<TopicToWrite>& topics, const WriteOptions& options) {
  std::string out = "#ROSBAG V2.0\n";
  const size_t header_at = out.size();
  auto bag_header = [&](uint64_t index_pos, uint32_t chunks) {
    std::string header;
    Field(&header, "op", std::string(1, '\x03'));
    Field(&header, "index_pos", Bytes(index_pos));
    Field(&header, "conn_count", Bytes(static_cast<uint32_t>(topics.size())));
    Field(&header, "chunk_count", Bytes(chunks));
    std::string record;
    Record(&record, header, std::string(4096 - header.size() - 8, ' '));
    return record;
  };
  out += bag_header(0, 0);
  const std::vector<Entry> entries = InTimeOrder(topics);
  std::vector<bool> connected(topics.size(), false);
  struct ChunkInfo {
    uint64_t pos;
    int64_t start, end;
    std::map<uint32_t, uint32_t> counts;
  };
  std::vector<ChunkInfo> chunks;
  for (size_t begin = 0; begin < entries.size(); begin += static_cast<size_t>(options.messages_per_chunk)) {
    const size_t end = std::min(entries.size(), begin + static_cast<size_t>(options.messages_per_chunk));
    std::string content;
    ChunkInfo info{out.size(), entries[begin].time, entries[end - 1].time, {}};
    std::map<uint32_t, std::vector<std::pair<int64_t, uint32_t>>> index;
    for (size_t k = begin; k < end; ++k) {
      const Entry& e = entries[k];
      if (!connected[e.topic]) {
        ConnectionRecord(&content, e.topic, topics[e.topic]);
        connected[e.topic] = true;
      }
      index[e.topic].push_back({e.time, static_cast<uint32_t>(content.size())});
      ++info.counts[e.topic];
      std::string header;
      Field(&header, "op", std::string(1, '\x02'));
      Field(&header, "conn", Bytes(e.topic));
      Field(&header, "time", Bytes(Ros1Time(e.time)));
      Record(&content, header, Serialize(topics[e.topic], e.index, false));
    }
    std::string header;
    Field(&header, "op", std::string(1, '\x05'));
    Field(&header, "compression", options.compression);
    Field(&header, "size", Bytes(static_cast<uint32_t>(content.size())));
    Record(&out, header, Compress(options.compression, content));
    for (const auto& [conn, list] : index) {
      std::string h, data;
      Field(&h, "op", std::string(1, '\x04'));
      Field(&h, "ver", Bytes(uint32_t{1}));
      Field(&h, "conn", Bytes(conn));
      Field(&h, "count", Bytes(static_cast<uint32_t>(list.size())));
      for (const auto& [time, offset] : list) {
        Append(&data, Ros1Time(time));
        Append(&data, offset);
      }
      Record(&out, h, data);
    }
    chunks.push_back(std::move(info));
  }
  const uint64_t index_pos = out.size();
  for (uint32_t t = 0; t < topics.size(); ++t) ConnectionRecord(&out, t, topics[t]);
  for (const ChunkInfo& c : chunks) {
    std::string h, data;
    Field(&h, "op", std::string(1, '\x06'));
    Field(&h, "ver", Bytes(uint32_t{1}));
    Field(&h, "chunk_pos", Bytes(c.pos));
    Field(&h, "start_time", Bytes(Ros1Time(c.start)));
    Field(&h, "end_time", Bytes(Ros1Time(c.end)));
    Field(&h, "count", Bytes(static_cast<uint32_t>(c.counts.size())));
    for (const auto& [conn, count] : c.counts) {
      Append(&data, conn);
      Append(&data, count);
    }
    Record(&out, h, data);
  }
  out.replace(header_at, 4096, bag_header(index_pos, static_cast<uint32_t>(chunks.size())));
  return out;
}

// MCAP -------------------------------------------------------------------------------------------

void McapString(std::string* out, std::string_view s) {
  Append<uint32_t>(out, static_cast<uint32_t>(s.size()));
  out->append(s);
}
void McapRecord(std::string* out, uint8_t op, const std::string& content) {
  out->push_back(static_cast<char>(op));
  Append<uint64_t>(out, content.size());
  out->append(content);
}

std::string WriteMcap(const std::vector<TopicToWrite>& topics, const WriteOptions& options) {
  const bool cdr = options.mcap_encoding == "cdr";
  if (!cdr && options.mcap_encoding != "ros1") throw UsageError("WriteOptions::mcap_encoding must be cdr or ros1");
  std::string out("\x89MCAP0\r\n", 8);
  std::string header;
  McapString(&header, cdr ? "ros2" : "ros1");
  McapString(&header, "cheval");
  McapRecord(&out, 0x01, header);
  for (uint16_t t = 0; t < topics.size(); ++t) {
    std::string schema;
    Append<uint16_t>(&schema, static_cast<uint16_t>(t + 1));
    McapString(&schema, cdr ? Ros2Type(topics[t].type) : TypeName(topics[t].type));
    McapString(&schema, cdr ? "ros2msg" : "ros1msg");
    McapString(&schema, "");
    McapRecord(&out, 0x03, schema);
    std::string channel;
    Append<uint16_t>(&channel, t);
    Append<uint16_t>(&channel, static_cast<uint16_t>(t + 1));
    McapString(&channel, topics[t].name);
    McapString(&channel, cdr ? "cdr" : "ros1");
    Append<uint32_t>(&channel, 0);  // empty metadata map
    McapRecord(&out, 0x04, channel);
  }
  const std::vector<Entry> entries = InTimeOrder(topics);
  const std::string compression = options.compression == "none" ? "" : options.compression;
  for (size_t begin = 0; begin < entries.size(); begin += static_cast<size_t>(options.messages_per_chunk)) {
    const size_t end = std::min(entries.size(), begin + static_cast<size_t>(options.messages_per_chunk));
    std::string records;
    for (size_t k = begin; k < end; ++k) {
      std::string message;
      Append<uint16_t>(&message, static_cast<uint16_t>(entries[k].topic));
      Append<uint32_t>(&message, static_cast<uint32_t>(k));
      Append<uint64_t>(&message, static_cast<uint64_t>(entries[k].time));
      Append<uint64_t>(&message, static_cast<uint64_t>(entries[k].time));
      message += Serialize(topics[entries[k].topic], entries[k].index, cdr);
      McapRecord(&records, 0x05, message);
    }
    std::string chunk;
    Append<uint64_t>(&chunk, static_cast<uint64_t>(entries[begin].time));
    Append<uint64_t>(&chunk, static_cast<uint64_t>(entries[end - 1].time));
    Append<uint64_t>(&chunk, records.size());
    Append<uint32_t>(&chunk, 0);  // CRC not computed
    McapString(&chunk, compression);
    const std::string compressed = compression.empty() ? records : Compress(compression, records);
    Append<uint64_t>(&chunk, compressed.size());
    chunk += compressed;
    McapRecord(&out, 0x06, chunk);
  }
  McapRecord(&out, 0x0F, std::string(4, '\0'));
  McapRecord(&out, 0x02, std::string(20, '\0'));
  out.append("\x89MCAP0\r\n", 8);
  return out;
}

// ROS 2 ------------------------------------------------------------------------------------------

void WriteRos2(const std::string& folder, const std::vector<TopicToWrite>& topics, const WriteOptions& options) {
  const bool zstd = options.compression == "zstd";
  if (!zstd && options.compression != "none" && !options.compression.empty()) {
    throw UsageError("WriteOptions::compression '" + options.compression + "' for ROS 2 is not one of none, zstd");
  }
  if (zstd && options.ros2_compression_mode != "file" && options.ros2_compression_mode != "message") {
    throw UsageError("WriteOptions::ros2_compression_mode '" + options.ros2_compression_mode +
                     "' is not one of file, message");
  }
  const bool per_message = zstd && options.ros2_compression_mode == "message";
  std::error_code error;
  std::filesystem::create_directories(folder, error);
  if (error) throw OutputError(fmt::format("{}: cannot create the folder: {}", folder, error.message()));
  const std::string db_name = std::filesystem::path(folder).filename().string() + "_0.db3";
  const std::string db_path = (std::filesystem::path(folder) / db_name).string();
  std::filesystem::remove(db_path, error);
  sqlite3* raw = nullptr;
  const int opened = sqlite3_open(db_path.c_str(), &raw);
  std::unique_ptr<sqlite3, decltype(&sqlite3_close)> db(raw, sqlite3_close);
  auto exec = [&](const std::string& sql) {
    if (opened != SQLITE_OK || sqlite3_exec(raw, sql.c_str(), nullptr, nullptr, nullptr) != SQLITE_OK) {
      throw OutputError(fmt::format("{}: {}", db_path, raw != nullptr ? sqlite3_errmsg(raw) : "cannot open"));
    }
  };
  exec("CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, serialization_format "
       "TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
       "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, data "
       "BLOB NOT NULL); BEGIN;");
  std::string yaml_topics;
  for (size_t t = 0; t < topics.size(); ++t) {
    exec(fmt::format("INSERT INTO topics VALUES({}, '{}', '{}', 'cdr', '')", t + 1, topics[t].name, Ros2Type(topics[t].type)));
    yaml_topics += fmt::format("  - message_count: {}\n    topic_metadata:\n      name: {}\n      type: {}\n"
                               "      serialization_format: cdr\n      offered_qos_profiles: ''\n",
                               topics[t].messages.size(), topics[t].name, Ros2Type(topics[t].type));
  }
  sqlite3_stmt* statement = nullptr;
  if (sqlite3_prepare_v2(raw, "INSERT INTO messages(topic_id, timestamp, data) VALUES(?, ?, ?)", -1, &statement,
                         nullptr) != SQLITE_OK) {
    throw OutputError(fmt::format("{}: {}", db_path, sqlite3_errmsg(raw)));
  }
  std::unique_ptr<sqlite3_stmt, decltype(&sqlite3_finalize)> insert(statement, sqlite3_finalize);
  const std::vector<Entry> entries = InTimeOrder(topics);
  for (const Entry& e : entries) {
    const std::string serialized = Serialize(topics[e.topic], e.index, true);
    const std::string data = per_message ? Compress("zstd", serialized) : serialized;
    sqlite3_bind_int64(statement, 1, e.topic + 1);
    sqlite3_bind_int64(statement, 2, e.time);
    sqlite3_bind_blob(statement, 3, data.data(), static_cast<int>(data.size()), SQLITE_TRANSIENT);
    if (sqlite3_step(statement) != SQLITE_DONE) throw OutputError(fmt::format("{}: {}", db_path, sqlite3_errmsg(raw)));
    sqlite3_reset(statement);
  }
  exec("COMMIT;");
  insert.reset();
  db.reset();
  std::string stored = db_name;
  if (zstd && !per_message) {  // rosbag2's FILE mode: the database compressed whole, FILE.zstd
    stored += ".zstd";
    WriteOutput((std::filesystem::path(folder) / stored).string(), Compress("zstd", ReadFileBytes(db_path)));
    std::filesystem::remove(db_path, error);
  }
  const int64_t first = entries.empty() ? 0 : entries.front().time;
  const int64_t last = entries.empty() ? 0 : entries.back().time;
  const std::string yaml = fmt::format(
      "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: sqlite3\n  compression_format: '{}'\n"
      "  compression_mode: '{}'\n  relative_file_paths:\n  - {}\n  message_count: {}\n  starting_time:\n"
      "    nanoseconds_since_epoch: {}\n  duration:\n    nanoseconds: {}\n  topics_with_message_count:\n{}",
      zstd ? "zstd" : "", zstd ? (per_message ? "MESSAGE" : "FILE") : "", stored, entries.size(), first, last - first,
      yaml_topics);
  WriteOutput((std::filesystem::path(folder) / "metadata.yaml").string(), yaml);
}

}  // namespace

void WriteBag(const std::string& path, const std::vector<TopicToWrite>& topics, const WriteOptions& options) {
  if (options.messages_per_chunk < 1) throw OptionError("WriteOptions", "messages_per_chunk", "must be >= 1");
  switch (options.container) {
    case Container::kRos1: WriteOutput(path, WriteRos1(topics, options)); return;
    case Container::kMcap: WriteOutput(path, WriteMcap(topics, options)); return;
    case Container::kRos2: WriteRos2(path, topics, options); return;
    case Container::kNone: break;
  }
  throw UsageError("WriteOptions::container must be ros1, ros2 or mcap");
}

}  // namespace cheval::bag

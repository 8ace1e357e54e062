// ROS 2 bag folders: metadata.yaml (rosbag2_bagfile_information) naming the storage (sqlite3 or mcap)
// and the files, relative to the folder; compression_format zstd with compression_mode FILE (each
// file one zstd frame, FILE.zstd) or MESSAGE (each message's data one zstd frame). sqlite3 files hold
// the tables `topics` (id, name, type, serialization_format) and `messages` (topic_id, timestamp,
// data); messages are CDR.
#include <sqlite3.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <map>
#include <memory>

#include "container.h"

namespace cheval::bag {
namespace {

// A database file, or (`image` not null) a database decompressed into memory from `path`.
void ReadSqlite(const std::string& path, std::string* image, const Visitor& visitor, uint64_t file_index,
                int64_t* first_ns) {
  sqlite3* raw = nullptr;
  if (image == nullptr && !std::filesystem::is_regular_file(path)) {
    throw InputError(path, 0, 0, "cannot open the file (named by metadata.yaml)");
  }
  const int opened = image == nullptr ? sqlite3_open_v2(path.c_str(), &raw, SQLITE_OPEN_READONLY, nullptr)
                                      : sqlite3_open_v2(":memory:", &raw, SQLITE_OPEN_READWRITE, nullptr);
  std::unique_ptr<sqlite3, decltype(&sqlite3_close)> db(raw, sqlite3_close);
  auto fail = [&](const std::string& what) {
    throw InputError(path, 0, 0, fmt::format("{}: {}", what, raw != nullptr ? sqlite3_errmsg(raw) : "cannot open"));
  };
  if (opened != SQLITE_OK) fail("not a readable sqlite3 database");
  if (image != nullptr) {
    const auto size = static_cast<sqlite3_int64>(image->size());
    if (sqlite3_deserialize(raw, "main", reinterpret_cast<unsigned char*>(image->data()), size, size,
                            SQLITE_DESERIALIZE_READONLY) != SQLITE_OK) {
      fail("the decompressed file is not a readable sqlite3 database");
    }
  }
  auto prepare = [&](const char* sql, const std::string& what) {
    sqlite3_stmt* statement = nullptr;
    if (sqlite3_prepare_v2(raw, sql, -1, &statement, nullptr) != SQLITE_OK) fail(what);
    return std::unique_ptr<sqlite3_stmt, decltype(&sqlite3_finalize)>(statement, sqlite3_finalize);
  };
  // Connection ids are unique over the files of the folder: file index in the high bits.
  const uint64_t base = file_index << 40;
  std::map<int64_t, bool> wanted;
  {
    auto topics = prepare("SELECT id, name, type, serialization_format FROM topics", "table 'topics'");
    int status;
    while ((status = sqlite3_step(topics.get())) == SQLITE_ROW) {
      const int64_t id = sqlite3_column_int64(topics.get(), 0);
      Connection c;
      auto text = [&](int column) {
        const unsigned char* t = sqlite3_column_text(topics.get(), column);
        return t == nullptr ? std::string() : std::string(reinterpret_cast<const char*>(t));
      };
      c.topic = text(1);
      c.type = text(2);
      const std::string format = text(3);
      c.encoding = format == "cdr" ? Encoding::kCdr : Encoding::kUnsupported;
      wanted[id] = visitor.on_connection(base + static_cast<uint64_t>(id), c);
    }
    if (status != SQLITE_DONE) fail("table 'topics'");
  }
  auto messages = prepare("SELECT topic_id, timestamp, data FROM messages ORDER BY id", "table 'messages'");
  int status;
  while ((status = sqlite3_step(messages.get())) == SQLITE_ROW) {
    const int64_t topic = sqlite3_column_int64(messages.get(), 0);
    const auto it = wanted.find(topic);
    if (it == wanted.end()) {
      throw InputError(path, 0, 0, fmt::format("table 'messages': topic_id {} is not in table 'topics'", topic));
    }
    const int64_t time = sqlite3_column_int64(messages.get(), 1);
    *first_ns = *first_ns < 0 ? time : std::min(*first_ns, time);
    if (!it->second) continue;
    const void* blob = sqlite3_column_blob(messages.get(), 2);
    const int size = sqlite3_column_bytes(messages.get(), 2);
    visitor.on_message(base + static_cast<uint64_t>(topic), time,
                       std::string_view(static_cast<const char*>(blob), static_cast<size_t>(size)));
  }
  if (status != SQLITE_DONE) fail("table 'messages'");
}

}  // namespace

void ReadRos2(const std::string& folder, const Visitor& visitor) {
  const std::filesystem::path metadata_path = std::filesystem::path(folder) / "metadata.yaml";
  const std::string metadata_name = metadata_path.string();
  YAML::Node info;
  try {
    info = YAML::LoadFile(metadata_name)["rosbag2_bagfile_information"];
  } catch (const YAML::Exception& e) {
    throw InputError(metadata_name, e.mark.line + 1, e.mark.column + 1, fmt::format("not YAML: {}", e.msg));
  }
  try {
    if (!info || !info.IsMap()) throw InputError(metadata_name, 0, 0, "no 'rosbag2_bagfile_information' map");
    const std::string storage = info["storage_identifier"] ? info["storage_identifier"].as<std::string>() : "sqlite3";
    const std::string compression = info["compression_format"] ? info["compression_format"].as<std::string>() : "";
    std::string mode = info["compression_mode"] ? info["compression_mode"].as<std::string>() : "";
    std::transform(mode.begin(), mode.end(), mode.begin(), [](unsigned char c) { return std::toupper(c); });
    if (!compression.empty() && compression != "zstd") {
      throw InputError(metadata_name, 0, 0, fmt::format("compression_format '{}': only zstd (rosbag2's compressor) is "
                                                        "read",
                                                        compression));
    }
    if (!compression.empty() && mode != "FILE" && mode != "MESSAGE") {
      throw InputError(metadata_name, 0, 0, fmt::format("compression_mode '{}': expected FILE or MESSAGE with "
                                                        "compression_format zstd",
                                                        mode));
    }
    const bool file_compressed = !compression.empty() && mode == "FILE";
    // MESSAGE: each message's data is one zstd frame.
    Visitor inflating = visitor;
    int64_t message_number = 0;
    std::string current;  // the storage file being read
    if (!compression.empty() && mode == "MESSAGE") {
      inflating.on_message = [&](uint64_t id, int64_t t, std::string_view data) {
        ++message_number;
        const std::string inflated = DecompressZstd(
            data, current, fmt::format("message {} (compression_mode MESSAGE, log time {} ns)", message_number, t));
        visitor.on_message(id, t, inflated);
      };
    }
    if (storage != "sqlite3" && storage != "mcap") {
      throw InputError(metadata_name, 0, 0, fmt::format("storage_identifier '{}': expected sqlite3 or mcap", storage));
    }
    const YAML::Node files = info["relative_file_paths"];
    if (!files || !files.IsSequence() || files.size() == 0) {
      throw InputError(metadata_name, 0, 0, "no 'relative_file_paths' list");
    }
    uint64_t index = 0;
    int64_t first_ns = -1;
    for (const YAML::Node& file : files) {
      const std::string path = (std::filesystem::path(folder) / file.as<std::string>()).string();
      current = path;
      // FILE: each storage file is one zstd frame (rosbag2 names it FILE.zstd).
      std::string image;
      if (file_compressed) image = DecompressZstd(ReadFileBytes(path), path, "the file (compression_mode FILE)");
      if (storage == "mcap") {
        // Channel ids of several files are kept apart the same way.
        const uint64_t base = index << 40;
        Visitor shifted;
        shifted.on_connection = [&](uint64_t id, const Connection& c) { return inflating.on_connection(base + id, c); };
        shifted.on_message = [&](uint64_t id, int64_t t, std::string_view d) { inflating.on_message(base + id, t, d); };
        shifted.on_start_time = [&](int64_t t) { first_ns = first_ns < 0 ? t : std::min(first_ns, t); };
        if (file_compressed) {
          ReadMcapBytes(image, path, shifted);
        } else {
          ReadMcap(path, shifted);
        }
      } else {
        ReadSqlite(path, file_compressed ? &image : nullptr, inflating, index, &first_ns);
      }
      ++index;
    }
    // The start as rosbags gives it: metadata.yaml's starting_time (else the earliest message read).
    const YAML::Node start = info["starting_time"]["nanoseconds_since_epoch"];
    if (start && start.IsScalar()) first_ns = start.as<int64_t>();
    if (first_ns >= 0 && visitor.on_start_time) visitor.on_start_time(first_ns);
  } catch (const YAML::Exception& e) {
    throw InputError(metadata_name, e.mark.line + 1, e.mark.column + 1, fmt::format("unexpected content: {}", e.msg));
  }
}

}  // namespace cheval::bag

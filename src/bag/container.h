#pragma once
// The containers seen from the message decoders: each reader walks its file and reports connections
// (topic, type, encoding) and messages (connection, log time, bytes). Internal to src/bag.
#include <cstdint>
#include <cstring>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "cheval/bag/bag.h"
#include "cheval/common/error.h"

namespace cheval::bag {

enum class Encoding { kRos1, kCdr, kUnsupported };

struct Connection {
  std::string topic;
  std::string type;  // as recorded
  Encoding encoding = Encoding::kRos1;
};

// What a reader calls. `on_connection` returns whether the connection's messages are wanted (a reader
// may then skip decompressing chunks without any); `on_message` gets the bytes, valid during the call.
struct Visitor {
  std::function<bool(uint64_t id, const Connection&)> on_connection;
  std::function<void(uint64_t id, int64_t log_time_ns, std::string_view data)> on_message;
  // Optional: the recording's start as its index or metadata gives it (the earliest log time of any
  // message: ROS 1 chunk infos, ROS 2 metadata.yaml `starting_time`, MCAP message records), called
  // once after the messages when the recording holds any.
  std::function<void(int64_t start_ns)> on_start_time;
};

// Walks one recording with a visitor (a reader bound to its source).
using Walker = std::function<void(const Visitor&)>;

void ReadRos1(const std::string& path, const Visitor& visitor);
void ReadMcap(const std::string& path, const Visitor& visitor);
void ReadRos2(const std::string& path, const Visitor& visitor);

// The same readers on bytes already in memory (`path` only names the source in messages); the fuzzers
// use these.
void ReadRos1Bytes(std::string_view bytes, const std::string& path, const Visitor& visitor);
void ReadMcapBytes(std::string_view bytes, const std::string& path, const Visitor& visitor);

// ListTopics and ReadBagTrajectory on any source (`path` names it in messages); the fuzzers use them
// on bytes in memory.
std::vector<TopicInfo> ListTopicsWith(const Walker& walk);
traj::Trajectory ReadTrajectoryWith(const std::string& path, const Walker& walk, const BagReadOptions& options);

// The whole file; InputError when it cannot be read.
std::string ReadFileBytes(const std::string& path);

// Decompression into a buffer of exactly `size` bytes (the size the container records). `what` names
// the record in messages ("chunk at byte 4117"). InputError on corrupt data or a size mismatch.
std::string Decompress(std::string_view compression, std::string_view data, uint64_t size, const std::string& path,
                       const std::string& what);

// One zstd frame, whether or not its header records the uncompressed size (ROS 2 compressed bags).
std::string DecompressZstd(std::string_view data, const std::string& path, const std::string& what);

// A little-endian cursor over bytes that throws InputError on a read past the end, naming what it
// reads as `PREFIX LABEL NUMBER` ("chunk at byte 4109: record at byte 70"); the name is formatted
// only on failure (a cursor is made per record and per message).
class Cursor {
 public:
  Cursor(std::string_view bytes, const std::string& path, std::string_view label, int64_t number = -1,
         std::string_view prefix = {})
      : bytes_(bytes), path_(path), label_(label), prefix_(prefix), number_(number) {}

  size_t position() const { return position_; }
  size_t remaining() const { return bytes_.size() - position_; }
  bool done() const { return position_ >= bytes_.size(); }

  template <typename T>
  T Read() {
    Need(sizeof(T));
    T value;
    std::memcpy(&value, bytes_.data() + position_, sizeof(T));
    position_ += sizeof(T);
    return value;
  }
  std::string_view Bytes(uint64_t n) {
    Need(n);
    std::string_view out = bytes_.substr(position_, n);
    position_ += n;
    return out;
  }
  void Skip(uint64_t n) { Need(n); position_ += n; }
  // Pads to a multiple of `n` counted from `origin` (CDR alignment).
  void Align(size_t n, size_t origin) {
    const size_t offset = (position_ - origin) % n;
    if (offset != 0) Skip(n - offset);
  }
  [[noreturn]] void Fail(const std::string& problem) const {
    const std::string what = number_ >= 0 ? fmt::format("{}{} {}", prefix_, label_, number_)
                                          : fmt::format("{}{}", prefix_, label_);
    throw InputError(path_, 0, 0, fmt::format("{}: {}", what, problem));
  }

 private:
  void Need(uint64_t n) const {
    if (n > remaining()) {
      Fail(fmt::format("truncated: needs {} more bytes at byte {}, {} left", n, position_, remaining()));
    }
  }

  std::string_view bytes_;
  const std::string& path_;
  std::string_view label_;
  std::string_view prefix_;
  int64_t number_;
  size_t position_ = 0;
};

}  // namespace cheval::bag

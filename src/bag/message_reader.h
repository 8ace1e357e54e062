#pragma once
// One message's fields in ROS 1 serialization or CDR. Internal to src/bag.
#include <string>
#include <string_view>

#include "container.h"

namespace cheval::bag {

// Reads one message in either encoding. CDR: a 4-byte encapsulation header (little-endian only),
// then fields aligned to their size from the end of the header; ROS 1: packed little-endian.
class MessageReader {
 public:
  // Errors name the message as `PREFIX message NUMBER`.
  MessageReader(std::string_view data, Encoding encoding, const std::string& path, std::string_view prefix,
                int64_t number)
      : cursor_(data, path, "message", number, prefix), cdr_(encoding == Encoding::kCdr) {
    if (encoding == Encoding::kUnsupported) cursor_.Fail("the message encoding is neither cdr nor ros1");
    if (cdr_) {
      const std::string_view header = cursor_.Bytes(4);
      if (header[0] != 0 || (header[1] != 1 && header[1] != 3)) {
        cursor_.Fail(header[1] == 0 || header[1] == 2 ? "big-endian CDR is not supported"
                                                      : "not CDR: expected the encapsulation header 00 01");
      }
    }
  }

  uint32_t U32() {
    if (cdr_) cursor_.Align(4, 4);
    return cursor_.Read<uint32_t>();
  }
  double F64() {
    if (cdr_) cursor_.Align(8, 4);
    return cursor_.Read<double>();
  }
  void F64s(double* out, int n) {
    for (int i = 0; i < n; ++i) out[i] = F64();
  }
  void SkipF64s(int n) {
    for (int i = 0; i < n; ++i) F64();
  }
  std::string_view String() {
    const uint32_t length = U32();
    std::string_view s = cursor_.Bytes(length);
    if (cdr_) {
      if (s.empty() || s.back() != '\0') cursor_.Fail("a CDR string without its terminating NUL");
      s.remove_suffix(1);
    }
    return s;
  }
  int64_t Time() {
    const uint32_t sec = U32();
    const uint32_t nsec = U32();
    if (nsec >= 1000000000u) cursor_.Fail(fmt::format("a stamp with {} nanoseconds (must be < 1e9)", nsec));
    // ROS 1 time is unsigned, ROS 2's builtin_interfaces/Time has a signed second count.
    const int64_t seconds = cdr_ ? static_cast<int64_t>(static_cast<int32_t>(sec)) : static_cast<int64_t>(sec);
    return seconds * 1000000000 + nsec;
  }
  // std_msgs/Header: the stamp; the frame into `frame_id`.
  int64_t Header(std::string_view* frame_id) {
    if (!cdr_) U32();  // seq
    const int64_t stamp = Time();
    *frame_id = String();
    return stamp;
  }
  [[noreturn]] void Fail(const std::string& problem) const { cursor_.Fail(problem); }

 private:
  Cursor cursor_;
  bool cdr_;
};

// "pkg/msg/Name" (ROS 2) as "pkg/Name" (ROS 1); other names unchanged.
std::string ShortType(std::string_view type);

}  // namespace cheval::bag

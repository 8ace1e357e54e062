#pragma once
/// \file
/// Reading zip archives (the result files of evo and of `cheval ape --save-results`): every member,
/// stored or deflated, with its CRC-32 and sizes checked. No zip64, no encryption, one disk; each is
/// refused with a message that says so. docs/cli.md, "cheval res".

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace cheval {

/// One member of a zip archive: its name as the central directory gives it, and its bytes.
struct ZipMember {
  std::string name;
  std::string data;
};

/// Limits of ReadZip, against archives that claim (or inflate to) more than any result file holds.
struct ZipLimits {
  /// Largest uncompressed size of one member.
  uint64_t max_member_bytes = uint64_t{1} << 30;
  /// Largest sum of the uncompressed sizes of all members.
  uint64_t max_total_bytes = uint64_t{2} << 30;
  /// Most members.
  uint64_t max_members = 100000;
};

/// Every member of the zip archive `bytes`, in the central directory's order. Methods 0 (stored) and 8
/// (deflate, with zlib). Throws InputError(`path`, 0, 0, ...) when the bytes are no zip archive (no end
/// of central directory record), a record is truncated or points outside the file, a member is
/// encrypted, uses another method or zip64, inflates to other bytes than its sizes and CRC-32 say, or
/// exceeds `limits`; the message names the member ("member error_array.npy: CRC-32 ...").
std::vector<ZipMember> ReadZip(std::string_view bytes, const std::string& path, const ZipLimits& limits = {});

}  // namespace cheval

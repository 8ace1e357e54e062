// Trajectory readers: every format is described as a row layout (separator, role of each column,
// accepted field counts) and read by one scanner, so all formats share the same checks and the
// same error messages.
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <sstream>

#include <sys/stat.h>
#include <unistd.h>

#include <fmt/format.h>

#include "cheval/bag/bag.h"
#include "cheval/common/error.h"
#include "cheval/traj/io.h"
#include "cheval/traj/stamp.h"
#include "cheval/traj/validate.h"

namespace cheval::traj {
namespace {

struct Field {
  std::string_view text;
  int64_t column;  // 1-based column of the first character
};

// "N bytes (X MiB)" for messages about sizes.
std::string Bytes(uint64_t bytes) {
  return bytes >= (uint64_t{1} << 30) ? fmt::format("{} bytes ({:.3g} GiB)", bytes, static_cast<double>(bytes) / (1 << 30))
                                      : fmt::format("{} bytes ({:.3g} MiB)", bytes, static_cast<double>(bytes) / (1 << 20));
}

// An input file read a block at a time, each block checked as it arrives: no NUL byte (a text file
// has none; /dev/zero and binary files stop at the first block), no line longer than
// kMaxInputLineBytes, and no more than MaxInputFileBytes() in all. So a FIFO, a device or a file
// without newlines is refused after at most a block past kMaxInputLineBytes, and a large file is
// never held whole in memory: the scanner keeps only the lines it has not reached yet.
class BlockReader {
 public:
  explicit BlockReader(std::string path) : path_(std::move(path)), file_(nullptr, &std::fclose) {
    if (path_.find('\0') != std::string::npos) {
      throw InputError(QuoteField(path_, std::string::npos), 0, 0,
                       "the file name contains a NUL byte (\\0); expected a path");
    }
    file_.reset(std::fopen(path_.c_str(), "rb"));
    if (file_ == nullptr) throw InputError(path_, 0, 0, fmt::format("cannot open file: {}", std::strerror(errno)));
    struct stat status {};
    if (fstat(fileno(file_.get()), &status) != 0) {
      throw InputError(path_, 0, 0, fmt::format("cannot read file: {}", std::strerror(errno)));
    }
    if (S_ISDIR(status.st_mode)) throw InputError(path_, 0, 0, "is a directory; expected a trajectory file");
    if (S_ISREG(status.st_mode)) {
      size_ = static_cast<uint64_t>(status.st_size);
      if (size_ > limit_) throw TooLarge(size_, "the file is");
    }
  }

  // The file's size where it is a regular file, else 0 (only to reserve memory).
  uint64_t size() const { return size_; }

  // Appends the next block of the file to `buffer`; false at its end.
  bool Append(std::string* buffer) {
    if (done_) return false;
    const size_t old = buffer->size();
    buffer->resize(old + kBlockBytes);
    const size_t n = std::fread(buffer->data() + old, 1, kBlockBytes, file_.get());
    buffer->resize(old + n);
    if (n == 0) {
      done_ = true;
      if (std::ferror(file_.get())) {
        throw InputError(path_, 0, 0, fmt::format("cannot read file: {}", std::strerror(errno)));
      }
      return false;
    }
    Check(std::string_view(*buffer).substr(old));
    read_ += n;
    if (read_ > limit_) throw TooLarge(read_, "the input is more than");
    return true;
  }

 private:
  static constexpr size_t kBlockBytes = size_t{1} << 20;

  InputError TooLarge(uint64_t size, const char* what) const {
    return InputError(path_, 0, 0,
                      fmt::format("{} {}; the largest input file read is {} (the smaller of 8 GiB and half the "
                                  "physical memory)",
                                  what, Bytes(size), Bytes(limit_)));
  }

  // Checks a new block; line_ and line_bytes_ (the length of the line so far) carry over.
  void Check(std::string_view block) {
    const auto fail_long = [&](size_t length) {
      throw InputError(path_, line_, 1,
                       fmt::format("no newline in the first {} of this line; expected lines of a trajectory file, "
                                   "at most {} each",
                                   Bytes(length), Bytes(kMaxInputLineBytes)));
    };
    const size_t nul = block.find('\0');
    const size_t stop = nul == std::string_view::npos ? block.size() : nul;
    size_t line_start = 0;  // in `block`; the line began line_bytes_ before the block
    size_t carried = line_bytes_;
    for (size_t i = 0; i < stop;) {
      const void* found = std::memchr(block.data() + i, '\n', stop - i);
      if (found == nullptr) break;
      const size_t newline = static_cast<size_t>(static_cast<const char*>(found) - block.data());
      if (carried + newline - line_start > kMaxInputLineBytes) fail_long(carried + newline - line_start);
      line_start = newline + 1;
      carried = 0;
      ++line_;
      i = newline + 1;
    }
    line_bytes_ = carried + stop - line_start;
    if (line_bytes_ > kMaxInputLineBytes) fail_long(line_bytes_);
    if (nul != std::string_view::npos) {
      throw InputError(path_, line_, static_cast<int64_t>(line_bytes_) + 1,
                       "contains a NUL byte (\\0); expected a text file");
    }
  }

  std::string path_;
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file_;
  uint64_t limit_ = MaxInputFileBytes();
  uint64_t size_ = 0;
  uint64_t read_ = 0;
  int64_t line_ = 1;
  size_t line_bytes_ = 0;
  bool done_ = false;
};

// Walks over the lines of a text, skipping blank lines and `#` comments: a text in memory, or a file
// streamed through a buffer. A line's view (and its fields') holds until the next call of Next().
class LineScanner {
 public:
  explicit LineScanner(std::string_view content) : content_(content) {}

  // Streams `file` through `buffer`, starting with what the buffer holds already (text read from the
  // same file). With `keep`, the buffer keeps every line (a look at the first lines, read again
  // later from the buffer); without, the lines behind are dropped as the buffer is refilled.
  LineScanner(BlockReader* file, std::string* buffer, bool keep)
      : content_(*buffer), file_(file), buffer_(buffer), keep_(keep) {}

  // Moves to the next data line; false at the end of the text.
  bool Next() {
    while (true) {
      size_t end = content_.find('\n', position_);
      while (end == std::string_view::npos && Refill()) end = content_.find('\n', position_);
      if (position_ >= content_.size()) return false;
      has_newline_ = end != std::string_view::npos;
      const size_t stop = has_newline_ ? end : content_.size();
      line_ = content_.substr(position_, stop - position_);
      if (!line_.empty() && line_.back() == '\r') line_.remove_suffix(1);
      position_ = has_newline_ ? stop + 1 : stop;
      ++line_number_;
      const size_t first = line_.find_first_not_of(" \t");
      if (first == std::string_view::npos) continue;  // blank
      if (line_[first] == '#') {
        if (first_comment_.empty()) first_comment_ = line_.substr(first);
        continue;
      }
      return true;
    }
  }

  std::string_view line() const { return line_; }
  int64_t line_number() const { return line_number_; }
  // False only for a last line that is not terminated by a newline.
  bool has_newline() const { return has_newline_; }
  std::string_view first_comment() const { return first_comment_; }

  // Splits the current line at `separator` (',' or ' ' meaning runs of spaces/tabs), trimming
  // spaces and tabs around comma-separated fields. One empty field after a final comma is dropped.
  void Split(char separator, std::vector<Field>* fields) const {
    fields->clear();
    const std::string_view line = line_;
    if (separator == ',') {
      size_t start = 0;
      while (true) {
        const size_t comma = line.find(',', start);
        const size_t stop = comma == std::string_view::npos ? line.size() : comma;
        size_t b = start, e = stop;
        while (b < e && (line[b] == ' ' || line[b] == '\t')) ++b;
        while (e > b && (line[e - 1] == ' ' || line[e - 1] == '\t')) --e;
        fields->push_back({line.substr(b, e - b), static_cast<int64_t>(b + 1)});
        if (comma == std::string_view::npos) break;
        start = comma + 1;
      }
      if (fields->size() > 1 && fields->back().text.empty()) fields->pop_back();
    } else {
      size_t i = 0;
      while (i < line.size()) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
        if (i >= line.size()) break;
        const size_t b = i;
        while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
        fields->push_back({line.substr(b, i - b), static_cast<int64_t>(b + 1)});
      }
    }
  }

  // One past the last character of the current line, as a 1-based column.
  int64_t end_column() const { return static_cast<int64_t>(line_.size()) + 1; }

 private:
  // Reads the next block of a streamed file into the buffer, first dropping the lines behind the
  // current position (unless kept); false for a text in memory or at the file's end.
  bool Refill() {
    if (file_ == nullptr) return false;
    if (!keep_ && position_ > 0) {
      buffer_->erase(0, position_);
      position_ = 0;
    }
    const bool more = file_->Append(buffer_);
    content_ = *buffer_;
    return more;
  }

  std::string_view content_;
  BlockReader* file_ = nullptr;  // the streamed file, or null for a text in memory
  std::string* buffer_ = nullptr;
  bool keep_ = false;
  size_t position_ = 0;
  std::string_view line_;
  int64_t line_number_ = 0;
  bool has_newline_ = true;
  std::string first_comment_;  // owned: the buffer it was read from is refilled
};

// A field is name-like (part of a header row) when it starts with a letter, '_' or a quote.
bool LooksLikeName(std::string_view text) {
  if (text.empty()) return false;
  const char c = text.front();
  return std::isalpha(static_cast<unsigned char>(c)) || c == '_' || c == '"' || c == '\'';
}

bool IsHeaderRow(const std::vector<Field>& fields) {
  if (fields.empty()) return false;
  for (const Field& f : fields) {
    // "nan"/"inf" look like names but are numbers; a header never consists of them alone.
    if (!LooksLikeName(f.text) || f.text == "nan" || f.text == "inf" || f.text == "NaN") return false;
  }
  return true;
}

// std::from_chars reports result_out_of_range alike for a decimal beyond the largest double (~1.8e308)
// and for one that rounds to zero (below half the smallest subnormal, ~2.5e-324). Tells which from
// the power of ten of the leading significant digit, which is then >= 308 or <= -324: true for the
// tiny one. `text` is what from_chars matched: [-]digits[.digits][(e|E)[+|-]digits].
bool RoundsToZero(std::string_view text) {
  size_t i = !text.empty() && text.front() == '-' ? 1 : 0;
  int64_t integer_digits = 0;  // before the point, leading zeros excluded
  int64_t fraction_zeros = 0;  // after the point, before the first nonzero digit
  bool point = false, fraction_nonzero = false;
  for (; i < text.size() && text[i] != 'e' && text[i] != 'E'; ++i) {
    const char c = text[i];
    if (c == '.') {
      point = true;
    } else if (!point) {
      if (integer_digits > 0 || c != '0') ++integer_digits;
    } else if (!fraction_nonzero) {
      if (c == '0') ++fraction_zeros; else fraction_nonzero = true;
    }
  }
  int64_t exponent = 0;
  bool negative_exponent = false;
  if (i < text.size()) {
    ++i;  // 'e'
    if (i < text.size() && (text[i] == '+' || text[i] == '-')) negative_exponent = text[i++] == '-';
    // Saturates: any exponent beyond 1e15 is far outside a double either way.
    for (; i < text.size(); ++i) exponent = std::min<int64_t>(exponent * 10 + (text[i] - '0'), 1'000'000'000'000'000);
  }
  const int64_t leading = integer_digits > 0 ? integer_digits - 1 : -fraction_zeros - 1;
  return leading + (negative_exponent ? -exponent : exponent) < 0;
}

// Parses a double with std::from_chars; accepts a leading '+'. nullopt on anything else. A decimal
// too large for a double gives ±inf (Number() reports it). One too small to be told from zero gives
// ±0: that is its correctly rounded value, the one strtod, Python's float() and numpy.loadtxt (so
// evo) give, just as 1e-320 rounds to a subnormal and 0.1 to the nearest double.
std::optional<double> ParseDouble(std::string_view text) {
  // One sign at most: "+-1", "-+1" and "++1" are no numbers (from_chars would read "-1" after a '+').
  if (!text.empty() && text.front() == '+') {
    text.remove_prefix(1);
    if (!text.empty() && (text.front() == '+' || text.front() == '-')) return std::nullopt;
  }
  if (text.empty() || (text.front() == '-' && text.size() > 1 && (text[1] == '+' || text[1] == '-'))) {
    return std::nullopt;
  }
  double value = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (end != text.data() + text.size()) return std::nullopt;  // trailing garbage, or no number at all
  if (ec == std::errc::result_out_of_range) {
    const double magnitude = RoundsToZero(text) ? 0.0 : std::numeric_limits<double>::infinity();
    return text.front() == '-' ? -magnitude : magnitude;
  }
  if (ec != std::errc()) return std::nullopt;
  return value;
}

// A row layout: what each column holds, how many fields a row may have, and names for messages.
struct Layout {
  Format format = Format::kTum;
  char separator = ' ';
  std::vector<ColumnRole> roles;      // role per column (kitti: unused)
  std::vector<std::string> names;     // display name per column, for messages
  std::vector<size_t> field_counts;   // accepted counts; empty = at least roles.size()
  bool kitti = false;
  bool velocity = false;
  bool angular_velocity = false;
  OrientationKind orientation = OrientationKind::kQuaternion;
  bool euler = false;
  size_t first_quaternion_field = 0;  // for the zero-norm message
  // Fields after those of `roles` must still be numbers (EuRoC's biases); else they are ignored.
  bool numbers_after_roles = false;
};

std::vector<std::string> Split(std::string_view names) {
  std::vector<std::string> out;
  std::istringstream in{std::string(names)};
  for (std::string name; in >> name;) out.push_back(name);
  return out;
}

std::vector<ColumnRole> RolesOf(std::string_view spec) { return ColumnMap::Parse(spec).roles; }

Layout MakeLayout(const ColumnMap& map, char separator, Format format) {
  Layout layout;
  layout.format = format;
  layout.separator = separator;
  layout.roles = map.roles;
  std::string names = map.ToString();
  std::replace(names.begin(), names.end(), ',', ' ');
  layout.names = Split(names);
  bool quaternion = false;
  for (size_t i = 0; i < map.roles.size(); ++i) {
    const ColumnRole r = map.roles[i];
    layout.velocity = layout.velocity || r == ColumnRole::kVx;
    layout.angular_velocity = layout.angular_velocity || r == ColumnRole::kWx;
    layout.euler = layout.euler || r == ColumnRole::kRoll;
    if (r == ColumnRole::kQx || r == ColumnRole::kQy || r == ColumnRole::kQz || r == ColumnRole::kQw) {
      if (!quaternion) layout.first_quaternion_field = i;
      quaternion = true;
    }
  }
  layout.orientation = (quaternion || layout.euler) ? OrientationKind::kQuaternion : OrientationKind::kNone;
  return layout;
}

// TUM (8 fields), TUM + velocity (11) and TUM + velocity + body angular velocity (14, what
// `cheval velocity --angular` and `cheval sim motion --truth` write). For tumv the first row
// decides between 11 and 14 (FixLayoutFromFirstRow).
Layout TumLayout(bool velocity, bool angular = false) {
  const char* roles = angular    ? "t,px,py,pz,qx,qy,qz,qw,vx,vy,vz,wx,wy,wz"
                      : velocity ? "t,px,py,pz,qx,qy,qz,qw,vx,vy,vz"
                                 : "t,px,py,pz,qx,qy,qz,qw";
  Layout layout = MakeLayout(ColumnMap{RolesOf(roles)}, ' ', velocity ? Format::kTumV : Format::kTum);
  layout.names = Split("t x y z qx qy qz qw vx vy vz wx wy wz");
  layout.names.resize(layout.roles.size());
  layout.field_counts = {layout.roles.size()};
  return layout;
}

// EuRoC and VINS share the row layout t_ns p q(w first) [v ...]; `fields` is the first row's count.
Layout NanosecondCsvLayout(Format format, bool velocity) {
  Layout layout = MakeLayout(
      ColumnMap{RolesOf(velocity ? "t_ns,px,py,pz,qw,qx,qy,qz,vx,vy,vz" : "t_ns,px,py,pz,qw,qx,qy,qz")}, ',', format);
  layout.names = Split("t_ns px py pz qw qx qy qz vx vy vz bwx bwy bwz bax bay baz");
  return layout;
}

Layout KittiLayout() {
  Layout layout;
  layout.format = Format::kKitti;
  layout.separator = ' ';
  layout.kitti = true;
  layout.orientation = OrientationKind::kMatrix;
  layout.names = Split("r00 r01 r02 tx r10 r11 r12 ty r20 r21 r22 tz");
  layout.field_counts = {12};
  return layout;
}

std::string JoinNames(const std::vector<std::string>& names, size_t count) {
  std::string out;
  for (size_t i = 0; i < count && i < names.size(); ++i) {
    if (i > 0) out += ' ';
    out += names[i];
  }
  return out;
}

std::string FieldName(const Layout& layout, size_t index) {
  return index < layout.names.size() ? fmt::format("field {} ({})", index + 1, layout.names[index])
                                     : fmt::format("field {}", index + 1);
}

Eigen::Quaterniond QuaternionFromRollPitchYaw(double roll, double pitch, double yaw) {
  return Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
}

class Reader {
 public:
  // Reads the rows `scanner` walks; `size` is the text's size in bytes where known (else 0), only to
  // reserve memory.
  Reader(LineScanner scanner, uint64_t size, std::string path)
      : scanner_(std::move(scanner)), content_size_(size), path_(std::move(path)) {}

  [[noreturn]] void Fail(int64_t column, const std::string& what) const {
    throw InputError(path_, scanner_.line_number(), column, what);
  }

  // Reads all rows with `layout`. For euroc/vins the first row fixes the field count (and whether
  // there is velocity).
  Trajectory Read(Layout layout) {
    bool first_row = true;
    Trajectory trajectory;
    std::vector<Field> fields;
    while (scanner_.Next()) {
      scanner_.Split(layout.separator, &fields);
      if (first_row && IsHeaderRow(fields)) continue;  // one header row of names, before any data
      if (first_row) {
        layout = FixLayoutFromFirstRow(layout, fields.size());
        trajectory = Trajectory(Channels{layout.orientation, layout.velocity, layout.angular_velocity, true});
        trajectory.Reserve(EstimateRows());
        first_row = false;
      }
      CheckFieldCount(layout, fields);
      ParseRow(layout, fields, &trajectory);
    }
    if (first_row) {
      const std::string expected = layout.kitti || layout.format != Format::kCsv
                                       ? JoinNames(layout.names, layout.field_counts.empty() ? layout.names.size()
                                                                                          : layout.field_counts[0])
                                       : JoinNames(layout.names, layout.names.size());
      throw InputError(path_, scanner_.line_number() + 1, 1,
                       fmt::format("no poses: expected at least one row of data ({})", expected));
    }
    return trajectory;
  }

 private:
  // Rows in the file, guessed from the first data line's length (only to reserve memory), with a
  // quarter more for lines shorter than the first: a guess 1 % short doubled the poses' memory at
  // the last rows and copied all of them (room reserved and never written costs no pages).
  Eigen::Index EstimateRows() const {
    return static_cast<Eigen::Index>(content_size_ / (scanner_.line().size() + 1) * 5 / 4 + 1);
  }

  Layout FixLayoutFromFirstRow(Layout layout, size_t count) {
    if (layout.format == Format::kEuroc && !layout.kitti && layout.field_counts.empty()) {
      if (count == 8 || count >= 11) {
        layout = NanosecondCsvLayout(Format::kEuroc, count >= 11);
        layout.field_counts = {count};
        // cheval does not use the biases (bw, ba) or what follows them, but a non-number there
        // means a broken file, which skipping them would hide (evo converts every column to float
        // and rejects it too).
        layout.numbers_after_roles = true;
      } else {
        Fail(scanner_.end_column(),
             fmt::format("expected 8 fields (t_ns px py pz qw qx qy qz) or at least 11 (... vx vy vz), got {}", count));
      }
    } else if (layout.format == Format::kTumV && layout.field_counts.size() == 1 && count == 14) {
      layout = TumLayout(true, true);
    } else if (layout.format == Format::kVins && layout.field_counts.empty()) {
      if (count == 8 || count == 11) {
        layout = NanosecondCsvLayout(Format::kVins, count == 11);
        layout.field_counts = {count};
      } else {
        Fail(scanner_.end_column(),
             fmt::format("expected 8 fields (t_ns px py pz qw qx qy qz) or 11 (... vx vy vz), got {}", count));
      }
    }
    return layout;
  }

  void CheckFieldCount(const Layout& layout, const std::vector<Field>& fields) const {
    const size_t count = fields.size();
    bool ok = false;
    if (layout.field_counts.empty()) {
      ok = count >= layout.roles.size();
    } else {
      for (size_t c : layout.field_counts) ok = ok || c == count;
    }
    if (ok) return;
    const size_t expected = layout.field_counts.empty() ? layout.roles.size() : layout.field_counts.front();
    std::string what = layout.field_counts.empty()
                           ? fmt::format("expected at least {} fields ({}), got {}", expected,
                                         JoinNames(layout.names, expected), count)
                           : fmt::format("expected {} fields ({}), got {}", expected,
                                         JoinNames(layout.names, expected), count);
    if (!scanner_.has_newline() && count < expected) {
      what = "truncated last line (no newline at end of file): " + what;
    }
    const int64_t column = count > expected ? fields[expected].column : scanner_.end_column();
    Fail(column, what);
  }

  double Number(const Layout& layout, const std::vector<Field>& fields, size_t index) const {
    const Field& field = fields[index];
    if (field.text.empty()) Fail(field.column, fmt::format("{} is empty; expected a number", FieldName(layout, index)));
    const std::optional<double> value = ParseDouble(field.text);
    if (!value) {
      Fail(field.column, fmt::format("expected a number for {}, got {}", FieldName(layout, index), QuoteField(field.text)));
    }
    if (!std::isfinite(*value)) {
      // Either spelt as such ("inf", "nan", ...) or a decimal beyond the range of a double.
      const size_t first = field.text.find_first_not_of("+-");
      const bool spelt = first != std::string_view::npos && std::isalpha(static_cast<unsigned char>(field.text[first]));
      Fail(field.column, NotFiniteMessage(FieldName(layout, index), QuoteField(field.text), !spelt));
    }
    return *value;
  }

  int64_t Stamp(const Layout& layout, const std::vector<Field>& fields, size_t index, ColumnRole role) const {
    const Field& field = fields[index];
    int scale = 9;
    const char* unit = "seconds";
    switch (role) {
      case ColumnRole::kTimeMilliseconds: scale = 6, unit = "milliseconds"; break;
      case ColumnRole::kTimeMicroseconds: scale = 3, unit = "microseconds"; break;
      case ColumnRole::kTimeNanoseconds: scale = 0, unit = "nanoseconds"; break;
      default: break;
    }
    const bool integer = role == ColumnRole::kTimeNanoseconds;
    const StampParseResult r = ParseDecimalStamp(field.text, scale, integer);
    if (!r.error) return r.value;
    switch (*r.error) {
      case StampParseError::kNotANumber:
        Fail(field.column, fmt::format("expected a time stamp in {} for {}, got {}", unit,
                                       FieldName(layout, index), QuoteField(field.text)));
      case StampParseError::kOutOfRange:
        Fail(field.column, StampOutOfRangeMessage(QuoteField(field.text), FieldName(layout, index)));
      case StampParseError::kNotAnInteger:
        Fail(field.column, fmt::format("expected an integer number of nanoseconds for {}, got {}",
                                       FieldName(layout, index), QuoteField(field.text)));
    }
    Fail(field.column, "bad time stamp");
  }

  void ParseRow(const Layout& layout, const std::vector<Field>& fields, Trajectory* trajectory) {
    if (layout.kitti) return ParseKittiRow(layout, fields, trajectory);
    int64_t stamp = 0;
    double p[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, euler[3] = {0, 0, 0}, v[3] = {0, 0, 0}, w[3] = {0, 0, 0};
    size_t time_field = 0;
    for (size_t i = 0; i < layout.roles.size(); ++i) {
      const ColumnRole role = layout.roles[i];
      switch (role) {
        case ColumnRole::kSkip: break;
        case ColumnRole::kTimeSeconds:
        case ColumnRole::kTimeMilliseconds:
        case ColumnRole::kTimeMicroseconds:
        case ColumnRole::kTimeNanoseconds: stamp = Stamp(layout, fields, i, role), time_field = i; break;
        case ColumnRole::kPx: p[0] = Number(layout, fields, i); break;
        case ColumnRole::kPy: p[1] = Number(layout, fields, i); break;
        case ColumnRole::kPz: p[2] = Number(layout, fields, i); break;
        case ColumnRole::kQx: q[0] = Number(layout, fields, i); break;
        case ColumnRole::kQy: q[1] = Number(layout, fields, i); break;
        case ColumnRole::kQz: q[2] = Number(layout, fields, i); break;
        case ColumnRole::kQw: q[3] = Number(layout, fields, i); break;
        case ColumnRole::kRoll: euler[0] = Number(layout, fields, i); break;
        case ColumnRole::kPitch: euler[1] = Number(layout, fields, i); break;
        case ColumnRole::kYaw: euler[2] = Number(layout, fields, i); break;
        case ColumnRole::kVx: v[0] = Number(layout, fields, i); break;
        case ColumnRole::kVy: v[1] = Number(layout, fields, i); break;
        case ColumnRole::kVz: v[2] = Number(layout, fields, i); break;
        case ColumnRole::kWx: w[0] = Number(layout, fields, i); break;
        case ColumnRole::kWy: w[1] = Number(layout, fields, i); break;
        case ColumnRole::kWz: w[2] = Number(layout, fields, i); break;
      }
    }
    if (layout.numbers_after_roles) {
      for (size_t i = layout.roles.size(); i < fields.size(); ++i) Number(layout, fields, i);
    }
    if (layout.euler) {
      const Eigen::Quaterniond rotation = QuaternionFromRollPitchYaw(euler[0], euler[1], euler[2]);
      q[0] = rotation.x(), q[1] = rotation.y(), q[2] = rotation.z(), q[3] = rotation.w();
    } else if (layout.orientation == OrientationKind::kQuaternion) {
      if (auto problem = QuaternionProblem(q[0], q[1], q[2], q[3], QuaternionNames(layout))) {
        Fail(fields[layout.first_quaternion_field].column, *problem);
      }
    }
    if (auto problem = span_.Add(stamp, scanner_.line_number(), "line")) Fail(fields[time_field].column, *problem);
    trajectory->Append(stamp, p, q, v, w);
  }

  static std::string QuaternionNames(const Layout& layout) {
    std::string out;
    for (size_t i = 0; i < layout.roles.size(); ++i) {
      const ColumnRole r = layout.roles[i];
      if (r == ColumnRole::kQx || r == ColumnRole::kQy || r == ColumnRole::kQz || r == ColumnRole::kQw) {
        if (!out.empty()) out += ' ';
        out += layout.names[i];
      }
    }
    return out;
  }

  void ParseKittiRow(const Layout& layout, const std::vector<Field>& fields, Trajectory* trajectory) {
    double m[12];
    for (size_t i = 0; i < 12; ++i) m[i] = Number(layout, fields, i);
    const double rotation[9] = {m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10]};
    const double position[3] = {m[3], m[7], m[11]};
    const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> R(rotation);
    const double det = R.determinant();
    // A rotation has determinant 1 and R·Rᵀ = I; KITTI's are off by ~1e-6. 0.1 only rejects what is
    // no rotation (a determinant alone lets shears such as [1 1e160 0; 0 1 0; 0 0 1] through).
    if (!(std::abs(det - 1.0) <= 0.1)) {
      Fail(fields[0].column,
           fmt::format("expected a rotation matrix in fields 1-3, 5-7, 9-11 (r00..r22), got determinant {:.6g}", det));
    }
    const double orthonormality = (R * R.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    if (!(orthonormality <= 0.1)) {
      Fail(fields[0].column,
           fmt::format("expected a rotation matrix in fields 1-3, 5-7, 9-11 (r00..r22), got one that is not "
                       "orthonormal (max |R*R^T - I| = {:.6g})",
                       orthonormality));
    }
    trajectory->Append(trajectory->size() * kNanosecondsPerSecond, position, rotation);
  }

  LineScanner scanner_;
  uint64_t content_size_;
  std::string path_;
  StampSpan span_;
};

bool IsIntegerNanoseconds(std::string_view text) {
  if (text.size() < 13) return false;  // fewer digits cannot be ns since the epoch (1e12 ns = 1000 s)
  for (char c : text) {
    if (c < '0' || c > '9') return false;
  }
  return true;
}

// Where a header row disagrees with TUM's columns (t x y z qx qy qz qw, then vx vy vz for tumv):
// its first name must start with 't' (t, ts, time, timestamp) and each later one end in the axis of
// its column (x, px, tx, qx, q_x, "qx", ...). Returns the index of the first name that does not, or
// nullopt. A header says the file has its own layout: an IMU log `t gyro_x gyro_y gyro_z acc_x acc_y
// acc_z thrust` or a w-first `t x y z qw qx qy qz` also has 8 columns, and reading them as TUM
// would give wrong rotations without a word, so detection assumes TUM only when the names agree.
std::optional<size_t> FirstNameNotInTumOrder(const std::vector<Field>& header) {
  constexpr std::string_view kAxes = "txyzxyzwxyzxyz";  // the letter each column's name must show
  for (size_t i = 0; i < header.size(); ++i) {
    std::string_view name = header[i].text;
    while (!name.empty() && (name.front() == '"' || name.front() == '\'')) name.remove_prefix(1);
    while (!name.empty() && (name.back() == '"' || name.back() == '\'')) name.remove_suffix(1);
    if (i >= kAxes.size() || name.empty()) return i;
    const auto letter = static_cast<unsigned char>(i == 0 ? name.front() : name.back());
    if (std::tolower(letter) != kAxes[i]) return i;
  }
  return std::nullopt;
}

// The format of the text `scanner` walks, from its lines up to the first row of data.
Format DetectFormatOfLines(const std::string& path, LineScanner& scanner) {
  std::vector<Field> fields;
  bool header = false;
  std::string header_text;  // a copy: a streamed line's view ends at the next line
  char header_separator = ' ';
  int64_t header_line = 0;
  while (scanner.Next()) {
    const char separator = scanner.line().find(',') != std::string_view::npos ? ',' : ' ';
    scanner.Split(separator, &fields);
    if (!header && IsHeaderRow(fields)) {
      header = true;
      header_text = scanner.line();
      header_separator = separator;
      header_line = scanner.line_number();
      continue;
    }
    const size_t count = fields.size();
    std::string comment(scanner.first_comment());
    std::transform(comment.begin(), comment.end(), comment.begin(), [](unsigned char c) { return std::tolower(c); });
    if (separator == ',') {
      // EuRoC: a '#' header naming the time column first (`#timestamp`, `#time(ns)`) or EuRoC's p_RS_R.
      if (comment.rfind("#time", 0) == 0 || comment.find("p_rs_r") != std::string::npos) return Format::kEuroc;
      if (!header && IsIntegerNanoseconds(fields[0].text) && (count == 8 || count == 11)) return Format::kVins;
      throw InputError(path, scanner.line_number(), 1,
                       fmt::format("cannot detect the format: {} comma-separated fields{}; EuRoC needs a "
                                   "'#timestamp' or '#time' header, VINS integer nanosecond stamps and 8 or 11 fields. "
                                   "Use ReadOptions::format csv ReadOptions::columns ... (e.g. t_ns,px,py,pz,qw,qx,qy,qz)",
                                   count, header ? " after a header row" : ""));
    }
    if (count == 8 || count == 11 || count == 14) {
      const Format format = count == 8 ? Format::kTum : Format::kTumV;
      if (!header) return format;
      std::vector<Field> header_fields;
      LineScanner header_row(header_text);
      header_row.Next();
      header_row.Split(header_separator, &header_fields);
      // The tum/tumv readers skip a header row, so detection accepts one that names TUM's columns.
      const std::optional<size_t> wrong = FirstNameNotInTumOrder(header_fields);
      if (!wrong && header_fields.size() == count) return format;
      const std::string columns = count == 8    ? "t x y z qx qy qz qw"
                                  : count == 11 ? "t x y z qx qy qz qw vx vy vz"
                                                : "t x y z qx qy qz qw vx vy vz wx wy wz";
      const std::string axes = count == 8 ? "x y z x y z w" : count == 11 ? "x y z x y z w x y z" : "x y z x y z w x y z x y z";
      const bool named = wrong && *wrong < count;
      throw InputError(path, header_line, named ? header_fields[*wrong].column : 1,
                       fmt::format("cannot detect the format: {} space-separated fields after a header row that does "
                                   "not name {}'s columns ({}: a time first, then names ending in {}); {}. Use "
                                   "ReadOptions::format {} if the columns are in that order, else ReadOptions::format csv "
                                   "ReadOptions::columns ...",
                                   count, ToString(format), columns, axes,
                                   named ? fmt::format("its field {} is {}", *wrong + 1, QuoteField(header_fields[*wrong].text))
                                         : fmt::format("it has {} names", header_fields.size()),
                                   ToString(format)));
    }
    if (count == 12) {
      if (!header) return Format::kKitti;
      throw InputError(path, scanner.line_number(), 1,
                       "cannot detect the format: 12 space-separated fields after a header row; KITTI files have no "
                       "header. Use ReadOptions::format kitti if this is one, else ReadOptions::format csv "
                       "ReadOptions::columns ...");
    }
    throw InputError(path, scanner.line_number(), 1,
                     fmt::format("cannot detect the format: {} space-separated fields{}; expected 8 (tum: t x y z qx "
                                 "qy qz qw), 11 (tumv: ... vx vy vz), 12 (kitti) or 14 (tumv: ... vx vy vz wx wy wz). Use "
                                 "ReadOptions::format csv ReadOptions::columns ...",
                                 count, header ? " after a header row" : ""));
  }
  throw InputError(path, scanner.line_number() + 1, 1,
                   "no poses: expected at least one row of data (the file is empty or only comments)");
}

}  // namespace

Format DetectFormat(const std::string& path, std::string_view content) {
  LineScanner scanner(content);
  return DetectFormatOfLines(path, scanner);
}

namespace {

// Reads a trajectory from the lines `scan(keep)` walks from the start of the text: a look at the
// first data line where the format is detected or the separator probed (`keep`: those lines are
// read again), then the rows. `size` is the text's size where known (else 0).
template <typename Scan>
Trajectory ParseLines(Scan scan, uint64_t size, const std::string& path, const ReadOptions& options,
                      Format* format_read) {
  Format format = options.format;
  if (format == Format::kAuto) {
    LineScanner probe = scan(true);
    format = DetectFormatOfLines(path, probe);
  }
  if (format_read != nullptr) *format_read = format;
  Layout layout;
  switch (format) {
    case Format::kTum: layout = TumLayout(false); break;
    case Format::kTumV: layout = TumLayout(true); break;
    case Format::kEuroc: layout = NanosecondCsvLayout(Format::kEuroc, false); layout.field_counts.clear(); break;
    case Format::kVins: layout = NanosecondCsvLayout(Format::kVins, false); layout.field_counts.clear(); break;
    case Format::kKitti: layout = KittiLayout(); break;
    case Format::kCsv: {
      if (!options.columns) throw UsageError(
            "ReadOptions::format csv needs ReadOptions::columns (e.g. ReadOptions::columns t,px,py,pz,qx,qy,qz,qw)");
      // The separator is the file's: commas if its first data line has one, else whitespace.
      LineScanner probe = scan(true);
      const char separator = probe.Next() && probe.line().find(',') != std::string_view::npos ? ',' : ' ';
      layout = MakeLayout(*options.columns, separator, Format::kCsv);
      break;
    }
    case Format::kAuto: break;
  }
  Reader reader(scan(false), size, path);
  Trajectory trajectory = reader.Read(layout);
  if (format == Format::kKitti) {
    if (options.kitti_times_path.empty()) {
      trajectory.SetHasStamps(false);
    } else {
      std::vector<int64_t> stamps = ReadStampsFile(options.kitti_times_path);
      if (static_cast<Eigen::Index>(stamps.size()) != trajectory.size()) {
        throw InputError(options.kitti_times_path, 0, 0,
                         fmt::format("has {} stamps but the KITTI poses file {} has {} poses; expected one stamp "
                                     "per pose",
                                     stamps.size(), path, trajectory.size()));
      }
      trajectory.SetStamps(std::move(stamps));
    }
  }
  return trajectory;
}

}  // namespace

Trajectory ParseTrajectory(std::string_view content, const std::string& path, const ReadOptions& options,
                           Format* format_read) {
  return ParseLines([content](bool) { return LineScanner(content); }, content.size(), path, options, format_read);
}

uint64_t MaxInputFileBytes() {
  static const uint64_t limit = [] {
    const long pages = sysconf(_SC_PHYS_PAGES);
    const long page_size = sysconf(_SC_PAGE_SIZE);
    if (pages <= 0 || page_size <= 0) return kMaxInputFileBytes;
    return std::min(kMaxInputFileBytes, static_cast<uint64_t>(pages) * static_cast<uint64_t>(page_size) / 2);
  }();
  return limit;
}

namespace {

std::vector<int64_t> ParseStamps(LineScanner scanner, const std::string& path) {
  std::vector<Field> fields;
  std::vector<int64_t> stamps;
  StampSpan span;
  while (scanner.Next()) {
    scanner.Split(' ', &fields);
    if (fields.size() != 1) {
      throw InputError(path, scanner.line_number(), fields.size() > 1 ? fields[1].column : 1,
                       fmt::format("expected 1 field (t, seconds), got {}", fields.size()));
    }
    const StampParseResult r = ParseDecimalStamp(fields[0].text, 9);
    if (r.error) {
      throw InputError(path, scanner.line_number(), fields[0].column,
                       fmt::format("expected a time stamp in seconds, got {}", QuoteField(fields[0].text)));
    }
    if (auto problem = span.Add(r.value, scanner.line_number(), "line")) {
      throw InputError(path, scanner.line_number(), fields[0].column, *problem);
    }
    stamps.push_back(r.value);
  }
  if (stamps.empty()) {
    throw InputError(path, scanner.line_number() + 1, 1, "no stamps: expected one time stamp (seconds) per line");
  }
  return stamps;
}


// `read()`, with std::bad_alloc reported as the InputError it is.
template <typename Read>
auto WithinMemory(const std::string& path, Read read) -> decltype(read()) {
  try {
    return read();
  } catch (const std::bad_alloc&) {
    // The file fits the size limit but not the memory left (other processes, a cgroup limit): an
    // input problem to report with the file and its size, never an internal error.
    std::error_code error;
    const uintmax_t size = std::filesystem::file_size(path, error);
    throw InputError(path, 0, 0,
                     fmt::format("not enough memory to read {}: its poses need up to about twice its size; "
                                 "expected a smaller file or more free memory",
                                 error ? std::string("it") : "the file of " + Bytes(size)));
  }
}

}  // namespace

Trajectory ReadTrajectory(const std::string& path, const ReadOptions& options, Format* format_read) {
  return WithinMemory(path, [&] {
    if (std::optional<Trajectory> recorded = bag::ReadIfRecording(path, options.topic, options.record_time)) {
      if (format_read != nullptr) *format_read = Format::kAuto;
      return std::move(*recorded);
    }
    BlockReader file(path);
    std::string buffer;  // the lines not read yet, about one block
    return ParseLines([&](bool keep) { return LineScanner(&file, &buffer, keep); }, file.size(), path, options,
                      format_read);
  });
}

std::vector<int64_t> ReadStampsFile(const std::string& path) {
  return WithinMemory(path, [&] {
    BlockReader file(path);
    std::string buffer;
    return ParseStamps(LineScanner(&file, &buffer, false), path);
  });
}


}  // namespace cheval::traj

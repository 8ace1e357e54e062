#include "cheval/common/input_file.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <vector>

#include <fmt/format.h>

#include "cheval/common/error.h"

namespace cheval {

std::string ReadInputFile(const std::string& path, uint64_t max_bytes, std::string_view what) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) {
    throw InputError(path, 0, 0, fmt::format("is a directory; expected {}", what));
  }
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (file == nullptr) throw InputError(path, 0, 0, fmt::format("cannot open file: {}", std::strerror(errno)));
  const auto too_large = [&](uint64_t size) {
    return InputError(path, 0, 0,
                      fmt::format("is too large: {} bytes or more, above the limit of {} bytes for {}", size,
                                  max_bytes, what));
  };
  if (std::filesystem::is_regular_file(path, error)) {
    const uint64_t size = std::filesystem::file_size(path, error);
    if (!error && size > max_bytes) throw too_large(size);
  }
  // Read in chunks whatever the size said (a pipe, a file that grew), never beyond the limit.
  std::string content;
  std::vector<char> chunk(1 << 16);
  while (const size_t n = std::fread(chunk.data(), 1, chunk.size(), file.get())) {
    if (content.size() + n > max_bytes) throw too_large(content.size() + n);
    content.append(chunk.data(), n);
  }
  if (std::ferror(file.get())) throw InputError(path, 0, 0, fmt::format("cannot read file: {}", std::strerror(errno)));
  return content;
}

namespace {

// Where the parser is: one frame per open object (its current key) or array (its current index).
struct JsonPath {
  struct Frame {
    bool array = false;
    std::string key;
    size_t index = 0;
  };
  std::vector<Frame> frames;

  std::string ToString() const {
    std::string out;
    for (const Frame& frame : frames) {
      if (frame.array) {
        out += fmt::format("[{}]", frame.index);
      } else if (!frame.key.empty()) {
        out += (out.empty() ? "" : ".") + frame.key;
      }
    }
    return out.empty() ? "(top level)" : out;
  }

  void ValueDone() {
    if (!frames.empty() && frames.back().array) ++frames.back().index;
  }
};

}  // namespace

nlohmann::json ParseJsonInput(std::string_view text, const std::string& path, std::string_view what) {
  using Json = nlohmann::json;
  JsonPath where;
  const Json::parser_callback_t track = [&where](int /*depth*/, Json::parse_event_t event, Json& parsed) {
    switch (event) {
      case Json::parse_event_t::object_start:
        where.frames.push_back({false, "", 0});
        break;
      case Json::parse_event_t::array_start:
        where.frames.push_back({true, "", 0});
        break;
      case Json::parse_event_t::key:
        if (!where.frames.empty() && parsed.is_string()) where.frames.back().key = parsed.get<std::string>();
        break;
      case Json::parse_event_t::object_end:
      case Json::parse_event_t::array_end:
        if (!where.frames.empty()) where.frames.pop_back();
        where.ValueDone();
        break;
      case Json::parse_event_t::value:
        where.ValueDone();
        break;
    }
    return true;
  };
  try {
    return Json::parse(text.begin(), text.end(), track);
  } catch (const Json::parse_error& e) {
    // nlohmann's message: "[json.exception.parse_error.101] parse error at line L, column C: WHAT".
    const std::string message = e.what();
    long line = 0, column = 0;
    const size_t at = message.find(" at line ");
    if (at != std::string::npos) std::sscanf(message.c_str() + at, " at line %ld, column %ld", &line, &column);
    const size_t colon = message.find(": ", at == std::string::npos ? 0 : at);
    throw InputError(path, line, column,
                     fmt::format("expected JSON ({}): {}", what,
                                 colon == std::string::npos ? message : message.substr(colon + 2)));
  } catch (const Json::out_of_range& e) {
    // "[json.exception.out_of_range.406] number overflow parsing '1e400'": no position, but the key.
    const std::string message = e.what();
    const size_t quote = message.find('\'');
    const std::string number = quote == std::string::npos ? std::string("a number") : message.substr(quote);
    throw InputError(path, 0, 0,
                     fmt::format("{}: the number {} is too large for a double (at most 1.8e308 in magnitude)",
                                 where.ToString(), number.size() > 42 ? number.substr(0, 39) + "..." : number));
  } catch (const Json::exception& e) {
    const std::string message = e.what();
    const size_t bracket = message.find("] ");
    throw InputError(path, 0, 0,
                     fmt::format("expected JSON ({}): {}", what,
                                 bracket == std::string::npos ? message : message.substr(bracket + 2)));
  }
}

}  // namespace cheval

#include "cheval/common/option_names.h"

namespace cheval {
namespace {

bool IsIdentifier(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
}

}  // namespace

std::string SpellOptions(std::string_view text, std::span<const OptionName> names) {
  std::string out;
  out.reserve(text.size());
  size_t copied = 0;  // text[0, copied) is in `out`
  for (size_t colons = text.find("::"); colons != std::string_view::npos; colons = text.find("::", colons + 2)) {
    size_t begin = colons, end = colons + 2;
    while (begin > copied && IsIdentifier(text[begin - 1])) --begin;
    while (end < text.size() && IsIdentifier(text[end])) ++end;
    const std::string_view token = text.substr(begin, end - begin);
    for (const OptionName& name : names) {
      if (name.field != token) continue;
      out.append(text.substr(copied, begin - copied));
      out.append(name.name);
      copied = end;
      break;
    }
  }
  out.append(text.substr(copied));
  return out;
}

}  // namespace cheval

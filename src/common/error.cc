#include "cheval/common/error.h"

#include <fmt/format.h>

namespace cheval {

InputError::InputError(std::string path, int64_t line, int64_t column, const std::string& what)
    : Error(fmt::format("{}:{}:{}: error: {}", path, line, column, what)),
      path_(std::move(path)),
      line_(line),
      column_(column),
      detail_(what) {}

OptionError::OptionError(std::string options, std::string field, std::string rule)
    : UsageError(fmt::format("{}::{} {}", options, field, rule)),
      options_(std::move(options)),
      field_(std::move(field)),
      rule_(std::move(rule)) {}

}  // namespace cheval

// Expects a call to throw cheval::OptionError naming one options field, as the faces translate it.

#pragma once

#include <string>

#include <gtest/gtest.h>

#include "cheval/common/error.h"

namespace cheval::testing {

// Expects `call` to throw OptionError for OPTIONS::FIELD, its what() being "OPTIONS::FIELD RULE".
template <typename Call>
void ExpectOptionError(const Call& call, const std::string& options, const std::string& field) {
  try {
    call();
    ADD_FAILURE() << "expected OptionError on " << options << "::" << field;
  } catch (const OptionError& e) {
    EXPECT_EQ(e.options(), options) << e.what();
    EXPECT_EQ(e.field(), field) << e.what();
    EXPECT_EQ(std::string(e.what()), options + "::" + field + " " + e.rule());
  }
}

}  // namespace cheval::testing

// The report page's files in a build without the chart library (CMake option
// CHEVAL_BUILD_REPORT=OFF, the default when npm is not found): none; `cheval report` says so.
#include "assets.h"

namespace cheval::report::detail {

std::optional<PageAssets> EmbeddedPageAssets() { return std::nullopt; }

}  // namespace cheval::report::detail

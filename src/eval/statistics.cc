#include "cheval/eval/statistics.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace cheval::eval {

ErrorStatistics ComputeStatistics(std::span<const double> errors) {
  ErrorStatistics s;
  if (errors.empty()) return s;
  const size_t n = errors.size();
  s.n = static_cast<Eigen::Index>(n);
  s.min = s.max = errors[0];
  double sum = 0;
  for (double e : errors) {
    sum += e;
    s.sse += e * e;
    s.min = std::min(s.min, e);
    s.max = std::max(s.max, e);
  }
  s.mean = sum / static_cast<double>(n);
  s.rmse = std::sqrt(s.sse / static_cast<double>(n));
  double squares = 0;  // numpy.std: the mean of the squared deviations from the mean (ddof 0)
  for (double e : errors) squares += (e - s.mean) * (e - s.mean);
  s.std = std::sqrt(squares / static_cast<double>(n));
  // numpy.median: the middle value, or the mean of the two middle values; O(n) by selection.
  std::vector<double> copy(errors.begin(), errors.end());
  const auto middle = copy.begin() + static_cast<std::ptrdiff_t>(n / 2);
  std::nth_element(copy.begin(), middle, copy.end());
  s.median = n % 2 == 1 ? *middle : 0.5 * (*std::max_element(copy.begin(), middle) + *middle);
  return s;
}

}  // namespace cheval::eval

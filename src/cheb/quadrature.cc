#include "cheval/cheb/quadrature.h"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <utility>

namespace cheval::cheb {
namespace {

// P_n(z) and P_n'(z) by the three-term recurrence k P_k = (2k − 1) z P_{k−1} − (k − 1) P_{k−2}.
std::pair<double, double> Legendre(int n, double z) {
  if (n == 0) return {1.0, 0.0};
  double previous = 1.0, value = z;
  for (int k = 2; k <= n; ++k) {
    const double next = ((2.0 * k - 1.0) * z * value - (k - 1.0) * previous) / k;
    previous = value;
    value = next;
  }
  return {value, n * (z * value - previous) / (z * z - 1.0)};
}

}  // namespace

QuadratureRule GaussLegendre(int n) {
  if (n < 1) throw std::invalid_argument("GaussLegendre needs n >= 1");
  QuadratureRule rule;
  rule.nodes.resize(n);
  rule.weights.resize(n);
  for (int i = 0; i < n; ++i) {
    double z = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5));
    for (int iteration = 0; iteration < 100; ++iteration) {
      const auto [p, dp] = Legendre(n, z);
      z -= p / dp;
      if (std::abs(p / dp) < 1e-16) break;
    }
    const double dp = Legendre(n, z).second;
    rule.nodes[i] = z;
    rule.weights[i] = 2.0 / ((1.0 - z * z) * dp * dp);
  }
  return rule;
}

}  // namespace cheval::cheb

#include "cheval/cheb/quadrature.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace cheval::cheb {
namespace {

// Gauss–Legendre with n points integrates every monomial of degree <= 2n − 1 exactly on [-1, 1]
// (∫ x^k = 2/(k+1) for even k, 0 for odd): to rounding, 1e-14 on these O(1) sums.
TEST(GaussLegendre, IsExactToDegreeTwoNMinusOne) {
  for (int n = 1; n <= 12; ++n) {
    const QuadratureRule rule = GaussLegendre(n);
    const Eigen::VectorXd& x = rule.nodes;
    const Eigen::VectorXd& w = rule.weights;
    for (int k = 0; k <= 2 * n - 1; ++k) {
      double sum = 0;
      for (int q = 0; q < n; ++q) sum += w[q] * std::pow(x[q], k);
      EXPECT_NEAR(sum, k % 2 == 0 ? 2.0 / (k + 1) : 0.0, 1e-14) << "n " << n << " k " << k;
    }
    // Degree 2n is not integrated exactly (the rule has exactly 2n − 1 degrees of exactness): the
    // error there is still 1.8e-7 at n = 12, far above rounding.
    double sum = 0;
    for (int q = 0; q < n; ++q) sum += w[q] * std::pow(x[q], 2 * n);
    EXPECT_GT(std::abs(sum - 2.0 / (2 * n + 1)), 1e-12) << n;
  }
}

TEST(GaussLegendre, RejectsNoPoints) { EXPECT_THROW(GaussLegendre(0), std::invalid_argument); }

}  // namespace
}  // namespace cheval::cheb

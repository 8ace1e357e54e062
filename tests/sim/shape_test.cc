// Each kind's Shape (src/sim/internal/shape.h): the jets it returns carry the derivatives of its own
// values (checked against central differences), and its two Integrand overloads agree.
#include "internal/shape.h"

#include <gtest/gtest.h>

#include <cmath>

namespace cheval::sim::internal {
namespace {

// Fourth-order central difference with h = 1 ms. Truncation h⁴|f⁽⁵⁾|/30 ≤ 2e-10 (the fastest term,
// 2 cm of handheld bounce or 0.02 rad of pitch at 12.6 rad/s, has |f⁽⁵⁾| ≈ 6e3) and rounding
// ~1.5ε|f|/h ≤ 1e-11 (|f| ≤ 30 m), so the 3e-9 bound below has a margin of 10.
constexpr double kStep = 1e-3;

template <class F>
double CentralDifference(const F& f, double t) {
  return ((f(t - 2 * kStep) - f(t + 2 * kStep)) + 8.0 * (f(t + kStep) - f(t - kStep))) / (12.0 * kStep);
}

class EveryShape : public ::testing::TestWithParam<MotionKind> {};

TEST_P(EveryShape, JetDerivativesAreTheDerivativesOfTheValues) {
  for (const uint64_t seed : {1ULL, 2ULL, 3ULL}) {
    const auto shape = MakeShape(GetParam(), seed);
    for (const double t : {-1.3, 0.0, 0.4, 2.75, 11.1, 37.9}) {
      const Vec3<Jet> q = shape->Offset(Jet::Variable(t));
      const Vec3<Jet> u = shape->Integrand(Jet::Variable(t));
      const Mat3<Jet> R = shape->Attitude(q, Jet::Variable(t));
      for (int i = 0; i < 3; ++i) {
        auto offset = [&](double s) { return shape->Offset(Jet::Variable(s))[i].c[0]; };
        EXPECT_NEAR(q[i].c[1], CentralDifference(offset, t), 3e-9) << "q'" << i << " at " << t;
        // The integrand as a number is the jet's value, and the jet's derivative is its derivative.
        EXPECT_EQ(shape->Integrand(t)[i], u[i].c[0]) << i << " at " << t;
        auto integrand = [&](double s) { return shape->Integrand(s)[i]; };
        EXPECT_NEAR(u[i].c[1], CentralDifference(integrand, t), 3e-9) << "u'" << i << " at " << t;
        for (int j = 0; j < 3; ++j) {
          auto rotation = [&](double s) {
            const Vec3<Jet> qs = shape->Offset(Jet::Variable(s));
            return shape->Attitude(qs, Jet::Variable(s))[i][j].c[0];
          };
          EXPECT_NEAR(R[i][j].c[1], CentralDifference(rotation, t), 3e-9) << "R'" << i << j << " at " << t;
        }
      }
    }
  }
}

TEST_P(EveryShape, OnlyTheDroneHasNoIntegralPart) {
  const auto shape = MakeShape(GetParam(), 1);
  EXPECT_EQ(shape->integrated(), GetParam() != MotionKind::kDrone);
}

INSTANTIATE_TEST_SUITE_P(Shapes, EveryShape,
                         ::testing::Values(MotionKind::kCar, MotionKind::kLegged, MotionKind::kDrone,
                                           MotionKind::kHandheld),
                         [](const auto& param_info) { return std::string(ToString(param_info.param)); });

}  // namespace
}  // namespace cheval::sim::internal

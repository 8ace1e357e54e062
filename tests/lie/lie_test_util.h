// Helpers shared by the Lie-group tests (lie_group_test.cc, lie_jacobian_test.cc, lie_jet_test.cc):
// seeded random draws, the tangent sample list, pairs of samples, elements with a given rotation,
// the typed-test group list and its name printer, Compose and Between as callables, manifold
// perturbation and a relative Jacobian comparison. Each test file keeps its own seed and
// tolerances.

#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "cheval/lie/se23.h"
#include "cheval/lie/se3.h"
#include "cheval/lie/sim3.h"
#include "cheval/lie/so3.h"

namespace cheval::lie::testing {

// π as a double.
inline constexpr double kPi = std::numbers::pi;

// How many seeded random elements or tangents a sample list holds after its fixed cases.
inline constexpr int kRandomSamples = 100;

// The groups every typed Lie test runs on.
using Groups = ::testing::Types<SO3d, SE3d, Sim3d, SE23d>;

// Names typed-test instances by the group (SO3, SE3, ...) instead of an index.
struct GroupName {
  template <typename G>
  static std::string GetName(int) {
    return std::string(G::kName);
  }
};

// A named test case: the name goes to SCOPED_TRACE.
template <typename T>
struct Sample {
  std::string name;
  T value;
};

// A uniform draw in [lo, hi).
inline double Uniform(std::mt19937& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

// A 3-vector with each component uniform in ±extent.
inline Eigen::Vector3d RandomVector(std::mt19937& rng, double extent) {
  return Eigen::Vector3d(Uniform(rng, -extent, extent), Uniform(rng, -extent, extent),
                         Uniform(rng, -extent, extent));
}

// A unit 3-vector uniform on the sphere (normalised Gaussian).
inline Eigen::Vector3d RandomUnitVector(std::mt19937& rng) {
  std::normal_distribution<double> normal;
  return Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
}

// A tangent with rotation angle `angle` about a random axis and other components in ±extent.
template <typename G>
typename G::Tangent TangentWithAngle(double angle, double extent, std::mt19937& rng) {
  typename G::Tangent tau;
  tau.template head<3>() = angle * RandomUnitVector(rng);
  for (int i = 3; i < G::kDoF; ++i) tau[i] = Uniform(rng, -extent, extent);
  return tau;
}

// The default last step of MakeTangentSamples: leaves each random tangent as drawn.
struct KeepTangent {
  template <typename T>
  void operator()(T&, std::mt19937&) const {}
};

// Tangents from a generator seeded with `seed`: zero, tiny, tiny rotation, π − 1e-6, random.
// Each non-zero one is draw(angle, extent, rng) with extent 1e-8 ("tiny") or 2; each random one
// (angle uniform in [0, π − 1e-6)) then goes through finish(tau, rng).
template <typename G, typename Draw, typename Finish = KeepTangent>
std::vector<Sample<typename G::Tangent>> MakeTangentSamples(unsigned seed, const Draw& draw,
                                                            const Finish& finish = {}) {
  std::mt19937 rng(seed);
  std::vector<Sample<typename G::Tangent>> s;
  s.push_back({"zero", G::Tangent::Zero()});
  s.push_back({"tiny", draw(1e-8, 1e-8, rng)});
  s.push_back({"tiny rotation", draw(1e-8, 2.0, rng)});
  s.push_back({"pi - 1e-6", draw(kPi - 1e-6, 2.0, rng)});
  for (int i = 0; i < kRandomSamples; ++i) {
    typename G::Tangent tau = draw(Uniform(rng, 0.0, kPi - 1e-6), 2.0, rng);
    finish(tau, rng);
    s.push_back({"random " + std::to_string(i), tau});
  }
  return s;
}

// Calls f(g, h) for each sample g of s and the sample `offset` places after it (cyclically), under
// a SCOPED_TRACE of g's name.
template <typename S, typename F>
void ForEachPair(const std::vector<S>& s, std::size_t offset, const F& f) {
  for (std::size_t i = 0; i < s.size(); ++i) {
    SCOPED_TRACE(s[i].name);
    f(s[i].value, s[(i + offset) % s.size()].value);
  }
}

// Compose and Between as callables op(a, b, J_a*, J_b*), for tests of both Jacobians.
inline constexpr auto kCompose = [](const auto& a, const auto& b, auto j_a, auto j_b) {
  return a.Compose(b, j_a, j_b);
};
inline constexpr auto kBetween = [](const auto& a, const auto& b, auto j_a, auto j_b) {
  return a.Between(b, j_a, j_b);
};

// An element of G with rotation r and its other parts random of size `extent` (log-scale ≤ 1).
template <typename G>
G WithRotation(const SO3d& r, double extent, std::mt19937& rng);
template <>
inline SO3d WithRotation<SO3d>(const SO3d& r, double, std::mt19937&) {
  return r;
}
template <>
inline SE3d WithRotation<SE3d>(const SO3d& r, double extent, std::mt19937& rng) {
  return SE3d(r, RandomVector(rng, extent));
}
template <>
inline Sim3d WithRotation<Sim3d>(const SO3d& r, double extent, std::mt19937& rng) {
  const double log_scale = std::min(extent, 1.0);
  return Sim3d(r, RandomVector(rng, extent), std::exp(Uniform(rng, -log_scale, log_scale)));
}
template <>
inline SE23d WithRotation<SE23d>(const SO3d& r, double extent, std::mt19937& rng) {
  return SE23d(r, RandomVector(rng, extent), RandomVector(rng, extent));
}

// True for the group types (they have Log and Inverse), false for Eigen vectors.
template <typename T>
concept Group = requires(const T& g) {
  g.Log();
  g.Inverse();
};

// Degrees of freedom of a group, or the size of a vector.
template <typename T>
constexpr int Dim() {
  if constexpr (Group<T>) {
    return T::kDoF;
  } else {
    return T::RowsAtCompileTime;
  }
}

// x ⊕ δ for groups (right Plus), x + δ for vectors.
template <typename T, typename D>
T Perturb(const T& x, const D& d) {
  if constexpr (Group<T>) {
    return x.Plus(d);
  } else {
    return (x + d).eval();
  }
}

// a ⊖ b for groups (right Minus), a − b for vectors.
template <typename T>
auto Difference(const T& a, const T& b) {
  if constexpr (Group<T>) {
    return a.Minus(b);
  } else {
    return (a - b).eval();
  }
}

// max |analytic − reference| ≤ tol · max(1, max |reference|); on failure prints both, the
// reference under `label`.
template <typename A, typename B>
::testing::AssertionResult MaxEntryNear(const A& analytic, const B& reference, double tol,
                                        const char* label) {
  const double error = (analytic - reference).cwiseAbs().maxCoeff();
  const double scale = std::max(1.0, reference.cwiseAbs().maxCoeff());
  if (error <= tol * scale) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "max error " << error << " > " << tol << " · " << scale << "\nanalytic:\n"
         << analytic << "\n"
         << label << ":\n"
         << reference;
}

}  // namespace cheval::lie::testing

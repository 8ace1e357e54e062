#pragma once
// A check for the estimator's costs: Ceres evaluates a residual block without Jacobians to price a
// step and with them to linearise, and the costs take a cheaper path for the first (doubles instead
// of ceres::Jet). Both must give the same cost, or the solver would accept steps by a different
// function from the one it minimises.
#include <algorithm>
#include <vector>

#include <ceres/ceres.h>
#include <gtest/gtest.h>

namespace cheval::testing {

/// For every residual block of `problem`: the squared norm of its residuals evaluated without
/// Jacobians equals the one evaluated with them, to `relative` (a compressed block returns another
/// vector of the same norm when evaluated alone). Returns the number of blocks checked.
inline int ExpectResidualOnlyEvaluationMatches(const ceres::Problem& problem, double relative = 1e-13) {
  std::vector<ceres::ResidualBlockId> ids;
  problem.GetResidualBlocks(&ids);
  for (ceres::ResidualBlockId id : ids) {
    std::vector<double*> blocks;
    problem.GetParameterBlocksForResidualBlock(id, &blocks);
    const int rows = problem.GetCostFunctionForResidualBlock(id)->num_residuals();
    std::vector<std::vector<double>> storage;
    std::vector<double*> jacobians;
    for (double* b : blocks) {
      storage.emplace_back(static_cast<size_t>(rows * problem.ParameterBlockTangentSize(b)));
      jacobians.push_back(storage.back().data());
    }
    std::vector<double> alone(rows), linearised(rows);
    double cost_alone = 0, cost_linearised = 0;
    EXPECT_TRUE(problem.EvaluateResidualBlock(id, false, &cost_alone, alone.data(), nullptr));
    EXPECT_TRUE(problem.EvaluateResidualBlock(id, false, &cost_linearised, linearised.data(), jacobians.data()));
    EXPECT_NEAR(cost_alone, cost_linearised, relative * std::max(1e-300, cost_linearised));
  }
  return static_cast<int>(ids.size());
}

}  // namespace cheval::testing

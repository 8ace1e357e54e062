#pragma once
/// \file
/// The base of every cost of the pseudo-spectral problem (problem.h): a ceres::CostFunction that
/// knows its own parameter blocks, so that the problem adds any cost (a residual of the dynamics, of
/// a measurement or of a prior) the same way, PseudoSpectralProblem::AddPrior for priors.

#include <vector>

#include <ceres/cost_function.h>

namespace cheval::estim::internal {

/// A cost with its parameter blocks (pointers into the problem's node storage), in the order of
/// Evaluate's `parameters`.
class BlockCost : public ceres::CostFunction {
 public:
  const std::vector<double*>& blocks() const { return blocks_; }
  /// The residual rows this cost stands for: its own, or more for one that compresses its rows
  /// (measurement_cost.h) — what a count of degrees of freedom (a reduced χ²) must use.
  virtual int represented_rows() const { return num_residuals(); }

 protected:
  /// Appends a parameter block of `size` numbers.
  void AddBlock(double* block, int size) {
    blocks_.push_back(block);
    mutable_parameter_block_sizes()->push_back(size);
  }

 private:
  std::vector<double*> blocks_;
};

}  // namespace cheval::estim::internal

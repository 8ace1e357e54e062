// Parses a TUM line with an installed cheval and prints the exact stamp: proves headers, library
// and package config were installed and work together.
#include <cstdio>

#include "cheval/traj/io.h"
#include "cheval/traj/stamp.h"

int main() {
  const cheval::traj::Trajectory t = cheval::traj::ParseTrajectory("1403636579.758555651 1 2 3 0 0 0 1\n", "inline");
  std::printf("%s\n", cheval::traj::FormatSeconds(t.stamps_ns()[0]).c_str());
  return t.size() == 1 && t.stamps_ns()[0] == 1403636579758555651LL ? 0 : 1;
}

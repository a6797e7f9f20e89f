// Prints the closed loop of SpeedController and Plant as closed_loop_reference.hpp computes it, one
// "k,speed,drive" line per communication point: what the runner's closed-loop test through cosmicd
// (tests/integration/daemon/fmu_loop_test.sh) compares the plant's trace with.
// Usage: cosmic-fmu-loop-reference STEPS
#include <cstdio>
#include <cstdlib>

#include "closed_loop_reference.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s STEPS\n", argv[0]);
    return 64;
  }
  cosmic::test::ClosedLoopParameters parameters;
  parameters.steps = std::strtoul(argv[1], nullptr, 10);
  const auto trace = cosmic::test::closed_loop_reference(parameters);
  for (std::size_t k = 0; k < trace.speed.size(); ++k)
    std::printf("%zu,%.17g,%.17g\n", k, trace.speed[k], trace.drive[k]);
  return 0;
}

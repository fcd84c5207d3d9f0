// Memory of a simulated cloth: heap bytes per node held by the World (model, state and the
// integrator's scratch arrays) and the process's resident set, current and peak, while it steps.
//   memory_footprint [NODES (default 100000)] [INTEGRATOR (default xpbd)] [STEPS (default 20)]
// Prints one CSV line after a header:
//   integrator,n_nodes,n_springs,heap_bytes,heap_bytes_per_node,rss_mb,peak_rss_mb,finite
#include <malloc.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include "large_cloth.h"

namespace
{
/// Bytes the C allocator has handed out and not taken back (small blocks + mmapped large ones).
double heapBytes()
{
  const struct mallinfo2 info = mallinfo2();
  return static_cast<double>(info.uordblks + info.hblkhd);
}

/// A field of /proc/self/status in MB (VmRSS: resident now, VmHWM: peak resident).
double statusMegabytes(const std::string& field)
{
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind(field + ":", 0) == 0)
      return std::stod(line.substr(field.size() + 1)) / 1024.0;  // kB
  return 0.0;
}
}  // namespace

int main(int argc, char** argv)
{
  using namespace soft_body_sim;
  const int requested = argc > 1 ? std::stoi(argv[1]) : 100000;
  IntegratorType integrator = IntegratorType::Xpbd;
  if (argc > 2 && !integratorFromName(argv[2], integrator))
  {
    std::fprintf(stderr, "memory_footprint: unknown integrator '%s'\n", argv[2]);
    return 2;
  }
  const int steps = argc > 3 ? std::stoi(argv[3]) : 20;
  const int side = static_cast<int>(std::lround(std::sqrt(static_cast<double>(requested))));

  const double heap_before = heapBytes();
  // The benchmarks' cloth (large_cloth.h); the scene definition is gone once the world is built.
  World world = buildWorld(largeClothScene(side, integrator));
  for (int s = 0; s < steps; ++s)
    world.step();
  const double heap = heapBytes() - heap_before;
  const int nodes = world.model().nodeCount();
  std::printf("integrator,n_nodes,n_springs,heap_bytes,heap_bytes_per_node,rss_mb,peak_rss_mb,finite\n");
  std::printf("%s,%d,%zu,%.0f,%.1f,%.1f,%.1f,%d\n", integratorName(integrator).c_str(), nodes,
              world.model().springs.size(), heap, heap / nodes, statusMegabytes("VmRSS"), statusMegabytes("VmHWM"),
              world.state().position.allFinite() ? 1 : 0);
  return 0;
}

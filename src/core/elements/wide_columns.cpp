#include "core/elements/wide_columns.h"

namespace soft_body_sim
{
namespace
{
bool& wideLanes()
{
  static bool wide = __builtin_cpu_supports("avx2");
  return wide;
}
}  // namespace

bool hasWideLanes() { return wideLanes(); }

void useWideLanes(bool on) { wideLanes() = on && __builtin_cpu_supports("avx2"); }

}  // namespace soft_body_sim

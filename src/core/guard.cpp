#include "soft_body_sim/core/guard.h"

#include <atomic>
#include <cstdio>

namespace soft_body_sim
{
const std::vector<std::string>& guardPolicyNames()
{
  static const std::vector<std::string> names = { "halve_step", "switch_integrator", "freeze" };
  return names;
}

std::string guardPolicyName(GuardPolicy policy) { return guardPolicyNames().at(static_cast<std::size_t>(policy)); }

bool guardPolicyFromName(const std::string& name, GuardPolicy& policy)
{
  const std::vector<std::string>& names = guardPolicyNames();
  for (std::size_t k = 0; k < names.size(); ++k)
    if (names[k] == name)
    {
      policy = static_cast<GuardPolicy>(k);
      return true;
    }
  return false;
}

namespace
{
std::atomic<std::int64_t> events_in_process{ 0 };
}  // namespace

std::int64_t divergenceEventsInProcess() { return events_in_process.load(); }

void countDivergenceEventInProcess() { ++events_in_process; }

std::string DivergenceEvent::describe() const
{
  char at[32];
  std::snprintf(at, sizeof at, "%.3f", time);
  return "body '" + body + "' diverged at t = " + at + " s (" + reason + "): restored to its last good state, " +
         action;
}

}  // namespace soft_body_sim

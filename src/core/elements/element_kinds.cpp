#include "core/elements/element_kinds.h"

#include <stdexcept>

namespace soft_body_sim
{
void requireIntegratorRunsModel(const Model& model, IntegratorType integrator)
{
  std::string refused;
  forEachKind([&](auto kind) {
    if (kind.of(model).empty() || kind.runsUnder(integrator))
      return;
    std::string by;
    for (const std::string& name : integratorNames())
    {
      IntegratorType other;
      if (integratorFromName(name, other) && kind.runsUnder(other))
        by += (by.empty() ? "" : " or ") + name;
    }
    refused += std::string(refused.empty() ? "" : "; ") + kind.kName + " run only under " + by;
  });
  if (!refused.empty())
    throw std::invalid_argument(refused + ", not " + integratorName(integrator));
}

}  // namespace soft_body_sim

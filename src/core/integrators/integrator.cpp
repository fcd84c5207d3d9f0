#include "soft_body_sim/core/integrators/integrator.h"

#include <stdexcept>

#include "core/integrators/integrator_kit.h"
#include "core/names.h"

namespace soft_body_sim
{
namespace
{
struct Entry
{
  IntegratorType type;
  const char* name;
  std::unique_ptr<Integrator> (*make)();
};

// In IntegratorType's order: integratorNames() lists them so, and enumFromName maps name k to value k.
const Entry kEntries[] = {
  { IntegratorType::ExplicitEuler, "explicit_euler", makeExplicitEuler },
  { IntegratorType::SemiImplicitEuler, "semi_implicit_euler", makeSemiImplicitEuler },
  { IntegratorType::Verlet, "verlet", makeVerlet },
  { IntegratorType::VelocityVerlet, "velocity_verlet", makeVelocityVerlet },
  { IntegratorType::Rk4, "rk4", makeRk4 },
  { IntegratorType::ImplicitEuler, "implicit_euler", makeImplicitEuler },
  { IntegratorType::Xpbd, "xpbd", makeXpbd },
};

const Entry& entry(IntegratorType type)
{
  for (const Entry& e : kEntries)
    if (e.type == type)
      return e;
  throw std::logic_error("integrator type without an entry");
}
}  // namespace

std::string integratorName(IntegratorType type) { return entry(type).name; }

bool integratorFromName(const std::string& name, IntegratorType& type)
{
  return enumFromName(integratorNames(), name, type);
}

const std::vector<std::string>& integratorNames()
{
  static const std::vector<std::string> names = [] {
    std::vector<std::string> all;
    for (const Entry& e : kEntries)
      all.emplace_back(e.name);
    return all;
  }();
  return names;
}

std::unique_ptr<Integrator> makeIntegrator(IntegratorType type) { return entry(type).make(); }

void stateInternalForces(const Model& model, const State& state, InternalForces& forces)
{
  forces.tension.setZero(static_cast<Eigen::Index>(model.springs.size() + model.constraints.size()));
  for (std::size_t k = 0; k < model.springs.size(); ++k)
  {
    const Spring& s = model.springs[k];
    Vec3 u;
    double length;
    if (springAxis(state.position, s.a, s.b, u, length))
      forces.tension[static_cast<Eigen::Index>(k)] = springTension(s, u, length, state.velocity);
  }
  forces.pressure.resize(static_cast<Eigen::Index>(model.cells.size()));
  for (std::size_t k = 0; k < model.cells.size(); ++k)
    forces.pressure[static_cast<Eigen::Index>(k)] =
        cellGas(model.cells[k], cellArea(model.cells[k], state.position)).pressure;
}

}  // namespace soft_body_sim

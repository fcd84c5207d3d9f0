#include "soft_body_sim/core/material.h"

#include <cmath>
#include <stdexcept>

namespace soft_body_sim
{
MaterialScaling::MaterialScaling(const Model& built)
  : built_springs_(built.springs)
  , built_constraints_(built.constraints)
  , built_cells_(built.cells)
  , built_rods_(built.rods)
  , built_tetrahedra_(built.tetrahedra)
  , scaling_(built.bodies.size())
  , has_material_(built.bodies.size(), 0)
{
  for (const Spring& spring : built.springs)
    has_material_[built.bodyOf(spring.a)] = 1;
  for (const DistanceConstraint& constraint : built.constraints)
    has_material_[built.bodyOf(constraint.a)] = 1;
  for (const PressureCell& cell : built.cells)
    has_material_[built.bodyOf(cell.nodes[0])] = 1;
  for (const Rod& rod : built.rods)
    has_material_[built.bodyOf(rod.first)] = 1;
  for (const Tetrahedron& tet : built.tetrahedra)
    has_material_[built.bodyOf(tet.nodes[0])] = 1;
}

void MaterialScaling::set(Model& model, std::size_t body, const BodyScaling& scaling)
{
  // Stiffness and pressure divide (compliance = 1 / k, Boyle's law p0 A0 / A): they must stay > 0.
  if (!(scaling.stiffness > 0.0 && std::isfinite(scaling.stiffness)) ||
      !(scaling.pressure > 0.0 && std::isfinite(scaling.pressure)) ||
      !(scaling.damping >= 0.0 && std::isfinite(scaling.damping)))
    throw std::invalid_argument("World: body scaling: stiffness and pressure must be finite and > 0, damping >= 0");
  scaling_.at(body) = scaling;
  // From the built values, not the current ones: factors do not compound and 1 restores the scene.
  for (std::size_t k = 0; k < model.springs.size(); ++k)
    if (model.bodyOf(built_springs_[k].a) == body)
    {
      model.springs[k].stiffness = built_springs_[k].stiffness * scaling.stiffness;
      model.springs[k].damping = built_springs_[k].damping * scaling.damping;
    }
  for (std::size_t k = 0; k < model.constraints.size(); ++k)
    if (model.bodyOf(built_constraints_[k].a) == body)
      model.constraints[k].compliance = built_constraints_[k].compliance / scaling.stiffness;
  for (std::size_t k = 0; k < model.cells.size(); ++k)
    if (model.bodyOf(built_cells_[k].nodes[0]) == body)
      model.cells[k].pressure = built_cells_[k].pressure * scaling.pressure;
  // A rod's bending and twisting scale with its stretching (its E and G), its damping beta with the dashpots.
  for (std::size_t k = 0; k < model.rods.size(); ++k)
    if (model.bodyOf(built_rods_[k].first) == body)
    {
      model.rods[k].bending_stiffness = built_rods_[k].bending_stiffness * scaling.stiffness;
      model.rods[k].twisting_stiffness = built_rods_[k].twisting_stiffness * scaling.stiffness;
      model.rods[k].damping = built_rods_[k].damping * scaling.damping;
    }
  // A solid's Lame parameters scale with its Young's modulus (its Poisson's ratio kept), its gas's
  // pressure as a jelly cell's.
  for (std::size_t k = 0; k < model.tetrahedra.size(); ++k)
    if (model.bodyOf(built_tetrahedra_[k].nodes[0]) == body)
    {
      model.tetrahedra[k].mu = built_tetrahedra_[k].mu * scaling.stiffness;
      model.tetrahedra[k].lambda = built_tetrahedra_[k].lambda * scaling.stiffness;
      model.tetrahedra[k].pressure = built_tetrahedra_[k].pressure * scaling.pressure;
    }
}

}  // namespace soft_body_sim

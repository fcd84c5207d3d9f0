// A cable, hose or wire by its material (a `type: rod` body): a rod of circular cross-section that
// stretches, bends and twists (rods.h), straight and untwisted at rest.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "soft_body_sim/core/scene_def.h"

namespace soft_body_sim
{
struct RodDef
{
  int nodes = 41;                         ///< node count (segments = nodes - 1), >= 2
  Vec3 from = Vec3(0.0, 0.0, 1.0);        ///< first node [m]
  Vec3 to = Vec3(1.0, 0.0, 1.0);          ///< last node [m]
  double radius = 0.005;                  ///< r [m] > 0: its circular cross-section, also its contact radius
  double youngs_modulus = 1.0e9;          ///< E [Pa] > 0
  std::optional<double> shear_modulus;    ///< G [Pa] > 0; default E / 2.6 (Poisson's ratio 0.3)
  double density = 1000.0;                ///< rho [kg/m^3] > 0
  /// beta [s] >= 0: stiffness-proportional (Rayleigh) damping of its stretching and bending, a force
  /// -beta K v; a bending mode of angular frequency omega decays at the rate beta omega^2 / 2.
  double damping = 0.0;
  std::vector<int> clamped;               ///< nodes whose position and orientation are held (negative from the end)
  /// [N m] a constant moment on its last node about fixed world axes (Rod::end_moment); needs that node free
  Vec3 end_moment = Vec3::Zero();
  bool self_collision = false;            ///< its segments keep apart by its radius (as a rope's)
  double self_friction = 0.0;             ///< Coulomb coefficient [-] between touching segments, >= 0
};

/// The rod as nodes, stretching springs (E A / l, dashpot beta E A / l) and its Rod (bending E I, twisting
/// G J, I = pi r^4 / 4, J = pi r^4 / 2), nodes of rho A l lumped (half at each end); throws
/// DefinitionError on a bad definition.
BodyDef buildRod(const std::string& name, const RodDef& rod);

}  // namespace soft_body_sim

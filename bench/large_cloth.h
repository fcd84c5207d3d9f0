// The cloth the benchmarks scale up: config/scenes/cloth.yaml's cloth with side x side nodes of the
// same node mass and springs, pinned at two corners, flat and falling, so every spring is updated
// every step.
#pragma once

#include "soft_body_sim/core/bodies/cloth.h"

namespace soft_body_sim
{
inline SceneDef largeClothScene(int side, IntegratorType integrator)
{
  ClothDef cloth;
  cloth.nx = cloth.ny = side;
  cloth.mass = 0.3 / 225.0 * side * side;
  cloth.structural = SpringParameters{ 1000.0, 0.02 };
  cloth.shear = SpringParameters{ 200.0, 0.01 };
  cloth.bending = SpringParameters{ 20.0, 0.0 };
  cloth.pinned = { 0, side - 1 };
  SceneDef scene;
  scene.physics.integrator = integrator;
  // Stable for every scheme: omega_max ~ 3500 1/s at this node mass.
  scene.physics.step.dt = 2e-4;
  scene.bodies.push_back(buildCloth("cloth", cloth));
  return scene;
}

}  // namespace soft_body_sim

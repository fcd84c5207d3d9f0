// A rope or string (spring-string-tutorial.txt): a chain of equal-mass nodes, straight or laid along a
// path, joined by damped springs, optionally stiffened against bending by springs to second neighbours.
#pragma once

#include <string>
#include <vector>

#include "soft_body_sim/core/scene_def.h"

namespace soft_body_sim
{
struct RopeDef
{
  int nodes = 20;                     ///< node count, >= 2
  Vec3 from = Vec3::Zero();           ///< first node [m]
  Vec3 to = Vec3(1.0, 0.0, 0.0);      ///< last node [m]; segments start at rest, |to - from| / (nodes - 1)
  /// If not empty, replaces from and to: the polyline [m] (>= 2 points) along which the nodes lie at
  /// equal arc lengths, first and last node at its ends (a rope laid in a coil or a knot). Its links
  /// start at rest as laid; bending springs keep a straight rest shape.
  std::vector<Vec3> path;
  double mass = 0.1;                  ///< total mass [kg], spread equally over the nodes
  double stiffness = 1000.0;          ///< segment spring stiffness [N/m]
  double damping = 0.0;               ///< segment dashpot [N s/m]
  double bending = 0.0;               ///< stiffness [N/m] of springs to second neighbours; 0 = none
  double bending_damping = 0.0;       ///< their dashpot [N s/m]
  std::vector<int> pinned;            ///< pinned node indices; negative counts from the end (-1 = last)
  double radius = 0.0;                ///< [m] >= 0: contact radius of its nodes (0 = points)
  /// Its links keep apart by their radius from each other (but for neighbours along it,
  /// SelfContacts::kSkippedLinks) and from other self-colliding bodies (self_contacts.h); needs radius > 0.
  bool self_collision = false;
  double self_friction = 0.0;         ///< Coulomb coefficient [-] between touching links, >= 0
};

/// The rope as nodes and springs (type "rope"); throws std::invalid_argument on a bad definition.
BodyDef buildRope(const std::string& name, const RopeDef& rope);

}  // namespace soft_body_sim

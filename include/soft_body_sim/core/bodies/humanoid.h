// The silly humanoid of verlet-bezier-limbs.txt: a rigid, upright torso with two arms and two legs,
// each a seed limb (see limb.h) whose root rides on the torso. The torso follows its target with the
// same Jakobsen spring as the creature's lead (fuzzy-physics-constraints.txt):
//   p' = p + r (p - p_prev) + k T^2 (target - p)
// once per frame period T, the limbs then update with their roots at the torso's new attachment points.
// The torso translates only (it keeps `up` and `facing`); the limbs dangle and swing as it moves.
//
// Nodes (all pinned, driven by the controller): 0 pelvis, 1 neck, 2 head, then four limbs of three
// nodes (root, joint, leaf): 3-5 left arm, 6-8 right arm, 9-11 left leg, 12-14 right leg. The arm roots
// (shoulders) sit at neck +- shoulder_width / 2 along `left` = up x facing, the leg roots (hips) at
// pelvis +- hip_width / 2 along it. Limbs start hanging straight along -up.
#pragma once

#include <optional>
#include <string>

#include "soft_body_sim/core/bodies/limb.h"

namespace soft_body_sim
{
struct HumanoidDef
{
  Vec3 position = Vec3(0.0, 0.0, 1.0);  ///< [m] pelvis at the start
  std::optional<Vec3> target;            ///< [m] first target of the pelvis; default: `position`
  Vec3 up = Vec3::UnitZ();               ///< torso axis, pelvis to head (need not be unit, not zero)
  Vec3 facing = Vec3::UnitX();           ///< the way the figure faces (not parallel to up)
  double torso_length = 0.5;             ///< [m] pelvis to neck, > 0
  double head_height = 0.15;             ///< [m] neck to head centre, > 0
  double shoulder_width = 0.4;           ///< [m] between the arm roots, > 0
  double hip_width = 0.2;                ///< [m] between the leg roots, > 0
  double arm_length = 0.5;               ///< [m] shoulder to hand, halved at the elbow, > 0
  double leg_length = 0.8;               ///< [m] hip to foot, halved at the knee, > 0
  double torso_stiffness = 10.0;         ///< k [1/s^2] of the pelvis's spring to its target, >= 0
  double torso_retention = 0.9;          ///< r: the torso's velocity kept per frame, in [0, 1]; with k this
                                         ///< is close to critical damping at T = 1/60 s (-ln r / T = 2 sqrt(k))
  LimbMotion limbs;                      ///< the four limbs' motion; its frame_period and cap also time the torso
};

/// Node indices within a humanoid body.
enum HumanoidNode : int
{
  kHumanoidPelvis = 0,
  kHumanoidNeck = 1,
  kHumanoidHead = 2,
  kHumanoidLeftArm = 3,   ///< root (shoulder); joint (elbow) and leaf (hand) follow
  kHumanoidRightArm = 6,
  kHumanoidLeftLeg = 9,   ///< root (hip); joint (knee) and leaf (foot) follow
  kHumanoidRightLeg = 12,
  kHumanoidNodes = 15,
};

/// The humanoid as 15 pinned nodes and a controller (type "humanoid"); throws std::invalid_argument on a
/// bad definition.
BodyDef buildHumanoid(const std::string& name, const HumanoidDef& humanoid);

}  // namespace soft_body_sim

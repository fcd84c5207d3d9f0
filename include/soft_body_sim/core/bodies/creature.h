// The codeling of fuzzy-physics-constraints.txt: a small swimming creature animated by its own
// Jakobsen-Verlet dynamics. A lead point is pulled toward a target by a spring (F = -k x); when the
// target changes it first shifts away from it (anticipation), then overshoots and settles. A trailing
// orientation point, damped separately along and across the spine, and two side points held by soft
// unilateral constraints give it squash and stretch. Optional tendrils (ropes) hang from the side points.
//
// Units. The seed runs one update per tick of a fixed timer with "a time delta of about 0.25" in its own
// units and F = -0.9 x, so its recurrence sees the dimensionless k_seed tau^2 = 0.9 * 0.25^2 = 0.05625 per
// update. Here one update lasts T = update_period [s] and the spring is an acceleration per metre,
// k [1/s^2], with k T^2 = k_seed tau^2: the default T = 1/30 s (an assumed Flash frame rate) gives
// k = 0.05625 / T^2 = 50.625 1/s^2. Retentions (the seed's 0.7 drag, 0.7 / 0.5 parallel / perpendicular
// damping) and constraint strengths (0.8 / 0.1) are fractions per update: a retention r lets velocity
// decay as r^(t / T), at the rate -ln(r) / T (10.7 1/s for r = 0.7 at T = 1/30 s). The updates run from an
// accumulator at period T whatever the physics dt, so the motion does not depend on dt. To keep the same
// motion at another period T', scale k by (T / T')^2 and each retention r to r^(T' / T).
//
// 3D. The seed is 2D; here the creature swims in the plane through its start `position` with normal
// `plane_normal` (default +z: a horizontal plane, so that tendrils hang out of it under gravity). Targets
// are projected into that plane; the side points lie in it, perpendicular to the spine.
//
// Anticipation and streamed targets. The seed's antic starts a move: from rest, a new target shifts the
// lead away by anticipation * (lead - target) before it rushes in. Fired by every new target, it compounds:
// each antic multiplies the lead's error by (1 + a) and adds that shift as velocity, so targets streamed
// faster than the lead settles (a planner at 10 to 100 Hz) make the error grow geometrically, by 1.35 per
// update with the defaults and an antic every update, by 1.1 with one every other update (the spectral
// radius of the periodic map), until the tendrils hang from points moving at 1e5 m/s. Here an antic fires
// only from a settled lead (see settle_tolerance): then the shift is at most a (|jump| + s) once, the lead's
// linear recurrence (stable for k T^2 < 2 (1 + r), r < 1) damps it before another antic can fire, and
// between antics the lead is that stable filter of the target, so its motion stays bounded for any stream.
//
// Nodes: 0 lead, 1 orientation (tail), 2 left side point, 3 right side point ("left" = plane_normal x
// heading), then the left tendril's nodes from the top down, then the right tendril's. The four body
// points are pinned and driven by the controller; the tendril nodes are free and move by the integrator.
#pragma once

#include <optional>
#include <string>

#include "soft_body_sim/core/scene_def.h"

namespace soft_body_sim
{
/// Ropes hanging from the two side points, one each.
struct TendrilDef
{
  int segments = 8;                      ///< springs per tendril = free nodes per tendril, >= 1
  double length = 0.3;                   ///< [m] straight length at rest, > 0
  double mass = 0.01;                    ///< [kg] of one tendril, spread equally over its free nodes, > 0
  double stiffness = 20.0;               ///< [N/m] of each segment spring, > 0
  double damping = 0.01;                 ///< [N s/m] of each segment's dashpot, >= 0
  Vec3 direction = Vec3(0.0, 0.0, -1.0); ///< the tendrils start straight along this (need not be unit)
};

struct CreatureDef
{
  Vec3 position = Vec3::Zero();          ///< [m] start of the lead point; the swimming plane passes through it
  Vec3 heading = Vec3::UnitX();          ///< start direction from the orientation point to the lead (projected
                                         ///< into the plane; must not be parallel to plane_normal)
  Vec3 plane_normal = Vec3::UnitZ();     ///< normal of the swimming plane (need not be unit, not zero)
  std::optional<Vec3> target;            ///< [m] first target (no anticipation); default: `position`
  double length = 0.2;                   ///< [m] relaxed spine length, lead to orientation point, > 0
  double width = 0.12;                   ///< [m] relaxed distance between the side points, > 0
  double update_period = 1.0 / 30.0;     ///< T [s] of one update of the creature's dynamics, > 0
  double stiffness = 50.625;             ///< k [1/s^2]: the lead accelerates by k (target - lead), >= 0;
                                         ///< stable for k T^2 < 2 (1 + lead_retention)
  double lead_retention = 0.7;           ///< r: the lead's velocity kept per update, in [0, 1]; the seed's
                                         ///< x' = 1.7 x - 0.7 x_prev + a T^2 is x' = x + r (x - x_prev) + a T^2
  double anticipation = 0.2;             ///< fraction of the distance to a new target by which the lead first
                                         ///< shifts away from it, >= 0 (when it fires: see settle_tolerance)
  double settle_tolerance = 0.02;        ///< [-] fraction of `length`, > 0: a new target starts a move with
                                         ///< anticipation only if the lead has settled on the previous target
                                         ///< (within settle_tolerance * length of it and moving less than that
                                         ///< per update) and the new one lies farther than that from it; a
                                         ///< target that arrives while the creature swims only steers it
  double parallel_retention = 0.7;       ///< orientation point's velocity kept along the spine per update, [0, 1]
  double perpendicular_retention = 0.5;  ///< ... and across it, in [0, 1]
  double side_retention = 0.5;           ///< side points' velocity kept per update, in [0, 1]
  double min_ratio = 0.6;                ///< each soft constraint's min length / relaxed length, in (0, 1]
  double max_ratio = 1.4;                ///< ... max length / relaxed length, >= 1
  double soft_strength = 0.1;            ///< fraction of the error toward the relaxed length corrected per
                                         ///< update between min and max, in (0, 1]
  double hard_strength = 0.8;            ///< fraction of the error beyond min or max corrected per update, (0, 1]
  int iterations = 1;                    ///< passes over the soft constraints per update, >= 1 (the seed: 1)
  std::optional<TendrilDef> tendrils;    ///< none by default
};

/// Node indices within a creature body.
enum CreatureNode : int
{
  kCreatureLead = 0,
  kCreatureOrientation = 1,
  kCreatureLeftSide = 2,
  kCreatureRightSide = 3,
  kCreatureBodyPoints = 4,
};

/// Lengths of one soft unilateral constraint [m]: min <= relaxed <= max.
struct SoftLength
{
  double min = 0.0;
  double relaxed = 0.0;
  double max = 0.0;
};

/// The seed's soft unilateral constraint on d = reference - moved, |d| = L; returns the displacement [m]
/// to add to the moved point (the reference stays):
///   L < min:   d (L - min) / L * hard_strength      (over-compression)
///   L > max:   d (L - max) / L * hard_strength      (over-extension)
///   otherwise: d (L - relaxed) / L * soft_strength  (normal correction)
/// Zero when L is 0 (no direction) or exactly relaxed.
Vec3 softUnilateralCorrection(const Vec3& d, const SoftLength& length, double soft_strength, double hard_strength);

/// The creature as 4 pinned body points (+ tendrils) and a controller (type "creature"); throws
/// std::invalid_argument on a bad definition.
BodyDef buildCreature(const std::string& name, const CreatureDef& creature);

}  // namespace soft_body_sim

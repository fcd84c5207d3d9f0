// The limb of verlet-bezier-limbs.txt: three particles (root, joint, leaf) moved by Verlet under
// gravity, held together by two distance links relaxed a few times per update, and drawn as the
// quadratic Bezier curve whose control points they are.
//
// Units. The seed updates once per frame of T = 1 / room_speed (60 fps: 1/60 s) with positions in
// pixels and gravity in pixels per frame^2, and scales a frame's step by s = min(delta / T, 4) against long
// frames. Here positions are in metres, gravity g is in [m/s^2] (one update adds g T^2 [m]), and the
// limb updates at the fixed period T = frame_period from an accumulator, so its motion does not depend
// on the physics dt. The cap becomes: at most max_frames_per_step periods of limb time pass per world
// step; the rest of a longer step is dropped (the limb falls behind instead of jerking).
//
// The root. A limb's root is its node 0, pinned; the limb never moves it (the seed resets its root to the
// body every frame, dropping the root's share of a link correction). It stays where the scene puts it,
// or follows an anchor on node 0 (World::moveAnchor); the controller reads it every update. In a humanoid
// the torso places the roots.
#pragma once

#include <string>

#include "soft_body_sim/core/bodies/bezier.h"
#include "soft_body_sim/core/scene_def.h"
#include "soft_body_sim/core/state_archive.h"

namespace soft_body_sim
{
/// How a limb moves; shared by `limb` and the four limbs of `humanoid`.
/// The most points of a drawn limb curve (LimbMotion::curve_samples).
constexpr int kMaxCurveSamples = 10000;

struct LimbMotion
{
  Vec3 gravity = Vec3(0.0, 0.0, -9.81);  ///< [m/s^2] on joint and leaf (pinned nodes: physics.gravity does
                                         ///< not reach them, so the limb has its own)
  double frame_period = 1.0 / 60.0;      ///< T [s] between updates (the seed's 1 / room_speed), > 0
  double max_frames_per_step = 4.0;      ///< at most this many periods of limb time per world step (the
                                         ///< seed's cap of 4), > 0
  int iterations = 8;                    ///< link relaxation passes per update (linkIterations), >= 1
  double tension = 0.5;                  ///< fraction of a link's length error each end takes per pass
                                         ///< (velLinkTensionFactor), in (0, 1); 0.5 closes a free link in one pass
  double retention = 1.0;                ///< velocity kept per update, in [0, 1]; 1 = the seed's undamped Verlet
  int curve_samples = 16;                ///< points of each drawn Bezier curve, >= 2
};

struct LimbDef
{
  Vec3 root = Vec3(0.0, 0.0, 1.0);        ///< [m] node 0
  Vec3 direction = Vec3(0.0, 0.0, -1.0);  ///< the limb starts straight (and at rest) from the root along this
  double upper_length = 0.3;              ///< [m] link root-joint, > 0
  double lower_length = 0.3;              ///< [m] link joint-leaf, > 0
  LimbMotion motion;
};

/// Node indices within a limb body (and within each limb of a humanoid).
enum LimbNode : int
{
  kLimbRoot = 0,
  kLimbJoint = 1,
  kLimbLeaf = 2,
};

/// One limb's dynamics, one update at a time (no clock; the controllers own that).
class LimbDynamics
{
public:
  LimbDynamics(const LimbMotion& motion, double upper_length, double lower_length, const Vec3& joint,
               const Vec3& leaf);

  /// One update of period T with the root at `root` [m]:
  ///   x' = x + r (x - x_prev) + g T^2        (joint and leaf; the seed's Verlet step, r = retention)
  /// then `iterations` passes over the links root-joint and joint-leaf, each moving its ends toward the
  /// link length by tension * (L - |d|) / |d| * d (the seed's relaxation; the root's share is dropped).
  void update(const Vec3& root);

  const Vec3& joint() const { return joint_; }
  const Vec3& leaf() const { return leaf_; }

  void carry(StateArchive& archive) { archive(joint_, leaf_, joint_previous_, leaf_previous_); }

private:
  LimbMotion motion_;
  double upper_length_;
  double lower_length_;
  Vec3 joint_;
  Vec3 leaf_;
  Vec3 joint_previous_;
  Vec3 leaf_previous_;
};

/// The quadratic Bezier curve of the limb whose root is node `root_node` of `state` (joint and leaf
/// follow it), sampled at `samples` points, with its tangents dB/dt.
std::vector<Vec3> limbCurve(const State& state, int root_node, int samples);

/// Checks a LimbMotion; throws std::invalid_argument naming `what` ("limb 'arm'").
void checkLimbMotion(const LimbMotion& motion, const std::string& what);

/// The limb as 3 pinned nodes and a controller (type "limb"); throws std::invalid_argument on a bad
/// definition.
BodyDef buildLimb(const std::string& name, const LimbDef& limb);

}  // namespace soft_body_sim

// The Bezier limbs and the humanoid (verlet-bezier-limbs.txt) against independent truth: the fixed
// point of the link relaxation in closed form, the pendulum's peak tension, the step cap, the torso's
// spring recurrence, and the loader's reading of their keys.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "soft_body_sim/core/bodies/humanoid.h"
#include "soft_body_sim/core/bodies/limb.h"
#include "soft_body_sim/scene/scene_loader.h"
#include "test_util.h"
#include "scene_error.h"

namespace soft_body_sim::test
{
namespace
{
World limbWorld(const LimbDef& def, double dt)
{
  SceneDef scene = oneBodyScene(IntegratorType::SemiImplicitEuler, dt);
  scene.bodies[0] = buildLimb("limb", def);
  return buildWorld(scene);
}

Vec3 node(const World& world, int i) { return world.state().position.col(i); }

/// Link length errors |d| - L [m] of the limb whose root is node `root`.
Eigen::Vector2d linkErrors(const World& world, int root, double upper, double lower)
{
  return Eigen::Vector2d((node(world, root + kLimbJoint) - node(world, root)).norm() - upper,
                         (node(world, root + kLimbLeaf) - node(world, root + kLimbJoint)).norm() - lower);
}

/// The relaxation of a straight (collinear) limb, linear and exact in the link errors e = (e1, e2):
/// a pass over root-joint moves only the joint, by tau e1 toward the root (e1 -> (1 - tau) e1, e2 -> e2 +
/// tau e1); a pass over joint-leaf moves both by tau e2 toward each other (e2 -> (1 - 2 tau) e2, e1 -> e1 +
/// tau e2). One iteration is their product M; `iterations` of them M^k.
Eigen::Matrix2d relaxationMatrix(double tau, int iterations)
{
  Eigen::Matrix2d upper_pass;
  upper_pass << 1.0 - tau, 0.0, tau, 1.0;
  Eigen::Matrix2d lower_pass;
  lower_pass << 1.0, tau, 0.0, 1.0 - 2.0 * tau;
  const Eigen::Matrix2d one = lower_pass * upper_pass;
  Eigen::Matrix2d all = Eigen::Matrix2d::Identity();
  for (int k = 0; k < iterations; ++k)
    all = one * all;
  return all;
}

/// The stretch of a limb hanging at rest: each update gravity moves joint and leaf by a = g T^2 (the
/// upper link grows by a, the lower one not), and the relaxation must take it back:
/// e = M^k (e + (a, 0))  =>  e = (I - M^k)^-1 M^k (a, 0).
Eigen::Vector2d hangingStretch(const LimbMotion& motion)
{
  const Eigen::Matrix2d m = relaxationMatrix(motion.tension, motion.iterations);
  const double a = motion.gravity.norm() * motion.frame_period * motion.frame_period;
  return (Eigen::Matrix2d::Identity() - m).inverse() * m * Eigen::Vector2d(a, 0.0);
}

// --- limb ---------------------------------------------------------------------------------------

TEST(Limb, HangingLimbStretchesExactlyAsTheRelaxationFixedPoint)
{
  // Straight down from a fixed root, the limb stays collinear and the linear model above is exact; the
  // stretch converges to its fixed point (at rate ~ the spectral radius of M^k per update). Default
  // motion (8 iterations, tension 0.5): e = (3.03e-4, 0) m. Round-off: 1e-12 m.
  for (const int iterations : { 1, 4, 8 })
    for (const double tension : { 0.3, 0.5, 0.7 })
    {
      LimbDef def;
      def.motion.iterations = iterations;
      def.motion.tension = tension;
      World world = limbWorld(def, def.motion.frame_period);
      for (int n = 0; n < 3000; ++n)
        world.step();
      const Eigen::Vector2d expected = hangingStretch(def.motion);
      EXPECT_TRUE(expectNear(linkErrors(world, 0, def.upper_length, def.lower_length), expected, 1e-12))
          << "iterations " << iterations << " tension " << tension;
      // Straight below the root.
      EXPECT_TRUE(expectNear(node(world, kLimbLeaf).head<2>(), def.root.head<2>(), 1e-12));
    }
  EXPECT_TRUE(expectNear(hangingStretch(LimbMotion{}), Eigen::Vector2d(3.032e-4, 0.0), 1e-7));
}

TEST(Limb, SwingingLimbKeepsItsLinksWithinThreeTimesTheHangingStretch)
{
  // The relaxation acts like a stiff spring: the residual stretch of a link grows with the force it
  // carries. Hanging, the force is the weight (stretch: the fixed point above). A limb released
  // horizontal swings through the bottom like a pendulum, whose link then carries m g + m v^2 / L =
  // 3 m g (v^2 = 2 g L). So the stretch stays within ~3 times the hanging one; the double pendulum's
  // whip adds a little (measured: 2.9 to 3.1 over these settings). Bound asserted: 3.5 times.
  for (const int iterations : { 1, 8 })
    for (const double tension : { 0.3, 0.5 })
    {
      LimbDef def;
      def.direction = Vec3(1.0, 0.0, 0.0);
      def.motion.iterations = iterations;
      def.motion.tension = tension;
      World world = limbWorld(def, def.motion.frame_period);  // one frame per step: no drawing in between
      double worst = 0.0;
      for (int n = 0; n < 600; ++n)  // 10 s: many swings (undamped: retention 1)
      {
        world.step();
        worst = std::max(worst, linkErrors(world, 0, def.upper_length, def.lower_length).cwiseAbs().maxCoeff());
      }
      const double hanging = hangingStretch(def.motion)(0);
      EXPECT_LE(worst, 3.5 * hanging) << "iterations " << iterations << " tension " << tension;
      EXPECT_GE(worst, 2.0 * hanging) << "it swings through the bottom";
    }
}

TEST(Limb, HugeFrameTimeAdvancesByAtMostTheCap)
{
  // The seed's min(delta / period, 4): a 10 s world step moves the limb as 4 frames do. With a cap of
  // 2.5 it moves it as 2.5 frames: halfway between frames 2 and 3.
  LimbDef def;
  def.direction = Vec3(1.0, 0.0, -0.5);
  const double t = def.motion.frame_period;
  World huge = limbWorld(def, 10.0);
  World four_frames = limbWorld(def, t);
  huge.step();
  for (int n = 0; n < 4; ++n)
    four_frames.step();
  EXPECT_TRUE(expectNear(huge.state().position, four_frames.state().position, 1e-15));
  EXPECT_FALSE(expectNear(huge.state().position, limbWorld(def, t).state().position, 1e-3)) << "it moved";

  def.motion.max_frames_per_step = 2.5;
  World capped = limbWorld(def, 1e3);
  World half_frames = limbWorld(def, t / 2.0);
  capped.step();
  for (int n = 0; n < 5; ++n)
    half_frames.step();
  EXPECT_TRUE(expectNear(capped.state().position, half_frames.state().position, 1e-15));
}

TEST(Limb, MotionDoesNotDependOnThePhysicsStep)
{
  // A fixed frame period from an accumulator: the same limb time gives the same limb, up to the
  // round-off of summing dt.
  LimbDef def;
  def.direction = Vec3(1.0, 0.3, 0.2);
  const std::vector<double> steps = { 1e-3, 2e-3, def.motion.frame_period / 3.0, 1e-2 };
  std::vector<NodeArray> results;
  for (const double dt : steps)
  {
    World world = limbWorld(def, dt);
    while (world.time() < 1.0 - 1e-9)
      world.step();
    results.push_back(world.state().position);
  }
  for (std::size_t k = 1; k < results.size(); ++k)
    EXPECT_TRUE(expectNear(results[k], results[0], 1e-12)) << "dt = " << steps[k];
}

TEST(Limb, RootStaysPutOrFollowsItsAnchor)
{
  LimbDef def;
  def.direction = Vec3(1.0, 0.0, 0.0);
  SceneDef scene = oneBodyScene(IntegratorType::SemiImplicitEuler, 1e-3);
  scene.bodies[0] = buildLimb("arm", def);
  World fixed = buildWorld(scene);
  scene.bodies[0].anchors = { AnchorDef{ "shoulder", kLimbRoot } };
  World anchored = buildWorld(scene);
  const Vec3 goal = def.root + Vec3(0.5, -0.2, 0.1);
  const std::optional<int> anchor = anchored.findAnchor("arm", "shoulder");
  ASSERT_TRUE(anchor);
  anchored.moveAnchor(*anchor, goal);
  for (int n = 0; n < 3000; ++n)
  {
    fixed.step();
    anchored.step();
    ASSERT_EQ(node(fixed, kLimbRoot), def.root) << "the limb never moves its root";
  }
  EXPECT_EQ(node(anchored, kLimbRoot), goal);
  // The limb followed: its links hold their lengths around the new root (within the swing bound above).
  const double bound = 3.5 * hangingStretch(def.motion)(0);
  EXPECT_LE(linkErrors(anchored, 0, def.upper_length, def.lower_length).cwiseAbs().maxCoeff(), bound);
}

TEST(Limb, DrawsTheBezierCurveOfItsThreeNodes)
{
  LimbDef def;
  def.direction = Vec3(1.0, 0.0, 0.0);
  def.motion.curve_samples = 9;
  World world = limbWorld(def, 1e-3);
  for (int n = 0; n < 200; ++n)
    world.step();
  const Vec3 root = node(world, kLimbRoot);
  const Vec3 joint = node(world, kLimbJoint);
  const Vec3 leaf = node(world, kLimbLeaf);
  const auto curves = world.controllers()[0].controller->curves(world.state());
  ASSERT_EQ(curves.size(), 1u);
  ASSERT_EQ(curves[0].size(), 9u);
  EXPECT_EQ(curves[0].front(), root);
  EXPECT_EQ(curves[0].back(), leaf);
  for (int i = 0; i < 9; ++i)
    EXPECT_TRUE(expectNear(curves[0][static_cast<std::size_t>(i)], quadraticBezier(root, joint, leaf, i / 8.0), 1e-15));
  EXPECT_FALSE(world.setTarget("limb", Vec3::Zero())) << "a limb takes no target";
  EXPECT_FALSE(world.takesTarget(0));
}

// --- humanoid -----------------------------------------------------------------------------------

World humanoidWorld(const HumanoidDef& def, double dt)
{
  SceneDef scene = oneBodyScene(IntegratorType::SemiImplicitEuler, dt);
  scene.bodies[0] = buildHumanoid("figure", def);
  return buildWorld(scene);
}

TEST(Humanoid, LimbRootsStayAtTheirTorsoAttachmentPoints)
{
  // While the torso runs to a target, every drawn root is the pelvis plus its fixed offset (shoulders at
  // neck +- shoulder_width / 2 along left = up x facing, hips at pelvis +- hip_width / 2), exactly.
  HumanoidDef def;
  World world = humanoidWorld(def, 1e-3);
  world.setTarget("figure", Vec3(1.0, 0.5, 1.2));
  const Vec3 up = def.up;
  const Vec3 left(0.0, 1.0, 0.0);  // z x x
  for (int n = 0; n < 3000; ++n)
  {
    world.step();
    const Vec3 pelvis = node(world, kHumanoidPelvis);
    const Vec3 neck = pelvis + def.torso_length * up;
    ASSERT_TRUE(expectNear(node(world, kHumanoidNeck), neck, 1e-14)) << "step " << n;
    ASSERT_TRUE(expectNear(node(world, kHumanoidHead), Vec3(neck + def.head_height * up), 1e-14));
    ASSERT_TRUE(expectNear(node(world, kHumanoidLeftArm), Vec3(neck + 0.5 * def.shoulder_width * left), 1e-14));
    ASSERT_TRUE(expectNear(node(world, kHumanoidRightArm), Vec3(neck - 0.5 * def.shoulder_width * left), 1e-14));
    ASSERT_TRUE(expectNear(node(world, kHumanoidLeftLeg), Vec3(pelvis + 0.5 * def.hip_width * left), 1e-14));
    ASSERT_TRUE(expectNear(node(world, kHumanoidRightLeg), Vec3(pelvis - 0.5 * def.hip_width * left), 1e-14));
  }
  // The limbs came along: each link within the swing bound of its own hanging stretch.
  for (const int root : { kHumanoidLeftArm, kHumanoidRightArm, kHumanoidLeftLeg, kHumanoidRightLeg })
  {
    const bool arm = root == kHumanoidLeftArm || root == kHumanoidRightArm;
    const double half = 0.5 * (arm ? def.arm_length : def.leg_length);
    EXPECT_LE(linkErrors(world, root, half, half).cwiseAbs().maxCoeff(), 3.5 * hangingStretch(def.limbs)(0))
        << "limb at node " << root;
  }
}

TEST(Humanoid, TorsoReachesItsTarget)
{
  // The pelvis obeys e_{n+1} = (1 + r) e_n - r e_{n-1} - k T^2 e_n (e = pelvis - target), computed here;
  // its roots have modulus sqrt(r) = 0.949 per frame, so from 1 m away it is within 1 mm after 4 s
  // (the recurrence gives 6e-7 m there).
  HumanoidDef def;
  const double t = def.limbs.frame_period;
  World world = humanoidWorld(def, t / 2.0);
  world.step();
  world.step();  // one frame; the target then applies from the next frame computed
  const Vec3 target = def.position + Vec3(0.6, -0.8, 0.0);
  EXPECT_TRUE(world.takesTarget(0));
  world.setTarget("figure", target);
  const double r = def.torso_retention;
  const double kt2 = def.torso_stiffness * t * t;
  std::vector<double> e = { -1.0, -1.0 };  // along the unit (0.6, -0.8, 0), at rest
  while (e.size() < 400)
    e.push_back((1.0 + r) * e.back() - r * e[e.size() - 2] - kt2 * e.back());
  // Drawn at frame instant n is frame n. The figure computes one frame ahead, so the target, set at
  // instant 1, first moves frame 3 (= e[2]): frame n is e[n - 1].
  for (std::size_t n = 2; n < 242; ++n)
  {
    world.step();
    world.step();
    const Vec3 expected = target + e[n - 1] * Vec3(0.6, -0.8, 0.0);
    ASSERT_TRUE(expectNear(node(world, kHumanoidPelvis), expected, 1e-12)) << "frame " << n;
  }
  EXPECT_LT((node(world, kHumanoidPelvis) - target).norm(), 1e-3);
}

TEST(Humanoid, LegsHangBelowTheHipsAndCurvesAreDrawn)
{
  HumanoidDef def;
  World world = humanoidWorld(def, 1e-3);
  for (int n = 0; n < 2000; ++n)
    world.step();
  const Eigen::Vector2d stretch = hangingStretch(def.limbs);
  for (const int root : { kHumanoidLeftLeg, kHumanoidRightLeg })
    EXPECT_TRUE(expectNear(node(world, root + kLimbLeaf),
                           Vec3(node(world, root) - Vec3(0, 0, def.leg_length + stretch.sum())), 1e-12));
  const auto curves = world.controllers()[0].controller->curves(world.state());
  ASSERT_EQ(curves.size(), 7u);  // spine, shoulders, hips, four limbs
  EXPECT_EQ(curves[3].size(), static_cast<std::size_t>(def.limbs.curve_samples));
  EXPECT_EQ(curves[3].front(), node(world, kHumanoidLeftArm));
}

// --- scene files --------------------------------------------------------------------------------

void expectSameMotion(const SceneDef& parsed, const BodyDef& built, const std::string& type, bool target)
{
  ASSERT_EQ(parsed.bodies.size(), 1u);
  const BodyDef& body = parsed.bodies[0];
  EXPECT_EQ(body.type, type);
  ASSERT_EQ(body.nodes.size(), built.nodes.size());
  for (std::size_t i = 0; i < body.nodes.size(); ++i)
  {
    EXPECT_EQ(body.nodes[i].position, built.nodes[i].position) << "node " << i;
    EXPECT_TRUE(body.nodes[i].pinned);
  }
  SceneDef by_hand = parsed;
  by_hand.bodies[0] = built;
  by_hand.bodies[0].name = body.name;
  World from_file = buildWorld(parsed);
  World from_struct = buildWorld(by_hand);
  for (int n = 0; n < 1500; ++n)
  {
    if (target && n == 100)
    {
      from_file.setTarget(body.name, Vec3(0.4, 0.3, 1.0));
      from_struct.setTarget(body.name, Vec3(0.4, 0.3, 1.0));
    }
    from_file.step();
    from_struct.step();
  }
  EXPECT_TRUE(expectNear(from_file.state().position, from_struct.state().position, 0.0));
  const auto file_curves = from_file.controllers()[0].controller->curves(from_file.state());
  const auto struct_curves = from_struct.controllers()[0].controller->curves(from_struct.state());
  ASSERT_EQ(file_curves.size(), struct_curves.size());
  for (std::size_t k = 0; k < file_curves.size(); ++k)
    EXPECT_EQ(file_curves[k].size(), struct_curves[k].size());
}

const char* const kLimbAllKeys = R"(physics: {dt: 0.002}
bodies:
  - name: arm
    type: limb
    root: [0.1, 0.2, 1.5]
    direction: [1, 0, -1]
    upper_length: 0.35
    lower_length: 0.25
    gravity: [0, 0, -5]
    frame_period: 0.02
    max_frames_per_step: 3
    iterations: 5
    tension: 0.4
    retention: 0.98
    curve_samples: 12
)";

LimbDef limbAllKeysDef()
{
  LimbDef def;
  def.root = Vec3(0.1, 0.2, 1.5);
  def.direction = Vec3(1, 0, -1);
  def.upper_length = 0.35;
  def.lower_length = 0.25;
  def.motion = LimbMotion{ Vec3(0, 0, -5), 0.02, 3.0, 5, 0.4, 0.98, 12 };
  return def;
}

TEST(LimbScene, EveryKeyReachesTheBody)
{
  expectSameMotion(parseScene(kLimbAllKeys, "limb.yaml"), buildLimb("arm", limbAllKeysDef()), "limb", false);
  expectSameMotion(parseScene("bodies: [{name: l, type: limb}]", "limb.yaml"), buildLimb("l", LimbDef{}), "limb",
                   false);
}

const char* const kHumanoidAllKeys = R"(physics: {dt: 0.002}
bodies:
  - name: figure
    type: humanoid
    position: [0.5, 0.0, 1.2]
    target: [0.6, 0.1, 1.2]
    up: [0, 0, 2]
    facing: [0, 1, 0]
    torso_length: 0.45
    head_height: 0.12
    shoulder_width: 0.35
    hip_width: 0.18
    arm_length: 0.55
    leg_length: 0.75
    torso_stiffness: 12
    torso_retention: 0.88
    gravity: [0, 0, -9]
    frame_period: 0.02
    max_frames_per_step: 3
    iterations: 6
    tension: 0.45
    retention: 0.97
    curve_samples: 10
)";

HumanoidDef humanoidAllKeysDef()
{
  HumanoidDef def;
  def.position = Vec3(0.5, 0.0, 1.2);
  def.target = Vec3(0.6, 0.1, 1.2);
  def.up = Vec3(0, 0, 2);
  def.facing = Vec3(0, 1, 0);
  def.torso_length = 0.45;
  def.head_height = 0.12;
  def.shoulder_width = 0.35;
  def.hip_width = 0.18;
  def.arm_length = 0.55;
  def.leg_length = 0.75;
  def.torso_stiffness = 12.0;
  def.torso_retention = 0.88;
  def.limbs = LimbMotion{ Vec3(0, 0, -9), 0.02, 3.0, 6, 0.45, 0.97, 10 };
  return def;
}

TEST(HumanoidScene, EveryKeyReachesTheBody)
{
  expectSameMotion(parseScene(kHumanoidAllKeys, "humanoid.yaml"), buildHumanoid("figure", humanoidAllKeysDef()),
                   "humanoid", true);
  expectSameMotion(parseScene("bodies: [{name: h, type: humanoid}]", "humanoid.yaml"),
                   buildHumanoid("h", HumanoidDef{}), "humanoid", true);
}

/// A one-body scene of `type` whose 4th line is `line`.
std::string bodyWith(const std::string& type, const std::string& line)
{
  return "bodies:\n  - name: b\n    type: " + type + "\n    " + line + "\n";
}

TEST(LimbScene, BadValuesAreRejectedWithOneLineAtTheKey)
{
  const std::string at = "bad.yaml:4: bodies[0].";
  // The motion keys, for both types that have them.
  for (const std::string type : { "limb", "humanoid" })
  {
    SCOPED_TRACE(type);
    expectSceneError(bodyWith(type, "gravity: [0, 0]"), at + "gravity", { "3 numbers" });
    expectSceneError(bodyWith(type, "frame_period: 0"), at + "frame_period", { "> 0" });
    expectSceneError(bodyWith(type, "max_frames_per_step: -4"), at + "max_frames_per_step", { "(0, 100]", "-4" });
    expectSceneError(bodyWith(type, "iterations: 0"), at + "iterations", { "[1," });
    expectSceneError(bodyWith(type, "iterations: 2.5"), at + "iterations", { "integer" });
    expectSceneError(bodyWith(type, "tension: 1"), at + "tension", { "(0, 1)" });
    expectSceneError(bodyWith(type, "tension: 0"), at + "tension", { "(0, 1)", "got 0" });
    expectSceneError(bodyWith(type, "retention: 1.2"), at + "retention", { "[0, 1]" });
    expectSceneError(bodyWith(type, "curve_samples: 1"), at + "curve_samples", { "[2," });
    expectSceneError(bodyWith(type, "elbow: 3"), at + "elbow", { "unknown key", "curve_samples" });
  }
  expectSceneError(bodyWith("limb", "root: [0, 0, x]"), at + "root[2]", { "number" });
  expectSceneError(bodyWith("limb", "direction: [0, 0, 0]"), at + "direction", { "zero" });
  expectSceneError(bodyWith("limb", "upper_length: 0"), at + "upper_length", { "> 0" });
  expectSceneError(bodyWith("limb", "lower_length: -1"), at + "lower_length", { "> 0" });
  expectSceneError(bodyWith("limb", "target: [1, 2, 3]"), at + "target", { "unknown key" });
}

TEST(HumanoidScene, BadValuesAreRejectedWithOneLineAtTheKey)
{
  const std::string at = "bad.yaml:4: bodies[0].";
  expectSceneError(bodyWith("humanoid", "position: 3"), at + "position", { "3 numbers" });
  expectSceneError(bodyWith("humanoid", "up: [0, 0, 0]"), at + "up", { "zero" });
  expectSceneError(bodyWith("humanoid", "facing: [0, 0, 5]"), at + "facing", { "parallel to up" });
  for (const std::string key : { "torso_length", "head_height", "shoulder_width", "hip_width", "arm_length",
                                 "leg_length" })
    expectSceneError(bodyWith("humanoid", key + ": 0"), at + key, { "> 0" });
  expectSceneError(bodyWith("humanoid", "torso_stiffness: -1"), at + "torso_stiffness", { ">= 0" });
  // k T^2 = 1e5 / 3600 = 28 > 2 (1 + 0.9)
  expectSceneError(bodyWith("humanoid", "torso_stiffness: 100000"), at + "torso_stiffness", { "stable" });
  expectSceneError(bodyWith("humanoid", "torso_retention: 2"), at + "torso_retention", { "[0, 1]" });
  // Parallel up and facing through `up` alone (facing keeps its default): reported at `up`.
  expectSceneError(bodyWith("humanoid", "up: [1, 0, 0]"), at + "up", { "parallel to up" });
}

}  // namespace
}  // namespace soft_body_sim::test

// A physics step allocates no memory after the first one: every integrator, in a scene with every
// feature a step touches (springs, distance constraints, gas cells, a floor, moving anchors, and the
// creature, limb and humanoid controllers).
// Allocations are counted by interposing the C allocator: operator new (libstdc++) and Eigen's
// aligned_malloc both end in malloc, so counting malloc, calloc, realloc and the aligned variants
// sees every heap allocation of the step, whoever makes it.
#include <cstddef>
#include <cstdlib>

#include <gtest/gtest.h>

#include "soft_body_sim/core/bodies/cloth.h"
#include "soft_body_sim/core/bodies/creature.h"
#include "soft_body_sim/core/bodies/humanoid.h"
#include "soft_body_sim/core/bodies/jelly.h"
#include "soft_body_sim/core/bodies/limb.h"
#include "soft_body_sim/core/bodies/rod.h"
#include "soft_body_sim/core/bodies/volume.h"
#include "soft_body_sim/core/bodies/rope.h"
#include "soft_body_sim/core/scene_def.h"

// glibc's own entry points, which the interposed functions below forward to.
extern "C" void* __libc_malloc(std::size_t size);
extern "C" void* __libc_calloc(std::size_t count, std::size_t size);
extern "C" void* __libc_realloc(void* pointer, std::size_t size);
extern "C" void* __libc_memalign(std::size_t alignment, std::size_t size);
extern "C" void __libc_free(void* pointer);

namespace
{
bool g_counting = false;
long g_allocations = 0;
void* volatile g_sink = nullptr;  // keeps the probe allocations below from being optimised away

void count()
{
  if (g_counting)
    ++g_allocations;
}
}  // namespace

extern "C"
{
void* malloc(std::size_t size)
{
  count();
  return __libc_malloc(size);
}
void* calloc(std::size_t count_, std::size_t size)
{
  count();
  return __libc_calloc(count_, size);
}
void* realloc(void* pointer, std::size_t size)
{
  count();
  return __libc_realloc(pointer, size);
}
void* memalign(std::size_t alignment, std::size_t size)
{
  count();
  return __libc_memalign(alignment, size);
}
void* aligned_alloc(std::size_t alignment, std::size_t size)
{
  count();
  return __libc_memalign(alignment, size);
}
int posix_memalign(void** pointer, std::size_t alignment, std::size_t size)
{
  count();
  *pointer = __libc_memalign(alignment, size);
  return *pointer ? 0 : 12;  // ENOMEM
}
void free(void* pointer) { __libc_free(pointer); }
}

namespace soft_body_sim::test
{
namespace
{
/// Allocations made by `action`.
template <typename Action>
long allocationsOf(Action&& action)
{
  g_allocations = 0;
  g_counting = true;
  action();
  g_counting = false;
  return g_allocations;
}

/// Every body type side by side above a floor, with anchors on the rope and the cloth, inextensible
/// constraints along the rope and a heavy-ended chain, so that a step runs every stage and every kernel.
SceneDef everyFeatureScene(IntegratorType integrator)
{
  SceneDef scene;
  scene.physics.integrator = integrator;
  // Explicit Euler gains energy every step: a small step keeps it finite over the test.
  scene.physics.step.dt = integrator == IntegratorType::ExplicitEuler ? 1e-4 : 2e-3;
  scene.physics.step.substeps = 2;
  scene.physics.step.iterations = 2;
  scene.physics.drag = 0.1;
  scene.colliders.planes = { Plane{ Vec3::Zero(), Vec3::UnitZ(), 0.2, 0.5 } };
  // A rigid shape of each kind, one of them moving, under the rope (whose links collide too).
  ColliderPlacement at;
  at.friction = 0.5;
  at.name = "ball";
  at.position = Vec3(-1.8, 0.0, 0.8);
  scene.colliders.spheres.push_back(Sphere{ at, 0.15 });
  at.name = "rod";
  at.position = Vec3(-1.5, 0.0, 0.85);
  at.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(1.5707963267948966, Vec3::UnitX()));
  at.velocity = Vec3(0.0, 0.0, 0.2);
  scene.colliders.capsules.push_back(Capsule{ at, 0.05, 0.4 });
  at.name = "block";
  at.position = Vec3(-1.2, 0.0, 0.8);
  at.velocity = Vec3::Zero();
  scene.colliders.boxes.push_back(Box{ at, Vec3(0.2, 0.3, 0.2) });
  at.name = "post";
  at.position = Vec3(-1.05, 0.0, 0.8);
  scene.colliders.cylinders.push_back(Cylinder{ at, 0.05, 0.3 });

  RopeDef rope;
  rope.nodes = 12;
  rope.from = Vec3(-2.0, 0.0, 1.0);
  rope.to = Vec3(-1.0, 0.0, 1.0);
  rope.stiffness = 500.0;
  rope.damping = 0.01;
  rope.bending = 10.0;
  rope.radius = 0.01;
  rope.pinned = { 0, -1 };
  BodyDef rope_body = buildRope("rope", rope);
  for (int i = 0; i + 1 < rope.nodes; ++i)
    rope_body.constraints.push_back(ConstraintDef{ i, i + 1, 1e-4, std::nullopt });
  rope_body.anchors = { AnchorDef{ "left", 0 }, AnchorDef{ "right", rope.nodes - 1 } };
  scene.bodies.push_back(rope_body);

  // A chain with an end mass 100 times its nodes': xpbd solves it directly (chain_solver.h).
  BodyDef chain;
  chain.name = "chain";
  for (int i = 0; i < 6; ++i)
    chain.nodes.push_back(NodeDef{ Vec3(-3.0, 0.0, 2.0 - 0.1 * i), i == 5 ? 1.0 : 0.01, Vec3::Zero(), i == 0 });
  for (int i = 0; i + 1 < 6; ++i)
    chain.springs.push_back(SpringDef{ i, i + 1, 1e4, 0.1, std::nullopt });
  scene.bodies.push_back(chain);

  ClothDef cloth;
  cloth.nx = 6;
  cloth.ny = 5;
  cloth.corners = GridCorners{ Vec3(0.0, 0.0, 1.0), Vec3(0.5, 0.0, 1.0), Vec3(0.0, 0.5, 1.0) };
  cloth.bending = SpringParameters{ 5.0, 0.0 };
  cloth.pinned = { 0 };
  BodyDef cloth_body = buildCloth("cloth", cloth);
  cloth_body.anchors = { AnchorDef{ "corner", 0 } };
  scene.bodies.push_back(cloth_body);

  JellyDef jelly;
  jelly.nx = 3;
  jelly.ny = 3;
  // 1 mm above the floor: it lands within 15 ms.
  jelly.corners = GridCorners{ Vec3(1.0, 0.0, 0.301), Vec3(1.3, 0.0, 0.301), Vec3(1.0, 0.0, 0.001) };
  scene.bodies.push_back(buildJelly("jelly", jelly));

  CreatureDef creature;
  creature.position = Vec3(3.0, 0.0, 1.0);
  creature.target = Vec3(3.3, 0.1, 1.0);
  creature.tendrils = TendrilDef{};
  scene.bodies.push_back(buildCreature("creature", creature));

  LimbDef limb;
  limb.root = Vec3(4.0, 0.0, 1.5);
  limb.direction = Vec3::UnitX();
  scene.bodies.push_back(buildLimb("limb", limb));

  HumanoidDef humanoid;
  humanoid.position = Vec3(5.0, 0.0, 1.0);
  humanoid.target = Vec3(6.0, 0.0, 1.0);
  scene.bodies.push_back(buildHumanoid("figure", humanoid));
  return scene;
}

class StepAllocation : public ::testing::TestWithParam<IntegratorType>
{
};

TEST_P(StepAllocation, NoStepAllocatesAfterTheFirst)
{
  World world = buildWorld(everyFeatureScene(GetParam()));
  const int left = *world.findAnchor("rope", "left");
  const int corner = *world.findAnchor("cloth", "corner");
  // A gripper holds the cloth's far corner and turns it (grasps.h).
  const Vec3 far_corner = world.state().position.col(world.model().bodies[2].first + 29);
  world.grasp("hand", "cloth", RigidPose{ far_corner, Eigen::Quaterniond::Identity() }, 0.05);
  world.step();  // the first step may size the integrator's scratch arrays
  // Moving anchors and grasps invalidate the integrator every sub-step; the jelly lands on the floor early on, so
  // contacts invalidate it too.
  const long allocations = allocationsOf([&] {
    for (int n = 0; n < 400; ++n)
    {
      if (n % 10 == 0)
      {
        world.moveAnchor(left, Vec3(-2.0, 0.001 * n, 1.0));
        world.moveAnchor(corner, Vec3(0.0, -0.001 * n, 1.0));
        world.setTarget("creature", Vec3(3.0 + 0.001 * n, 0.2, 1.0));
        world.moveGrasp("hand", RigidPose{ far_corner + Vec3(0.0, 0.0, 0.001 * n),
                                           Eigen::Quaterniond(Eigen::AngleAxisd(0.002 * n, Vec3::UnitX())) });
      }
      world.step();
    }
  });
  EXPECT_EQ(allocations, 0) << integratorName(GetParam());
  EXPECT_TRUE(world.state().position.allFinite());
}

// The scene above mixes bodies, so implicit_euler solves it by the sparse factorisation; ropes alone are
// chains, solved block tridiagonally (block_tridiagonal_solver.h).
TEST(StepAllocation, ImplicitEulerOnChainsAllocatesNothing)
{
  SceneDef scene;
  scene.physics.integrator = IntegratorType::ImplicitEuler;
  scene.physics.step = StepSettings{ 1.0 / 60.0, 1, 2 };
  for (int r = 0; r < 2; ++r)
  {
    RopeDef rope;
    rope.nodes = 30;
    rope.from = Vec3(0.0, r, 1.0);
    rope.to = Vec3(1.0, r, 1.0);
    rope.stiffness = 1e5;
    rope.pinned = { 0 };
    BodyDef body = buildRope("rope" + std::to_string(r), rope);
    body.anchors = { AnchorDef{ "hand", 0 } };
    scene.bodies.push_back(body);
  }
  World world = buildWorld(scene);
  const int hand = *world.findAnchor("rope0", "hand");
  world.step();
  const long allocations = allocationsOf([&] {
    for (int n = 0; n < 200; ++n)
    {
      world.moveAnchor(hand, Vec3(0.0, 0.0, 1.0 + 0.002 * n));
      world.step();
    }
  });
  EXPECT_EQ(allocations, 0);
  EXPECT_TRUE(world.state().position.allFinite());
}

// A rod (rods.h) clamped at one end, its other end anchored and turned while it moves, a grasp turning in
// its middle: bending blocks, the twists' gradients, the anchor's and the grasp's turns.
TEST(StepAllocation, ImplicitEulerOnARodTurnedByItsAnchorAndAGraspAllocatesNothing)
{
  SceneDef scene;
  scene.physics.integrator = IntegratorType::ImplicitEuler;
  scene.physics.step = StepSettings{ 0.004, 2, 1 };
  RodDef rod;
  rod.nodes = 30;
  rod.clamped = { 0 };
  BodyDef body = buildRod("cable", rod);
  body.anchors = { AnchorDef{ "tip", 29 } };
  scene.bodies.push_back(body);
  World world = buildWorld(scene);
  const int tip = *world.findAnchor("cable", "tip");
  const Vec3 middle = world.state().position.col(15);
  world.grasp("hand", "cable", RigidPose{ middle, Eigen::Quaterniond::Identity() }, 0.01);
  world.step();
  const long allocations = allocationsOf([&] {
    for (int n = 0; n < 200; ++n)
    {
      world.moveAnchor(tip, Vec3(1.0 - 0.001 * n, 0.0, 1.0), Eigen::Quaterniond(Eigen::AngleAxisd(0.05 * n, Vec3::UnitX())));
      world.moveGrasp("hand", RigidPose{ middle, Eigen::Quaterniond(Eigen::AngleAxisd(-0.02 * n, Vec3::UnitX())) });
      world.step();
    }
  });
  EXPECT_EQ(allocations, 0);
  EXPECT_TRUE(world.state().position.allFinite());
  // Turned 9.95 rad against the grasp's -3.98: the twist after the grasp counts on past whole turns (less
  // than their difference: some of the turn went into its writhe as it sagged out of line).
  EXPECT_GT(world.state().twist[15], 2.0 * M_PI);
}

// A soft solid (tetrahedra.h) landing on the floor and pressed by a moving pad, a corner anchored and a
// grasp on its far side: tetrahedron blocks, holds on colliders found, let go and kept, friction.
TEST(StepAllocation, ImplicitEulerOnAPressedSolidAllocatesNothing)
{
  SceneDef scene;
  scene.physics.integrator = IntegratorType::ImplicitEuler;
  scene.physics.step = StepSettings{ 1.0 / 120.0, 1, 2 };
  scene.colliders.planes.push_back(Plane{ Vec3::Zero(), Vec3::UnitZ(), 0.0, 0.5 });
  Box pad;
  pad.at.name = "pad";
  pad.at.position = Vec3(0.0, 0.0, 0.16);
  pad.at.velocity = Vec3(0.0, 0.0, -0.05);
  pad.at.friction = 0.5;
  pad.size = Vec3(0.2, 0.2, 0.02);
  scene.colliders.boxes.push_back(pad);
  VolumeDef box;
  box.size = Vec3(0.1, 0.1, 0.1);
  box.resolution = 0.03;
  box.position = Vec3(0.0, 0.0, 0.06);
  BodyDef body = buildVolume("box", box);
  body.anchors = { AnchorDef{ "corner", 0 } };
  scene.bodies.push_back(body);
  World world = buildWorld(scene);
  const int corner = *world.findAnchor("box", "corner");
  const Vec3 start = world.state().position.col(world.model().anchors[0].node);
  const Vec3 far_side = world.state().position.col(world.model().nodeCount() - 1);
  world.grasp("hand", "box", RigidPose{ far_side, Eigen::Quaterniond::Identity() }, 0.01);
  world.step();
  const long allocations = allocationsOf([&] {
    for (int n = 0; n < 200; ++n)
    {
      world.moveAnchor(corner, start + Vec3(0.0, 0.0, -0.0001 * n));
      world.moveGrasp("hand", RigidPose{ far_side + Vec3(0.0001 * n, 0.0, 0.0), Eigen::Quaterniond::Identity() });
      world.step();
    }
  });
  EXPECT_EQ(allocations, 0);
  EXPECT_TRUE(world.state().position.allFinite());
}

// A face-contact cloth lying on a rail thinner than its spacing, its faces held on it inside
// implicit_euler's solve (surface_holds.h) and its contact stage's face pushes after it: once it rests,
// its steps allocate nothing.
TEST(StepAllocation, ImplicitEulerOnAClothRestingOnARailByItsFacesAllocatesNothing)
{
  SceneDef scene;
  scene.physics.integrator = IntegratorType::ImplicitEuler;
  scene.physics.step = StepSettings{ 1.0 / 60.0, 1, 1 };
  scene.physics.drag = 2.0;
  Capsule rail;
  rail.at.name = "rail";
  rail.at.position = Vec3(0.0, 0.0, 0.5);
  rail.at.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2.0, Vec3::UnitY()));
  rail.at.friction = 0.5;
  rail.radius = 0.005;
  rail.length = 0.8;
  scene.colliders.capsules.push_back(rail);
  ClothDef cloth;
  cloth.nx = 11;
  cloth.ny = 11;
  cloth.corners.top_left = Vec3(-0.25, 0.275, 0.52);
  cloth.corners.top_right = Vec3(0.25, 0.275, 0.52);
  cloth.corners.bottom_left = Vec3(-0.25, -0.225, 0.52);
  cloth.mass = 0.1;
  cloth.thickness = 0.005;
  cloth.face_contacts = true;
  scene.bodies.push_back(buildCloth("cloth", cloth));
  World world = buildWorld(scene);
  while (world.time() < 3.0)
    world.step();
  ASSERT_GT(world.state().position.row(2).maxCoeff(), 0.5) << "the cloth fell off or through the rail";
  const long allocations = allocationsOf([&] {
    for (int n = 0; n < 60; ++n)
      world.step();
  });
  EXPECT_EQ(allocations, 0);
  EXPECT_TRUE(world.state().position.allFinite());
}

TEST(StepAllocation, TheCounterSeesOperatorNewAndEigen)
{
  // The interposed allocator must see what a step could allocate, or the test above proves nothing.
  EXPECT_GE(allocationsOf([] {
              int* p = new int(1);
              g_sink = p;
              delete p;
            }),
            1);
  EXPECT_GE(allocationsOf([] {
              Eigen::Matrix3Xd grown(3, 100);
              grown.setZero();
              g_sink = grown.data();
            }),
            1);
  EXPECT_GE(allocationsOf([] {
              g_sink = std::malloc(16);
              std::free(g_sink);
            }),
            1);
}

INSTANTIATE_TEST_SUITE_P(EveryIntegrator, StepAllocation,
                         ::testing::Values(IntegratorType::ExplicitEuler, IntegratorType::SemiImplicitEuler,
                                           IntegratorType::Verlet, IntegratorType::VelocityVerlet,
                                           IntegratorType::Rk4, IntegratorType::ImplicitEuler,
                                           IntegratorType::Xpbd),
                         [](const ::testing::TestParamInfo<IntegratorType>& info) {
                           return integratorName(info.param);
                         });

}  // namespace
}  // namespace soft_body_sim::test

// Cost of one physics step (Google Benchmark). "Model only what a scene needs": a plain rope must cost
// the same inside the full engine (planes, pressure, anchors, controllers all compiled in but absent
// from the scene) as in a minimal loop that knows only springs and gravity. Compare, in one run,
//   BM_RopeStepEngine/semi_implicit_euler  against  BM_RopeStepMinimalLoop
// (same rope, same scheme, same arithmetic); their ratio is the price of the unused features.
// Cloths of 100 to 100,000 nodes (BM_ClothStep/<integrator>/<nodes>) give the cost per spring update
// (items = spring updates) and how the step cost grows with the node count (scripts/bench fits the
// log-log slope); BM_ClothSpringForces is the force kernel alone on the 10,000-node cloth.
// BM_StiffRopeImplicitEuler/<nodes>: implicit Euler's direct solve on a stiff rope, 100 to 100,000 nodes;
// BM_Cable/<rod|spring_rope>/<nodes>: a cable by its material (rods.h) against the spring rope with bending
// springs of the same mass, stretching stiffness and matrix pattern, implicit_euler at 1/60 s, clamped
// (pinned) at one end; items = segments, so the two compare per segment per step.
// BM_ClothLinearSolveAt60Hz/<cheaper|direct|iterative|multigrid>/<nodes>: implicit Euler on the cloths at
// dt = 1/60 s, 100 to 100,000 nodes (direct to 10,000), its linear solve made each way (cheaper: the rule's
// choice, what a scene gets; iterative: block-Jacobi conjugate gradients; multigrid: conjugate gradients
// preconditioned by the multigrid cycle).
// Contact (BM_RopeOnColliders/<shape>/<nodes>/<colliders>): a 1000-node rope lying across 10 spheres,
// capsules, boxes or 10,000-triangle spheres as meshes, against the same rope with none (the price of contact, and that a scene without
// colliders pays nothing for them); items = node-collider pairs checked per step.
// BM_CoiledRope/<plain|self_collision>/<nodes>: a rope laid to and fro, settled on the floor, without and
// with self-collision (self_contacts.h), 1000 to 100,000 nodes; BM_CoiledRopeFalling the same while it
// falls and lands (its links moving past each other: the candidate pairs found again more often).
// BM_ClothOnSphere/<plain|self_collision>: a 64 x 64 cloth draping over a sphere, without and with
// self-collision (its nodes as balls).
// BM_SoftBox/<cheaper|direct|iterative>/<n>: a 10 cm soft box (type: volume, E = 50 kPa, nu = 0.3,
// 100 kg/m^3) hanging from its top face, implicit_euler at 1/60 s, about 1,000 to 100,000 tetrahedra, its
// linear solve made each way; items = tetrahedra, so the cost per tetrahedron per step and its growth. BM_TetKernel: the tetrahedron's force and
// projected stiffness alone (tetForcesAndStiffness), per tetrahedron, on that box sagging.
// BM_SoftStack/<touching|apart>: two 10 cm soft cubes (2.5 cm tetrahedra) on the floor at 1/60 s, one
// resting on the other (its nodes held on the lower one's surface in the solve, about 100 holds) or beside
// it: what the surface holds cost per step (World::step, settled for 2 s before timing).
// BM_ThinRodPressing/<nodes|samples_2mm|samples_1mm>: config/scenes/soft_box.yaml's 8 cm box (1.6 cm
// tetrahedra) on the floor with a 2 mm rod pressed 5 mm into its top, at 4 sub-steps of 1/60 s: what its
// surface_samples cost per step against its nodes alone (which let the rod in).
// BM_LoadedRope/<pinned|over_capsule>: a rope with loads at its ends (xpbd chains) pinned where it would
// touch a capsule, and the same rope over the capsule with friction, its contacts inside the chains' solve.
// BM_Snapshot/<rope_51|demo>/<step|snapshot_restore|bytes>: a 51-node rope (implicit_euler at 1/60 s,
// gravity) and config/scenes/demo.yaml 2 s in: one step against one World::snapshot (into the last
// snapshot's buffers) plus World::restore, and against a snapshot to bytes and back (toBytes, fromBytes,
// restore), as a file or another process takes it.
// BM_CameraFrame/<render|messages>: a 640 x 480 frame of config/scenes/demo.yaml's camera 2 s into the
// scene (sensing/depth_camera.h): the ray casting alone, and with the node's five messages made from it
// (colour, depth in millimetres and in metres, mask, organised cloud: RosConverter); items = pixels.
#include <cmath>

#include <benchmark/benchmark.h>

#include "soft_body_sim/core/bodies/cloth.h"
#include "soft_body_sim/core/bodies/rod.h"
#include "soft_body_sim/core/bodies/rope.h"
#include "soft_body_sim/core/bodies/volume.h"
#include "soft_body_sim/core/meshing/volume_mesh.h"
#include "soft_body_sim/core/elements/forces.h"
#include "soft_body_sim/core/elements/tetrahedra.h"
#include "soft_body_sim/core/sensing/depth_camera.h"
#include "soft_body_sim/ros/ros_converter.h"
#include "soft_body_sim/scene/scene_loader.h"
#include "core/integrators/integrator_kit.h"
#include "large_cloth.h"
#include "test_meshes.h"

namespace soft_body_sim
{
namespace
{
constexpr double kDt = 1e-4;

SceneDef ropeScene(int nodes, IntegratorType integrator)
{
  RopeDef rope;
  rope.nodes = nodes;
  rope.mass = 0.1;
  rope.stiffness = 1000.0;
  rope.damping = 0.01;
  rope.pinned = { 0 };
  SceneDef scene;
  scene.physics.integrator = integrator;
  scene.physics.step.dt = kDt;
  scene.bodies.push_back(buildRope("rope", rope));
  return scene;
}

void BM_RopeStepEngine(benchmark::State& bench, IntegratorType integrator)
{
  World world = buildWorld(ropeScene(static_cast<int>(bench.range(0)), integrator));
  for (auto _ : bench)
  {
    world.step();
    benchmark::DoNotOptimize(world.state().position.data());
  }
  bench.SetItemsProcessed(bench.iterations() * static_cast<int64_t>(world.model().springs.size()));
}

/// Symplectic Euler written out for springs + gravity only: the lower bound for the engine's step.
void BM_RopeStepMinimalLoop(benchmark::State& bench)
{
  const World world = buildWorld(ropeScene(static_cast<int>(bench.range(0)), IntegratorType::SemiImplicitEuler));
  const Model& model = world.model();
  State state = world.state();
  NodeArray force(3, model.nodeCount());
  const SpringArrays springs = springArrays(model);
  for (auto _ : bench)
  {
    force.setZero();
    accumulateSpringForces(springs, state.position, state.velocity, force);
    for (int i = 0; i < model.nodeCount(); ++i)
    {
      if (model.inverse_mass[i] == 0.0)
        continue;
      state.velocity.col(i) += kDt * (model.gravity + model.inverse_mass[i] * force.col(i));
      state.position.col(i) += kDt * state.velocity.col(i);
    }
    benchmark::DoNotOptimize(state.position.data());
  }
  bench.SetItemsProcessed(bench.iterations() * static_cast<int64_t>(model.springs.size()));
}

/// The benchmarks' cloth (large_cloth.h) with about `nodes` nodes, a square grid.
SceneDef clothScene(int nodes, IntegratorType integrator)
{
  return largeClothScene(static_cast<int>(std::lround(std::sqrt(static_cast<double>(nodes)))), integrator);
}

void BM_ClothStep(benchmark::State& bench, IntegratorType integrator)
{
  World world = buildWorld(clothScene(static_cast<int>(bench.range(0)), integrator));
  world.step();  // sizes the integrator's arrays
  for (auto _ : bench)
  {
    world.step();
    benchmark::DoNotOptimize(world.state().position.data());
  }
  bench.counters["nodes"] = world.model().nodeCount();
  bench.counters["springs"] = static_cast<double>(world.model().springs.size());
  bench.SetItemsProcessed(bench.iterations() * static_cast<int64_t>(world.model().springs.size()));
}

/// The same cloths at dt = 1/60 s with implicit_euler's linear solve made one way (the integrator alone,
/// stepped from the world's model and state): the crossover between the sparse factorisation and
/// conjugate gradients, and whether the rule (cheaper) picks the faster.
void BM_ClothLinearSolveAt60Hz(benchmark::State& bench, LinearSolve solve)
{
  SceneDef scene = clothScene(static_cast<int>(bench.range(0)), IntegratorType::ImplicitEuler);
  const World world = buildWorld(scene);
  const Model& model = world.model();
  State state = world.state();
  const std::unique_ptr<Integrator> integrator = makeImplicitEuler(solve);
  constexpr double h = 1.0 / 60.0;
  integrator->step(model, state, h, 1);
  for (auto _ : bench)
  {
    integrator->step(model, state, h, 1);
    benchmark::DoNotOptimize(state.position.data());
  }
  bench.counters["nodes"] = model.nodeCount();
}

/// The spring force kernel alone: every spring's Hooke + dashpot force, accumulated.
void BM_ClothSpringForces(benchmark::State& bench)
{
  const World world = buildWorld(clothScene(static_cast<int>(bench.range(0)), IntegratorType::SemiImplicitEuler));
  const Model& model = world.model();
  NodeArray force = NodeArray::Zero(3, model.nodeCount());
  const SpringArrays springs = springArrays(model);
  for (auto _ : bench)
  {
    accumulateSpringForces(springs, world.state().position, world.state().velocity, force);
    benchmark::DoNotOptimize(force.data());
  }
  bench.SetItemsProcessed(bench.iterations() * static_cast<int64_t>(model.springs.size()));
}

/// The stiff hanging rope of issue 16 at a ROS node's step: `nodes` nodes over 1 m, 0.1 kg, springs of
/// 1e6 N/m, pinned at one end, implicit_euler at dt = 1/60 s with one Newton iteration. items = nodes
/// per step: the cost per node shows whether the step is linear in the rope's length.
void BM_StiffRopeImplicitEuler(benchmark::State& bench)
{
  RopeDef rope;
  rope.nodes = static_cast<int>(bench.range(0));
  rope.mass = 0.1;
  rope.stiffness = 1e6;
  rope.pinned = { 0 };
  SceneDef scene;
  scene.physics.integrator = IntegratorType::ImplicitEuler;
  scene.physics.step = StepSettings{ 1.0 / 60.0, 1, 1 };
  scene.bodies.push_back(buildRope("rope", rope));
  World world = buildWorld(scene);
  world.step();  // the pattern is analysed on the first step
  for (auto _ : bench)
  {
    world.step();
    benchmark::DoNotOptimize(world.state().position.data());
  }
  bench.SetItemsProcessed(bench.iterations() * static_cast<int64_t>(rope.nodes));
}

/// The cable of BM_Cable: 1 m, radius 5 mm, E = 1 GPa, 1000 kg/m^3, its first node clamped, either as a rod
/// or as a spring rope of the same mass and stretching springs (E A / l) with bending springs of the same
/// stiffness to second neighbours (the same block pattern, which cannot express E I).
void BM_Cable(benchmark::State& bench, bool rod)
{
  RodDef cable;
  cable.nodes = static_cast<int>(bench.range(0));
  cable.from = Vec3(0.0, 0.0, 1.0);
  cable.to = Vec3(1.0, 0.0, 1.0);
  cable.youngs_modulus = 1e9;
  cable.clamped = { 0 };
  SceneDef scene;
  scene.physics.integrator = IntegratorType::ImplicitEuler;
  scene.physics.step = StepSettings{ 1.0 / 60.0, 1, 1 };
  BodyDef body = buildRod("cable", cable);
  if (!rod)
  {
    body.rod.reset();
    for (int i = 0; i + 2 < cable.nodes; ++i)
      body.springs.push_back(SpringDef{ i, i + 2, body.springs[0].stiffness, 0.0, std::nullopt });
  }
  scene.bodies.push_back(body);
  World world = buildWorld(scene);
  world.step();  // the pattern is analysed on the first step
  for (auto _ : bench)
  {
    world.step();
    benchmark::DoNotOptimize(world.state().position.data());
  }
  bench.SetItemsProcessed(bench.iterations() * static_cast<int64_t>(cable.nodes - 1));
}

/// The box of BM_SoftBox meshed for at most about `tetrahedra` tetrahedra (kTetsPerMaxVolume per
/// resolution^3 / (2 sqrt 2) of volume; TetGen makes about 0.6 of that on this box), hanging from its top face.
SceneDef softBox(double tetrahedra)
{
  VolumeDef box;
  box.size = Vec3(0.1, 0.1, 0.1);
  box.resolution = std::cbrt(kTetsPerMaxVolume * 2.0 * std::sqrt(2.0) * 1e-3 / tetrahedra);
  box.youngs_modulus = 5.0e4;
  box.density = 100.0;
  box.pinned_faces = { "z_max" };
  SceneDef scene;
  scene.physics.integrator = IntegratorType::ImplicitEuler;
  scene.physics.step = StepSettings{ 1.0 / 60.0, 1, 1 };
  scene.bodies.push_back(buildVolume("box", box));
  return scene;
}

/// The soft box's step with its linear solve made each way (cheaper: the rule's choice, what a scene gets).
void BM_SoftBox(benchmark::State& bench, LinearSolve solve)
{
  const World world = buildWorld(softBox(static_cast<double>(bench.range(0))));
  const Model& model = world.model();
  State state = world.state();
  const std::unique_ptr<Integrator> integrator = makeImplicitEuler(solve);
  constexpr double h = 1.0 / 60.0;
  integrator->step(model, state, h, 1);  // the pattern is analysed on the first step
  for (auto _ : bench)
  {
    integrator->step(model, state, h, 1);
    benchmark::DoNotOptimize(state.position.data());
  }
  bench.counters["tetrahedra"] = static_cast<double>(model.tetrahedra.size());
  bench.counters["nodes"] = model.nodeCount();
  bench.SetItemsProcessed(bench.iterations() * static_cast<int64_t>(model.tetrahedra.size()));
}

/// Builds `scene`, steps it `settle` times untimed, then times its steps (an item each).
void stepSettled(benchmark::State& bench, const SceneDef& scene, int settle)
{
  World world = buildWorld(scene);
  for (int step = 0; step < settle; ++step)
    world.step();
  for (auto _ : bench)
  {
    world.step();
    benchmark::DoNotOptimize(world.state().position.data());
  }
  bench.SetItemsProcessed(bench.iterations());
}

void BM_ThinRodPressing(benchmark::State& bench, double spacing)
{
  SceneDef scene;
  scene.physics.integrator = IntegratorType::ImplicitEuler;
  scene.physics.step = StepSettings{ 1.0 / 60.0, 4, 1 };
  scene.colliders.planes.push_back(Plane{ Vec3::Zero(), Vec3::UnitZ(), 0.0, 0.5 });
  VolumeDef box;
  box.size = Vec3(0.08, 0.08, 0.08);
  box.resolution = 0.016;
  box.youngs_modulus = 5.0e4;
  box.density = 200.0;
  box.friction = 0.5;
  box.position = Vec3(0.0, 0.0, 0.04);
  box.surface_samples = spacing;
  scene.bodies.push_back(buildVolume("box", box));
  Capsule rod{ {}, 0.002, 0.3 };
  rod.at.position = Vec3(0.0, 0.0, 0.08 + 0.002 - 0.005);
  rod.at.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2.0, Vec3::UnitX()));
  rod.at.friction = 0.5;
  scene.colliders.capsules.push_back(rod);
  stepSettled(bench, scene, 30);
}

void BM_SoftStack(benchmark::State& bench, bool touching)
{
  SceneDef scene;
  scene.physics.integrator = IntegratorType::ImplicitEuler;
  scene.physics.step = StepSettings{ 1.0 / 60.0, 1, 1 };
  scene.physics.drag = 5.0;
  scene.colliders.planes.push_back(Plane{ Vec3::Zero(), Vec3::UnitZ(), 0.0, 0.5 });
  VolumeDef cube;
  cube.size = Vec3(0.1, 0.1, 0.1);
  cube.resolution = 0.025;
  cube.youngs_modulus = 5.0e4;
  cube.density = 100.0;
  cube.friction = 0.5;
  cube.position = Vec3(0.0, 0.0, 0.05);
  scene.bodies.push_back(buildVolume("lower", cube));
  cube.position = touching ? Vec3(0.0, 0.0, 0.151) : Vec3(0.3, 0.0, 0.05);
  scene.bodies.push_back(buildVolume("upper", cube));
  stepSettled(bench, scene, 120);
}

void BM_TetKernel(benchmark::State& bench)
{
  World world = buildWorld(softBox(10000.0));
  for (int k = 0; k < 30; ++k)
    world.step();  // sagging: every tetrahedron strained
  const Model& model = world.model();
  const NodeArray& x = world.state().position;
  Eigen::Matrix<double, 3, 4> force;
  TetStiffness stiffness;
  for (auto _ : bench)
    for (const Tetrahedron& tet : model.tetrahedra)
    {
      tetForcesAndStiffness(tet, x, true, force, stiffness);
      benchmark::DoNotOptimize(stiffness.blocks[0].data());
    }
  bench.SetItemsProcessed(bench.iterations() * static_cast<int64_t>(model.tetrahedra.size()));
}

enum class Shape
{
  Sphere,
  Capsule,
  Box,
  Mesh
};

/// A rope of `nodes` nodes along x (1 m per 100 nodes, radius 5 mm) lying across `colliders` shapes of
/// `shape` spread evenly under it, at a ROS node's step (xpbd, 1/240 s, 4 sub-steps).
SceneDef ropeOnColliders(int nodes, int colliders, Shape shape)
{
  RopeDef rope;
  rope.nodes = nodes;
  const double length = nodes / 100.0;
  rope.from = Vec3(0, 0, 0.105);
  rope.to = Vec3(length, 0, 0.105);
  rope.mass = 0.01 * length;
  rope.stiffness = 1e4;
  rope.radius = 0.005;
  SceneDef scene;
  scene.physics.integrator = IntegratorType::Xpbd;
  scene.physics.step = StepSettings{ 1.0 / 240.0, 4, 1 };
  scene.bodies.push_back(buildRope("rope", rope));
  // The mesh: the sphere of radius 0.1 m again, as 100 x 51 facets (10,000 triangles), its field (2 mm
  // voxels) built once and shared by all of them.
  std::vector<Mesh> ball(1);
  if (shape == Shape::Mesh)
  {
    ball[0].triangles = std::make_shared<const TriangleMesh>(test::uvSphere(0.1, 100, 51));
    buildMeshFields(ball, rope.radius);
  }
  for (int k = 0; k < colliders; ++k)
  {
    ColliderPlacement at;
    at.name = "c" + std::to_string(k);
    at.position = Vec3((k + 0.5) * length / colliders, 0, 0);
    at.friction = 0.5;
    if (shape == Shape::Sphere)
      scene.colliders.spheres.push_back(Sphere{ at, 0.1 });
    else if (shape == Shape::Capsule)
    {
      at.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * M_PI, Vec3::UnitX()));  // across the rope
      scene.colliders.capsules.push_back(Capsule{ at, 0.1, 0.3 });
    }
    else if (shape == Shape::Box)
      scene.colliders.boxes.push_back(Box{ at, Vec3(0.2, 0.3, 0.2) });
    else
    {
      scene.colliders.meshes.push_back(ball[0]);
      scene.colliders.meshes.back().at = at;
    }
  }
  return scene;
}

void BM_RopeOnColliders(benchmark::State& bench, Shape shape)
{
  const int nodes = static_cast<int>(bench.range(0)), colliders = static_cast<int>(bench.range(1));
  World world = buildWorld(ropeOnColliders(nodes, colliders, shape));
  for (int n = 0; n < 240; ++n)  // one second: the rope drapes over them and the arrays are sized
    world.step();
  for (auto _ : bench)
  {
    world.step();
    benchmark::DoNotOptimize(world.state().position.data());
  }
  bench.SetItemsProcessed(bench.iterations() * static_cast<int64_t>(nodes) * std::max(colliders, 1) *
                          world.settings().substeps);
}

/// A rope of 401 nodes (5 mm links, 20 g/m) with loads of 0.5 and 1 kg at its ends, laid over a capsule
/// of radius 0.1 m and friction 0.3 (its half circle over the top, its ends hanging 0.835 m straight
/// down; the capstan ratio 2.6 > 2: it holds) or, with `over_capsule` false, the same shape with no
/// capsule and its nodes over the top pinned, where the stuck rope would be: xpbd solves the hanging
/// parts as chains (chain_solver.h) either way, and the difference is the price of the contacts inside
/// their solve (chain_contacts.h).
SceneDef loadedRope(bool over_capsule)
{
  const double radius = 0.105, link = 0.005;  // radius: the capsule's and the rope's together
  const int arc_links = static_cast<int>(std::round(M_PI * radius / link));
  const int hanging_links = static_cast<int>(std::round(0.835 / link));
  BodyDef rope;
  rope.name = "rope";
  rope.contact_radius = 0.005;
  const auto add = [&rope, link](const Vec3& x) { rope.nodes.push_back(NodeDef{ x, 0.02 * link, Vec3::Zero(), false }); };
  for (int k = hanging_links; k > 0; --k)
    add(Vec3(-radius, 0, -k * link));
  for (int k = 0; k <= arc_links; ++k)
  {
    const double angle = M_PI * (1.0 - static_cast<double>(k) / arc_links);
    add(radius * Vec3(std::cos(angle), 0, std::sin(angle)));
  }
  for (int k = 1; k <= hanging_links; ++k)
    add(Vec3(radius, 0, -k * link));
  rope.nodes.front().mass += 0.5;
  rope.nodes.back().mass += 1.0;
  if (!over_capsule)
    for (int k = 0; k <= arc_links; ++k)
      rope.nodes[static_cast<std::size_t>(hanging_links + k)].pinned = true;
  for (int i = 0; i + 1 < static_cast<int>(rope.nodes.size()); ++i)
  {
    rope.springs.push_back(SpringDef{ i, i + 1, 1e5, 0.0, std::nullopt });
    rope.contact_segments.emplace_back(i, i + 1);
  }
  SceneDef scene;
  scene.physics.integrator = IntegratorType::Xpbd;
  scene.physics.step = StepSettings{ 1.0 / 60.0, 8, 1 };
  scene.bodies.push_back(rope);
  if (over_capsule)
  {
    ColliderPlacement at;
    at.name = "pulley";
    at.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * M_PI, Vec3::UnitX()));  // across the rope
    at.friction = 0.3;
    scene.colliders.capsules.push_back(Capsule{ at, 0.1, 0.3 });
  }
  return scene;
}

void BM_LoadedRope(benchmark::State& bench, bool over_capsule)
{
  World world = buildWorld(loadedRope(over_capsule));
  for (int n = 0; n < 60; ++n)  // one second: the rope takes up its loads
    world.step();
  if (!world.takeDivergenceEvents().empty())
  {
    bench.SkipWithError("the loaded rope diverged");
    return;
  }
  for (auto _ : bench)
  {
    world.step();
    benchmark::DoNotOptimize(world.state().position.data());
  }
  bench.SetItemsProcessed(bench.iterations() * world.model().nodeCount() * world.settings().substeps);
}

/// A rope of `nodes` nodes (1 cm links, radius 3 mm) laid to and fro in rows of 1 m, 1.5 cm apart, 2 cm
/// above the floor, dropped onto it (its turns fall onto its rows): the same density at any length. With
/// or without self-collision (self_contacts.h).
SceneDef coiledRope(int nodes, bool self_collision)
{
  const double link = 0.01, spacing = 0.015;
  const int per_row = 100;
  RopeDef rope;
  rope.nodes = nodes;
  rope.mass = 0.05 * nodes * link;
  rope.stiffness = 1e4;
  rope.damping = 0.05;
  rope.radius = 0.003;
  BodyDef body = buildRope("rope", rope);
  for (int i = 0; i < nodes; ++i)
  {
    const int row = i / per_row, k = i % per_row;
    const double along = (row % 2 == 0 ? k : per_row - 1 - k) * link;
    body.nodes[static_cast<std::size_t>(i)].position = Vec3(along, row * spacing, 0.02 + 0.01 * (row % 2));
  }
  for (SpringDef& spring : body.springs)
    spring.rest_length.reset();
  body.self_collision = self_collision;
  SceneDef scene;
  scene.physics.integrator = IntegratorType::Xpbd;
  scene.physics.step = StepSettings{ 1.0 / 60.0, 8, 2 };
  scene.bodies.push_back(body);
  scene.colliders.planes.push_back(Plane{ Vec3::Zero(), Vec3::UnitZ(), 0.0, 0.5 });
  return scene;
}

void BM_CoiledRope(benchmark::State& bench, bool self_collision)
{
  World world = buildWorld(coiledRope(static_cast<int>(bench.range(0)), self_collision));
  for (int n = 0; n < 60; ++n)  // one second: the coil settles on the floor
    world.step();
  for (auto _ : bench)
  {
    world.step();
    benchmark::DoNotOptimize(world.state().position.data());
  }
  bench.SetItemsProcessed(bench.iterations() * world.model().nodeCount() * world.settings().substeps);
}

/// Steps a world built from `scene` again and again, rebuilding it (outside the timing) every `steps`
/// steps: the cost of a scene's first moments, while its bodies fall and land. Registered with a whole
/// number of those cycles as its iterations: the steps' costs differ from first to last (a cloth falling
/// flat is cheap, one lying in folds dear), and an iteration count of the library's choosing weighs them by
/// where it happens to stop (until 2026-11-27: 16 steps of the cloth folding by its triangles, 51 after a
/// change that made only its first steps cheaper, which then measured 3.6 times dearer).
void stepFirstMoments(benchmark::State& bench, const SceneDef& scene, int steps)
{
  World world = buildWorld(scene);
  int done = 0;
  for (auto _ : bench)
  {
    if (done == steps)
    {
      bench.PauseTiming();
      world = buildWorld(scene);
      done = 0;
      bench.ResumeTiming();
    }
    world.step();
    ++done;
    benchmark::DoNotOptimize(world.state().position.data());
  }
  bench.SetItemsProcessed(bench.iterations() * world.model().nodeCount() * world.settings().substeps);
}

/// The same rope while it falls and lands: the first 0.5 s after its release, again and again, so that the
/// links keep moving past each other.
void BM_CoiledRopeFalling(benchmark::State& bench, bool self_collision)
{
  stepFirstMoments(bench, coiledRope(static_cast<int>(bench.range(0)), self_collision), 30);
}

/// A 64 x 64 cloth, 1.26 m square (2 cm spacing, 8 mm thick), dropped from 0.2 m onto a sphere of 0.25 m
/// on the floor, so that it drapes and folds onto itself; each step of its first second, again and again.
/// Without self-collision, with it by its nodes as balls (self_contacts.h), or by its triangles' edges
/// and faces (face_contacts: its faces meet the sphere too). xpbd at 1/60 s, 8 sub-steps: a fall of 0.7 m
/// to the floor moves 7.7 mm per sub-step, within the thickness (tunnellingRisk).
enum class ClothCollision
{
  None,
  Nodes,
  Triangles,
};
void BM_ClothOnSphere(benchmark::State& bench, ClothCollision collision)
{
  ClothDef cloth;
  cloth.nx = 64;
  cloth.ny = 64;
  cloth.corners.top_left = Vec3(-0.63, -0.63, 0.7);
  cloth.corners.top_right = Vec3(0.63, -0.63, 0.7);
  cloth.corners.bottom_left = Vec3(-0.63, 0.63, 0.7);
  cloth.mass = 0.5;
  cloth.structural = { 1000.0, 0.05 };
  cloth.shear = { 500.0, 0.05 };
  cloth.thickness = 0.008;
  cloth.self_collision = collision != ClothCollision::None;
  cloth.face_contacts = collision == ClothCollision::Triangles;
  SceneDef scene;
  scene.physics.integrator = IntegratorType::Xpbd;
  scene.physics.step = StepSettings{ 1.0 / 60.0, 8, 2 };
  scene.bodies.push_back(buildCloth("cloth", cloth));
  scene.colliders.planes.push_back(Plane{ Vec3::Zero(), Vec3::UnitZ(), 0.0, 0.5 });
  Sphere sphere;
  sphere.at.name = "ball";
  sphere.at.position = Vec3(0.0, 0.0, 0.25);
  sphere.at.friction = 0.5;
  sphere.radius = 0.25;
  scene.colliders.spheres.push_back(sphere);
  stepFirstMoments(bench, scene, 60);
}

/// A 64 x 64 cloth, 1.26 m square (2 cm spacing, 5 mm thick), dropped from 0.1 m onto ten colliders under
/// it (four capsule rails of 5 mm, three balls, two boxes, a cylinder lying down), so that it drapes over
/// all of them; each step of its first second, again and again. Its triangles touch them with their faces
/// and edges (face_contacts.h), or, for the comparison, only its nodes do (as by default). xpbd at
/// 1/60 s, 4 sub-steps.
void BM_ClothOnColliders(benchmark::State& bench, bool faces)
{
  ClothDef cloth;
  cloth.nx = 64;
  cloth.ny = 64;
  cloth.corners.top_left = Vec3(-0.63, -0.63, 0.6);
  cloth.corners.top_right = Vec3(0.63, -0.63, 0.6);
  cloth.corners.bottom_left = Vec3(-0.63, 0.63, 0.6);
  cloth.mass = 0.5;
  cloth.structural = { 1000.0, 0.05 };
  cloth.shear = { 500.0, 0.05 };
  cloth.thickness = 0.005;
  SceneDef scene;
  scene.physics.integrator = IntegratorType::Xpbd;
  scene.physics.step = StepSettings{ 1.0 / 60.0, 4, 2 };
  cloth.face_contacts = faces;
  scene.bodies.push_back(buildCloth("cloth", cloth));
  const Eigen::Quaterniond along_x(Eigen::AngleAxisd(M_PI / 2.0, Vec3::UnitY()));
  for (int k = 0; k < 4; ++k)
  {
    Capsule rail;
    rail.at.name = "rail" + std::to_string(k);
    rail.at.position = Vec3(0.0, -0.45 + 0.3 * k, 0.45 + 0.01 * k);
    rail.at.orientation = along_x;
    rail.at.friction = 0.5;
    rail.radius = 0.005;
    rail.length = 1.4;
    scene.colliders.capsules.push_back(rail);
  }
  for (int k = 0; k < 3; ++k)
  {
    Sphere ball;
    ball.at.name = "ball" + std::to_string(k);
    ball.at.position = Vec3(-0.4 + 0.4 * k, 0.15 * (k - 1), 0.3);
    ball.at.friction = 0.5;
    ball.radius = 0.12;
    scene.colliders.spheres.push_back(ball);
  }
  for (int k = 0; k < 2; ++k)
  {
    Box box;
    box.at.name = "box" + std::to_string(k);
    box.at.position = Vec3(-0.35 + 0.7 * k, 0.4, 0.2);
    box.at.friction = 0.5;
    box.size = Vec3(0.3, 0.2, 0.4);
    scene.colliders.boxes.push_back(box);
  }
  Cylinder roller;
  roller.at.name = "roller";
  roller.at.position = Vec3(0.0, -0.3, 0.3);
  roller.at.orientation = along_x;
  roller.at.friction = 0.5;
  roller.radius = 0.05;
  roller.length = 1.0;
  scene.colliders.cylinders.push_back(roller);
  stepFirstMoments(bench, scene, 60);
}

/// The world of BM_Snapshot: a 51-node rope (0.1 kg, 1000 N/m per segment) hanging from one end, implicit
/// Euler at 1/60 s under gravity, or the demo scene 2 s in.
World snapshotWorld(bool demo)
{
  if (demo)
  {
    World world = buildWorld(loadSceneFile(SOURCE_DIR "/config/scenes/demo.yaml"));
    while (world.time() < 2.0)
      world.step();
    return world;
  }
  SceneDef scene = ropeScene(51, IntegratorType::ImplicitEuler);
  scene.physics.step.dt = 1.0 / 60.0;
  World world = buildWorld(scene);
  for (int n = 0; n < 60; ++n)
    world.step();
  return world;
}

enum class SnapshotWork
{
  Step,
  SnapshotRestore,
  Bytes
};

void BM_Snapshot(benchmark::State& bench, bool demo, SnapshotWork work)
{
  World world = snapshotWorld(demo);
  const WorldSnapshot moment = world.snapshot();
  WorldSnapshot now = world.snapshot();
  for (auto _ : bench)
  {
    if (work == SnapshotWork::SnapshotRestore)
    {
      world.snapshot(now);  // as a planner takes one each cycle, into the last one's buffers
      world.restore(now);
    }
    else if (work == SnapshotWork::Bytes)
      world.restore(WorldSnapshot::fromBytes(world.snapshot().toBytes()));
    else
    {
      world.step();
      bench.PauseTiming();
      world.restore(moment);  // every timed step from the same moment
      bench.ResumeTiming();
    }
    benchmark::DoNotOptimize(world.state().position.data());
  }
}

/// The demo's camera on the demo scene 2 s in (its bodies settled, the jelly landed).
void BM_CameraFrame(benchmark::State& bench, bool messages)
{
  const SceneDef scene = loadSceneFile(SOURCE_DIR "/config/scenes/demo.yaml");
  World world = buildWorld(scene);
  while (world.time() < 2.0)
    world.step();
  const CameraDef& def = scene.cameras.at(0);
  DepthCamera camera(def, world.model());
  const RigidPose link{ def.position, def.orientation.normalized() };
  const std::vector<ColliderPose> colliders = world.colliderPoses();
  std_msgs::Header header;
  header.frame_id = def.name + "_color_optical_frame";
  CameraImage image;
  std::uint64_t frame = 0;
  for (auto _ : bench)
  {
    camera.render(world.state(), colliders, link, frame++, image);
    if (messages)
    {
      benchmark::DoNotOptimize(RosConverter::toCameraInfo(camera.intrinsics(), header));
      benchmark::DoNotOptimize(RosConverter::toColorImage(image, header));
      benchmark::DoNotOptimize(RosConverter::toDepthMillimetres(image, header));
      benchmark::DoNotOptimize(RosConverter::toDepthMetres(image, header));
      benchmark::DoNotOptimize(RosConverter::toMask(image, header));
      benchmark::DoNotOptimize(RosConverter::toPointCloud(image, camera.intrinsics(), header));
    }
    benchmark::DoNotOptimize(image.depth.data());
  }
  bench.SetItemsProcessed(bench.iterations() * image.width * image.height);
}

/// Node counts from 100 to 100,000, two per decade.
void clothSizes(benchmark::internal::Benchmark* bench)
{
  for (int nodes : { 100, 316, 1000, 3162, 10000, 31623, 100000 })
    bench->Arg(nodes);
}

BENCHMARK(BM_RopeStepMinimalLoop)->Arg(100)->Arg(1000);
BENCHMARK_CAPTURE(BM_RopeStepEngine, semi_implicit_euler, IntegratorType::SemiImplicitEuler)->Arg(100)->Arg(1000);
BENCHMARK_CAPTURE(BM_RopeStepEngine, explicit_euler, IntegratorType::ExplicitEuler)->Arg(100)->Arg(1000);
BENCHMARK_CAPTURE(BM_RopeStepEngine, verlet, IntegratorType::Verlet)->Arg(100)->Arg(1000);
BENCHMARK_CAPTURE(BM_RopeStepEngine, velocity_verlet, IntegratorType::VelocityVerlet)->Arg(100)->Arg(1000);
BENCHMARK_CAPTURE(BM_RopeStepEngine, rk4, IntegratorType::Rk4)->Arg(100)->Arg(1000);
BENCHMARK_CAPTURE(BM_RopeStepEngine, implicit_euler, IntegratorType::ImplicitEuler)->Arg(100)->Arg(1000);
BENCHMARK_CAPTURE(BM_RopeStepEngine, xpbd, IntegratorType::Xpbd)->Arg(100)->Arg(1000);
BENCHMARK_CAPTURE(BM_ClothStep, semi_implicit_euler, IntegratorType::SemiImplicitEuler)->Apply(clothSizes);
BENCHMARK_CAPTURE(BM_ClothStep, xpbd, IntegratorType::Xpbd)->Apply(clothSizes);
BENCHMARK_CAPTURE(BM_ClothStep, implicit_euler, IntegratorType::ImplicitEuler)->Apply(clothSizes);
BENCHMARK_CAPTURE(BM_ClothLinearSolveAt60Hz, cheaper, LinearSolve::Cheaper)->Arg(100)->Arg(316)->Arg(1000)->Arg(3162)->Arg(10000)->Arg(31623)->Arg(100000)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ClothLinearSolveAt60Hz, direct, LinearSolve::Direct)->Arg(100)->Arg(316)->Arg(1000)->Arg(3162)->Arg(10000)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ClothLinearSolveAt60Hz, iterative, LinearSolve::Iterative)->Arg(100)->Arg(316)->Arg(1000)->Arg(3162)->Arg(10000)->Arg(31623)->Arg(100000)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ClothLinearSolveAt60Hz, multigrid, LinearSolve::Multigrid)->Arg(100)->Arg(316)->Arg(1000)->Arg(3162)->Arg(10000)->Arg(31623)->Arg(100000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ClothSpringForces)->Arg(10000);
BENCHMARK(BM_StiffRopeImplicitEuler)->Arg(100)->Arg(1000)->Arg(10000)->Arg(100000);
BENCHMARK_CAPTURE(BM_Cable, rod, true)->Arg(100)->Arg(1000)->Arg(10000);
BENCHMARK_CAPTURE(BM_Cable, spring_rope, false)->Arg(100)->Arg(1000)->Arg(10000);
BENCHMARK_CAPTURE(BM_RopeOnColliders, sphere, Shape::Sphere)->Args({ 1000, 0 })->Args({ 1000, 10 });
BENCHMARK_CAPTURE(BM_RopeOnColliders, capsule, Shape::Capsule)->Args({ 1000, 10 });
BENCHMARK_CAPTURE(BM_RopeOnColliders, box, Shape::Box)->Args({ 1000, 10 });
BENCHMARK_CAPTURE(BM_RopeOnColliders, mesh_10k_triangles, Shape::Mesh)->Args({ 1000, 10 });
BENCHMARK_CAPTURE(BM_CoiledRope, plain, false)->Arg(1000)->Arg(10000)->Arg(100000);
BENCHMARK_CAPTURE(BM_CoiledRope, self_collision, true)->Arg(1000)->Arg(10000)->Arg(100000);
BENCHMARK_CAPTURE(BM_CoiledRopeFalling, plain, false)->Arg(1000)->Arg(10000)->Iterations(30);
BENCHMARK_CAPTURE(BM_CoiledRopeFalling, self_collision, true)->Arg(1000)->Arg(10000)->Iterations(30);
// Two whole drops each (the cost of a step changes as the cloth lands).
BENCHMARK_CAPTURE(BM_ClothOnColliders, nodes_only, false)->Iterations(120)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ClothOnColliders, faces, true)->Iterations(120)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ClothOnSphere, plain, ClothCollision::None)->Iterations(60)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ClothOnSphere, self_collision, ClothCollision::Nodes)->Iterations(60)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ClothOnSphere, triangles, ClothCollision::Triangles)->Iterations(60)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SoftBox, cheaper, LinearSolve::Cheaper)->Arg(1700)->Arg(4000)->Arg(8000)->Arg(17000)->Arg(170000)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SoftBox, direct, LinearSolve::Direct)->Arg(1700)->Arg(4000)->Arg(8000)->Arg(17000)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SoftBox, iterative, LinearSolve::Iterative)->Arg(1700)->Arg(4000)->Arg(8000)->Arg(17000)->Arg(170000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_TetKernel);
BENCHMARK_CAPTURE(BM_SoftStack, touching, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SoftStack, apart, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ThinRodPressing, nodes, 0.0)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ThinRodPressing, samples_2mm, 0.002)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ThinRodPressing, samples_1mm, 0.001)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LoadedRope, pinned, false);
BENCHMARK_CAPTURE(BM_LoadedRope, over_capsule, true);
BENCHMARK_CAPTURE(BM_Snapshot, rope_51/step, false, SnapshotWork::Step)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Snapshot, rope_51/snapshot_restore, false, SnapshotWork::SnapshotRestore)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Snapshot, rope_51/bytes, false, SnapshotWork::Bytes)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Snapshot, demo/step, true, SnapshotWork::Step)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Snapshot, demo/snapshot_restore, true, SnapshotWork::SnapshotRestore)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Snapshot, demo/bytes, true, SnapshotWork::Bytes)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_CameraFrame, render, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_CameraFrame, messages, true)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace soft_body_sim

BENCHMARK_MAIN();

// Scene loader: a valid scene becomes exactly the expected structs; every invalid one is rejected with
// a one-line message "<source>:<line>: <key path>: <reason>" that points at the offending value.
#include "soft_body_sim/scene/scene_loader.h"
#include "scene_error.h"
#include "soft_body_sim/core/contact/contact_stage.h"
#include "soft_body_sim/core/contact/mesh_field.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <string>
#include <vector>

namespace soft_body_sim
{
namespace
{

std::string sceneDir() { return std::string(SOURCE_DIR) + "/config/scenes"; }

void expectVec3(const Vec3& actual, double x, double y, double z)
{
  EXPECT_EQ(actual, Vec3(x, y, z)) << "actual: " << actual.transpose();
}

// --- valid scenes ------------------------------------------------------------------------------

const char* const kContractExample = R"(frame_id: world
physics:
  integrator: semi_implicit_euler
  dt: 0.001
  substeps: 1
  iterations: 1
  gravity: [0.0, 0.0, -9.81]
  drag: 0.0
bodies:
  - name: pair
    type: custom
    nodes:
      - {position: [2, 4, 0], mass: 1}
      - {position: [1, -3, 0], mass: 1, velocity: [0, 0, 0], pinned: false}
    springs:
      - {nodes: [0, 1], stiffness: 2, rest_length: 4, damping: 0}
    constraints:
      - {nodes: [0, 1], compliance: 0.0}
)";

TEST(SceneLoader, ContractExampleParsesToTheExpectedStructs)
{
  const SceneDef scene = parseScene(kContractExample, "example.yaml");
  EXPECT_EQ(scene.frame_id, "world");
  EXPECT_EQ(scene.physics.integrator, IntegratorType::SemiImplicitEuler);
  EXPECT_EQ(scene.physics.step.dt, 0.001);
  EXPECT_EQ(scene.physics.step.substeps, 1);
  EXPECT_EQ(scene.physics.step.iterations, 1);
  expectVec3(scene.physics.gravity, 0.0, 0.0, -9.81);
  EXPECT_EQ(scene.physics.drag, 0.0);

  ASSERT_EQ(scene.bodies.size(), 1u);
  const BodyDef& body = scene.bodies[0];
  EXPECT_EQ(body.name, "pair");
  EXPECT_EQ(body.type, "custom");
  ASSERT_EQ(body.nodes.size(), 2u);
  expectVec3(body.nodes[0].position, 2.0, 4.0, 0.0);
  EXPECT_EQ(body.nodes[0].mass, 1.0);
  expectVec3(body.nodes[0].velocity, 0.0, 0.0, 0.0);
  EXPECT_FALSE(body.nodes[0].pinned);
  expectVec3(body.nodes[1].position, 1.0, -3.0, 0.0);
  EXPECT_EQ(body.nodes[1].mass, 1.0);
  expectVec3(body.nodes[1].velocity, 0.0, 0.0, 0.0);
  EXPECT_FALSE(body.nodes[1].pinned);

  ASSERT_EQ(body.springs.size(), 1u);
  EXPECT_EQ(body.springs[0].a, 0);
  EXPECT_EQ(body.springs[0].b, 1);
  EXPECT_EQ(body.springs[0].stiffness, 2.0);
  EXPECT_EQ(body.springs[0].damping, 0.0);
  ASSERT_TRUE(body.springs[0].rest_length.has_value());
  EXPECT_EQ(*body.springs[0].rest_length, 4.0);

  ASSERT_EQ(body.constraints.size(), 1u);
  EXPECT_EQ(body.constraints[0].a, 0);
  EXPECT_EQ(body.constraints[0].b, 1);
  EXPECT_EQ(body.constraints[0].compliance, 0.0);
  EXPECT_FALSE(body.constraints[0].rest_length.has_value());
}

TEST(SceneLoader, DefaultsFillEveryOptionalKey)
{
  const SceneDef scene = parseScene(R"(bodies:
  - name: lone
    type: custom
    nodes:
      - {position: [1, 2, 3], mass: 0.5}
      - {position: [0, 0, 0], mass: 2}
    springs:
      - {nodes: [1, 0], stiffness: 10}
)",
                                    "defaults.yaml");
  const PhysicsDef defaults;
  EXPECT_EQ(scene.frame_id, "world");
  EXPECT_EQ(scene.physics.integrator, IntegratorType::SemiImplicitEuler);
  EXPECT_EQ(scene.physics.step.dt, 0.001);
  EXPECT_EQ(scene.physics.step.substeps, 1);
  EXPECT_EQ(scene.physics.step.iterations, 1);
  expectVec3(scene.physics.gravity, 0.0, 0.0, -9.81);
  EXPECT_EQ(scene.physics.drag, 0.0);
  EXPECT_EQ(scene.physics.step.dt, defaults.step.dt);

  ASSERT_EQ(scene.bodies.size(), 1u);
  const BodyDef& body = scene.bodies[0];
  ASSERT_EQ(body.nodes.size(), 2u);
  expectVec3(body.nodes[0].position, 1.0, 2.0, 3.0);
  EXPECT_EQ(body.nodes[0].mass, 0.5);
  expectVec3(body.nodes[0].velocity, 0.0, 0.0, 0.0);
  EXPECT_FALSE(body.nodes[0].pinned);
  ASSERT_EQ(body.springs.size(), 1u);
  EXPECT_EQ(body.springs[0].a, 1);
  EXPECT_EQ(body.springs[0].b, 0);
  EXPECT_EQ(body.springs[0].damping, 0.0);
  EXPECT_FALSE(body.springs[0].rest_length.has_value());
  EXPECT_TRUE(body.constraints.empty());
}

TEST(SceneLoader, EveryPhysicsKeyAndNodeKeyIsRead)
{
  const SceneDef scene = parseScene(R"(frame_id: map
physics:
  integrator: xpbd
  dt: 0.02
  substeps: 4
  iterations: 12
  gravity: [0, -1.62, 0]
  drag: 0.25
bodies:
  - name: a
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1, velocity: [1, -2, 3.5], pinned: true}
      - {position: [0, 1, 0], mass: 1, pinned: True}
      - {position: [0, 2, 0], mass: 1, pinned: FALSE}
    springs:
      - {nodes: [0, 2], stiffness: 5, damping: 0.5}
    constraints:
      - {nodes: [2, 1], compliance: 0.001, rest_length: 0}
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 1], mass: 3}
)",
                                    "full.yaml");
  EXPECT_EQ(scene.frame_id, "map");
  EXPECT_EQ(scene.physics.integrator, IntegratorType::Xpbd);
  EXPECT_EQ(scene.physics.step.dt, 0.02);
  EXPECT_EQ(scene.physics.step.substeps, 4);
  EXPECT_EQ(scene.physics.step.iterations, 12);
  expectVec3(scene.physics.gravity, 0.0, -1.62, 0.0);
  EXPECT_EQ(scene.physics.drag, 0.25);
  ASSERT_EQ(scene.bodies.size(), 2u);
  const BodyDef& a = scene.bodies[0];
  expectVec3(a.nodes[0].velocity, 1.0, -2.0, 3.5);
  EXPECT_TRUE(a.nodes[0].pinned);
  EXPECT_TRUE(a.nodes[1].pinned);
  EXPECT_FALSE(a.nodes[2].pinned);
  EXPECT_EQ(a.springs[0].damping, 0.5);
  EXPECT_EQ(a.constraints[0].a, 2);
  EXPECT_EQ(a.constraints[0].b, 1);
  EXPECT_EQ(a.constraints[0].compliance, 0.001);
  ASSERT_TRUE(a.constraints[0].rest_length.has_value());
  EXPECT_EQ(*a.constraints[0].rest_length, 0.0);
  EXPECT_EQ(scene.bodies[1].name, "b");
  EXPECT_EQ(scene.bodies[1].nodes[0].mass, 3.0);
}

TEST(SceneLoader, EveryIntegratorNameIsAccepted)
{
  for (const std::string& name : integratorNames())
  {
    const SceneDef scene =
        parseScene("physics: {integrator: " + name +
                       "}\nbodies: [{name: b, type: custom, nodes: [{position: [0, 0, 0], mass: 1}]}]\n",
                   "integrator.yaml");
    EXPECT_EQ(integratorName(scene.physics.integrator), name);
  }
}

TEST(SceneLoader, TrailingEmptyDocumentIsAccepted)
{
  const SceneDef scene =
      parseScene("bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 0], mass: 1}]}]\n---\n# empty\n",
                 "trailing.yaml");
  EXPECT_EQ(scene.bodies.size(), 1u);
}

TEST(SceneLoader, EmptySpringAndConstraintListsAreAccepted)
{
  const SceneDef scene = parseScene(R"(bodies:
  - {name: b, type: custom, nodes: [{position: [0, 0, 0], mass: 1}], springs: [], constraints: []}
)",
                                    "empty_lists.yaml");
  EXPECT_TRUE(scene.bodies[0].springs.empty());
  EXPECT_TRUE(scene.bodies[0].constraints.empty());
}

// --- invalid scenes ----------------------------------------------------------------------------

struct BadScene
{
  const char* name;      ///< the test's name: says what is wrong
  const char* yaml;      ///< starts right after R"( so that its first line is line 1
  const char* location;  ///< the message's start, "bad.yaml:<line>: <key path>"
  std::vector<std::string> reason_words;
};

void PrintTo(const BadScene& bad, std::ostream* out) { *out << bad.name; }

// Most cases edit one line of this minimal valid scene (nodes on lines 5 and 6, springs from line 8).
//   1 bodies:
//   2   - name: b
//   3     type: custom
//   4     nodes:
//   5       - {position: [0, 0, 0], mass: 1}
//   6       - {position: [1, 0, 0], mass: 1}
//   7     springs:
//   8       - {nodes: [0, 1], stiffness: 1}
const BadScene kBadScenes[] = {
  // --- unknown keys
  { "UnknownTopLevelKey", R"(frame: world
bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 0], mass: 1}]}]
)",
    "bad.yaml:1: frame", { "unknown key 'frame'", "frame_id, rate, physics, planes, colliders, robot_colliders, cameras, bodies" } },
  { "UnknownPhysicsKey", R"(physics:
  dt: 0.01
  timestep: 0.01
bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 0], mass: 1}]}]
)",
    "bad.yaml:3: physics.timestep",
    { "unknown key 'timestep'", "integrator, dt, substeps, iterations, gravity, drag" } },
  { "UnknownBodyKey", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1}
    spring: []
)",
    "bad.yaml:6: bodies[0].spring", { "unknown key 'spring'", "name, type, nodes, springs, constraints" } },
  { "UnknownNodeKey", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1}
      - {position: [1, 0, 0], mas: 1}
)",
    "bad.yaml:6: bodies[0].nodes[1].mas", { "unknown key 'mas'", "position, mass, velocity, pinned" } },
  { "UnknownSpringKey", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1}
      - {position: [1, 0, 0], mass: 1}
    springs:
      - {nodes: [0, 1], stiffness: 1, rest: 4}
)",
    "bad.yaml:8: bodies[0].springs[0].rest", { "unknown key 'rest'", "nodes, stiffness, damping, rest_length" } },
  { "UnknownConstraintKey", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1}
      - {position: [1, 0, 0], mass: 1}
    constraints:
      - {nodes: [0, 1], stiffness: 1}
)",
    "bad.yaml:8: bodies[0].constraints[0].stiffness",
    { "unknown key 'stiffness'", "nodes, compliance, rest_length" } },
  { "DuplicateKey", R"(physics:
  dt: 0.01
  dt: 0.02
bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 0], mass: 1}]}]
)",
    "bad.yaml:3: physics.dt", { "duplicate key" } },
  { "NonStringKey", R"(physics:
  [dt]: 0.01
bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 0], mass: 1}]}]
)",
    "bad.yaml:2: physics", { "keys must be strings", "a list" } },

  // --- wrong types
  { "DtIsAWord", R"(physics:
  dt: fast
bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 0], mass: 1}]}]
)",
    "bad.yaml:2: physics.dt", { "expected a number", "'fast'" } },
  { "DtIsAQuotedNumber", R"(physics:
  dt: "0.01"
bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 0], mass: 1}]}]
)",
    "bad.yaml:2: physics.dt", { "expected a number", "quoted string" } },
  { "DtIsEmpty", R"(physics:
  dt:
bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 0], mass: 1}]}]
)",
    "bad.yaml:2: physics.dt", { "expected a number", "empty value" } },
  { "PhysicsIsAList", R"(physics: [0.01]
bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 0], mass: 1}]}]
)",
    "bad.yaml:1: physics", { "expected a mapping", "a list" } },
  { "BodiesIsAScalar", R"(bodies: pair
)",
    "bad.yaml:1: bodies", { "expected a list", "'pair'" } },
  { "BodyIsAScalar", R"(bodies:
  - pair
)",
    "bad.yaml:2: bodies[0]", { "expected a mapping", "'pair'" } },
  { "NodesIsAMapping", R"(bodies:
  - name: b
    type: custom
    nodes: {position: [0, 0, 0], mass: 1}
)",
    "bad.yaml:4: bodies[0].nodes", { "expected a list", "a mapping" } },
  { "SpringsIsAScalar", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1}
    springs: none
)",
    "bad.yaml:6: bodies[0].springs", { "expected a list", "'none'" } },
  { "PositionHasTwoNumbers", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0], mass: 1}
)",
    "bad.yaml:5: bodies[0].nodes[0].position", { "3 numbers", "2 item" } },
  { "PositionIsAScalar", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: 1, mass: 1}
)",
    "bad.yaml:5: bodies[0].nodes[0].position", { "expected a list of 3 numbers", "'1'" } },
  { "VelocityComponentIsAWord", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1, velocity: [0, 0, up]}
)",
    "bad.yaml:5: bodies[0].nodes[0].velocity[2]", { "expected a number", "'up'" } },
  { "GravityHasFourNumbers", R"(physics:
  gravity: [0, 0, -9.81, 0]
bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 0], mass: 1}]}]
)",
    "bad.yaml:2: physics.gravity", { "3 numbers", "4 item" } },
  { "MassIsAList", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: [1]}
)",
    "bad.yaml:5: bodies[0].nodes[0].mass", { "expected a number", "a list" } },
  { "PinnedIsMaybe", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1, pinned: maybe}
)",
    "bad.yaml:5: bodies[0].nodes[0].pinned", { "true or false", "'maybe'" } },
  { "PinnedIsYes", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1, pinned: yes}
)",
    "bad.yaml:5: bodies[0].nodes[0].pinned", { "true or false", "'yes'" } },
  { "PinnedIsOne", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1, pinned: 1}
)",
    "bad.yaml:5: bodies[0].nodes[0].pinned", { "true or false", "'1'" } },
  { "SpringIndexIsFractional", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1}
      - {position: [1, 0, 0], mass: 1}
    springs:
      - {nodes: [0, 1.5], stiffness: 1}
)",
    "bad.yaml:8: bodies[0].springs[0].nodes[1]", { "must be an integer", "'1.5'" } },
  { "SpringIndexIsAWord", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1}
      - {position: [1, 0, 0], mass: 1}
    springs:
      - {nodes: [first, 1], stiffness: 1}
)",
    "bad.yaml:8: bodies[0].springs[0].nodes[0]", { "expected an integer", "'first'" } },
  { "SpringHasThreeIndices", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1}
      - {position: [1, 0, 0], mass: 1}
    springs:
      - {nodes: [0, 1, 0], stiffness: 1}
)",
    "bad.yaml:8: bodies[0].springs[0].nodes", { "2 node indices", "3 item" } },
  { "SubstepsIsFractional", R"(physics:
  substeps: 2.5
bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 0], mass: 1}]}]
)",
    "bad.yaml:2: physics.substeps", { "must be an integer", "'2.5'" } },
  { "IterationsIsAWord", R"(physics:
  iterations: many
bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 0], mass: 1}]}]
)",
    "bad.yaml:2: physics.iterations", { "expected an integer", "'many'" } },
  { "NameIsAList", R"(bodies:
  - name: [b]
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1}
)",
    "bad.yaml:2: bodies[0].name", { "expected a string", "a list" } },

  // --- missing required keys
  { "MissingBodies", R"(frame_id: world
physics: {dt: 0.01}
)",
    "bad.yaml:1: bodies", { "missing required key" } },
  { "MissingName", R"(bodies:
  - type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1}
)",
    "bad.yaml:2: bodies[0].name", { "missing required key" } },
  { "MissingType", R"(bodies:
  - name: b
    nodes:
      - {position: [0, 0, 0], mass: 1}
)",
    "bad.yaml:2: bodies[0].type", { "missing required key" } },
  { "MissingNodes", R"(bodies:
  - name: b
    type: custom
)",
    "bad.yaml:2: bodies[0].nodes", { "missing required key" } },
  { "MissingPosition", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {mass: 1}
)",
    "bad.yaml:5: bodies[0].nodes[0].position", { "missing required key" } },
  { "MissingMass", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0]}
)",
    "bad.yaml:5: bodies[0].nodes[0].mass", { "missing required key" } },
  { "MissingSpringNodes", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1}
      - {position: [1, 0, 0], mass: 1}
    springs:
      - {stiffness: 1}
)",
    "bad.yaml:8: bodies[0].springs[0].nodes", { "missing required key" } },
  { "MissingStiffness", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1}
      - {position: [1, 0, 0], mass: 1}
    springs:
      - {nodes: [0, 1], damping: 1}
)",
    "bad.yaml:8: bodies[0].springs[0].stiffness", { "missing required key" } },
  { "MissingConstraintNodes", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1}
      - {position: [1, 0, 0], mass: 1}
    constraints:
      - {compliance: 0}
)",
    "bad.yaml:8: bodies[0].constraints[0].nodes", { "missing required key" } },

  // --- values out of range
  { "ZeroMass", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1}
      - {position: [1, 0, 0], mass: 0}
)",
    "bad.yaml:6: bodies[0].nodes[1].mass", { "must be > 0", "got 0" } },
  { "NegativeMass", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: -1.5}
)",
    "bad.yaml:5: bodies[0].nodes[0].mass", { "must be > 0", "got -1.5" } },
  { "ZeroDt", R"(physics:
  dt: 0
bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 0], mass: 1}]}]
)",
    "bad.yaml:2: physics.dt", { "must be > 0" } },
  { "NegativeDt", R"(physics:
  dt: -0.01
bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 0], mass: 1}]}]
)",
    "bad.yaml:2: physics.dt", { "must be > 0", "-0.01" } },
  { "ZeroSubsteps", R"(physics:
  substeps: 0
bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 0], mass: 1}]}]
)",
    "bad.yaml:2: physics.substeps", { "[1, ", "got 0" } },
  { "ZeroIterations", R"(physics:
  iterations: 0
bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 0], mass: 1}]}]
)",
    "bad.yaml:2: physics.iterations", { "[1, ", "got 0" } },
  { "SubstepsBeyondInt", R"(physics:
  substeps: 99999999999
bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 0], mass: 1}]}]
)",
    "bad.yaml:2: physics.substeps", { "[1, 2147483647]" } },
  { "NegativeDrag", R"(physics:
  drag: -0.1
bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 0], mass: 1}]}]
)",
    "bad.yaml:2: physics.drag", { "must be >= 0", "-0.1" } },
  { "ZeroStiffness", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1}
      - {position: [1, 0, 0], mass: 1}
    springs:
      - {nodes: [0, 1], stiffness: 0}
)",
    "bad.yaml:8: bodies[0].springs[0].stiffness", { "must be > 0" } },
  { "NegativeStiffness", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1}
      - {position: [1, 0, 0], mass: 1}
    springs:
      - {nodes: [0, 1], stiffness: -3}
)",
    "bad.yaml:8: bodies[0].springs[0].stiffness", { "must be > 0", "-3" } },
  { "NegativeDamping", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1}
      - {position: [1, 0, 0], mass: 1}
    springs:
      - {nodes: [0, 1], stiffness: 1, damping: -0.5}
)",
    "bad.yaml:8: bodies[0].springs[0].damping", { "must be >= 0", "-0.5" } },
  { "NegativeSpringRestLength", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1}
      - {position: [1, 0, 0], mass: 1}
    springs:
      - {nodes: [0, 1], stiffness: 1, rest_length: -1}
)",
    "bad.yaml:8: bodies[0].springs[0].rest_length", { "must be >= 0", "-1" } },
  { "NegativeCompliance", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1}
      - {position: [1, 0, 0], mass: 1}
    constraints:
      - {nodes: [0, 1], compliance: -0.001}
)",
    "bad.yaml:8: bodies[0].constraints[0].compliance", { "must be >= 0", "-0.001" } },
  { "NegativeConstraintRestLength", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1}
      - {position: [1, 0, 0], mass: 1}
    constraints:
      - {nodes: [0, 1], rest_length: -0.2}
)",
    "bad.yaml:8: bodies[0].constraints[0].rest_length", { "must be >= 0", "-0.2" } },

  // --- work per step of the procedurally animated bodies (kMaxUpdatesPerStep, kMaxRelaxationPasses)
  { "CreatureIterationsOverTheLimit", R"(bodies: [{name: c, type: creature, iterations: 101}]
)",
    "bad.yaml:1: bodies[0].iterations", { "[1, 100]", "101" } },
  { "LimbIterationsOverTheLimit", R"(bodies: [{name: l, type: limb, iterations: 1000000}]
)",
    "bad.yaml:1: bodies[0].iterations", { "[1, 100]", "1000000" } },
  { "HumanoidMaxFramesPerStepOverTheLimit", R"(bodies: [{name: h, type: humanoid, max_frames_per_step: 1e9}]
)",
    "bad.yaml:1: bodies[0].max_frames_per_step", { "(0, 100]", "1e9" } },
  { "CreatureUpdatePeriodFarBelowDt", R"(physics: {dt: 0.01}
bodies: [{name: c, type: creature, update_period: 1e-9}]
)",
    "bad.yaml:2: bodies[0].update_period",
    { "physics.dt / update_period = 1e+07 updates per physics step", "more than 100" } },
  { "CreatureDtFarAboveTheDefaultPeriod", R"(physics: {dt: 10}
bodies: [{name: c, type: creature}]
)",
    "bad.yaml:2: bodies[0]", { "physics.dt / update_period = 300 updates per physics step" } },

  // --- non-finite numbers
  { "NanMass", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: .nan}
)",
    "bad.yaml:5: bodies[0].nodes[0].mass", { "finite", ".nan" } },
  { "InfiniteDt", R"(physics:
  dt: .inf
bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 0], mass: 1}]}]
)",
    "bad.yaml:2: physics.dt", { "finite", ".inf" } },
  { "NegativeInfiniteGravity", R"(physics:
  gravity: [0, 0, -.inf]
bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 0], mass: 1}]}]
)",
    "bad.yaml:2: physics.gravity[2]", { "finite", "-.inf" } },
  { "NanPosition", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [.NaN, 0, 0], mass: 1}
)",
    "bad.yaml:5: bodies[0].nodes[0].position[0]", { "finite" } },
  { "InfiniteRestLength", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1}
      - {position: [1, 0, 0], mass: 1}
    springs:
      - {nodes: [0, 1], stiffness: 1, rest_length: .inf}
)",
    "bad.yaml:8: bodies[0].springs[0].rest_length", { "finite" } },

  // --- node indices
  { "SpringIndexOutOfRange", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1}
      - {position: [1, 0, 0], mass: 1}
    springs:
      - {nodes: [0, 1], stiffness: 1}
      - {nodes: [1, 2], stiffness: 1}
)",
    "bad.yaml:9: bodies[0].springs[1].nodes[1]", { "node index 2 out of range", "2 nodes" } },
  { "SpringIndexNegative", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1}
      - {position: [1, 0, 0], mass: 1}
    springs:
      - {nodes: [-1, 1], stiffness: 1}
)",
    "bad.yaml:8: bodies[0].springs[0].nodes[0]", { "node index -1 out of range", "2 nodes" } },
  { "ConstraintIndexOutOfRange", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1}
      - {position: [1, 0, 0], mass: 1}
    constraints:
      - {nodes: [5, 0]}
)",
    "bad.yaml:8: bodies[0].constraints[0].nodes[0]", { "node index 5 out of range", "2 nodes" } },
  { "SpringFromANodeToItself", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1}
      - {position: [1, 0, 0], mass: 1}
    springs:
      - {nodes: [1, 1], stiffness: 1}
)",
    "bad.yaml:8: bodies[0].springs[0].nodes", { "connects node 1 to itself" } },
  { "ConstraintFromANodeToItself", R"(bodies:
  - name: b
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1}
      - {position: [1, 0, 0], mass: 1}
    constraints:
      - {nodes: [0, 0]}
)",
    "bad.yaml:8: bodies[0].constraints[0].nodes", { "connects node 0 to itself" } },

  // --- names
  { "UnknownIntegrator", R"(physics:
  integrator: leapfrog
bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 0], mass: 1}]}]
)",
    "bad.yaml:2: physics.integrator",
    { "unknown integrator 'leapfrog'",
      "explicit_euler, semi_implicit_euler, verlet, velocity_verlet, rk4, implicit_euler, xpbd" } },
  { "UnknownBodyType", R"(bodies:
  - name: b
    type: blob
    nodes:
      - {position: [0, 0, 0], mass: 1}
)",
    "bad.yaml:3: bodies[0].type", { "unknown body type 'blob'", "custom" } },
  { "DuplicateBodyName", R"(bodies:
  - name: twin
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1}
  - name: twin
    type: custom
    nodes:
      - {position: [1, 0, 0], mass: 1}
)",
    "bad.yaml:6: bodies[1].name", { "duplicate body name 'twin'", "bodies[0]" } },
  { "EmptyBodyName", R"(bodies:
  - name: ""
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1}
)",
    "bad.yaml:2: bodies[0].name", { "must not be empty" } },
  { "EmptyFrameId", R"(frame_id: ''
bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 0], mass: 1}]}]
)",
    "bad.yaml:1: frame_id", { "must not be empty" } },

  // --- empty lists
  { "EmptyBodies", R"(frame_id: world
bodies: []
)",
    "bad.yaml:2: bodies", { "must not be empty" } },
  { "EmptyNodes", R"(bodies:
  - name: b
    type: custom
    nodes: []
)",
    "bad.yaml:4: bodies[0].nodes", { "must not be empty" } },

  // --- the document itself
  { "MergeKey", R"(bodies:
  - &rope {name: a, type: rope, nodes: 8, from: [0, 0, 1], to: [1, 0, 1], mass: 0.1, stiffness: 50}
  - {<<: *rope, name: b}
)",
    "bad.yaml:3: bodies[1].<<", { "merge keys are not supported" } },

  { "MalformedYaml", R"(bodies:
  - name: b
    nodes: [{position: [0, 0, 0], mass: 1}
  - name: c
)",
    "bad.yaml:4:3", { "invalid YAML", "illegal block entry" } },
  { "ControlCharacterInYamlErrorIsEscaped", "bodies: \"\\\x01\"\n", "bad.yaml:1:12",
    { "invalid YAML", "unknown escape character: ?" } },
  // yaml-cpp 0.7's LoadAll loops on these, collecting empty documents until memory runs out.
  { "StrayCommaAtTopLevel", R"(,
)",
    "bad.yaml:1:1", { "invalid YAML", "unexpected ','" } },
  { "StrayCommaAfterTheScene", R"(bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 0], mass: 1}]}]
---
,
)",
    "bad.yaml:3:1", { "invalid YAML", "unexpected ','" } },
  { "TopLevelIsAList", R"(- name: b
  type: custom
)",
    "bad.yaml:1: (top level)", { "must be a YAML mapping", "frame_id, rate, physics, planes, colliders, robot_colliders, cameras, bodies", "a list" } },
  { "TopLevelIsAScalar", R"(hello
)",
    "bad.yaml:1: (top level)", { "must be a YAML mapping", "'hello'" } },
  { "EmptyDocument", R"(# nothing but a comment
)",
    "bad.yaml:1: (top level)", { "must be a YAML mapping", "empty document" } },
  { "TwoDocuments", R"(bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 0], mass: 1}]}]
---
bodies: [{name: c, type: custom, nodes: [{position: [0, 0, 0], mass: 1}]}]
)",
    "bad.yaml:3: (top level)", { "second YAML document" } },
  { "ZeroRate", R"(rate: 0
bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 1], mass: 1}]}]
)",
    "bad.yaml:1: rate", { "must be > 0" } },
  // --- planes and anchors
  { "PlaneWithZeroNormal", R"(planes:
  - {point: [0, 0, 0], normal: [0, 0, 0]}
bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 1], mass: 1}]}]
)",
    "bad.yaml:2: planes[0].normal", { "zero vector" } },
  { "PlaneRestitutionAboveOne", R"(planes:
  - {point: [0, 0, 0], normal: [0, 0, 1], restitution: 1.5}
bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 1], mass: 1}]}]
)",
    "bad.yaml:2: planes[0].restitution", { "must be in [0, 1]", "1.5" } },
  { "PlaneNegativeFriction", R"(planes:
  - {point: [0, 0, 0], normal: [0, 0, 1], friction: -0.1}
bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 1], mass: 1}]}]
)",
    "bad.yaml:2: planes[0].friction", { "must be >= 0" } },
  { "PlaneMissingPoint", R"(planes:
  - {normal: [0, 0, 1]}
bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 1], mass: 1}]}]
)",
    "bad.yaml:2: planes[0].point", { "missing required key" } },
  { "PlaneUnknownKey", R"(planes:
  - {point: [0, 0, 0], normal: [0, 0, 1], bounce: 1}
bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 1], mass: 1}]}]
)",
    "bad.yaml:2: planes[0].bounce", { "unknown key 'bounce'", "point, normal, restitution, friction" } },
  { "AnchorNodeOutOfRange", R"(bodies:
  - name: b
    type: custom
    nodes: [{position: [0, 0, 0], mass: 1}, {position: [1, 0, 0], mass: 1}]
    anchors: [{name: end, node: 2}]
)",
    "bad.yaml:5: bodies[0].anchors[0].node", { "node index 2 out of range", "-2..1" } },
  { "AnchorNegativeIndexOutOfRange", R"(bodies:
  - name: b
    type: custom
    nodes: [{position: [0, 0, 0], mass: 1}, {position: [1, 0, 0], mass: 1}]
    anchors: [{name: end, node: -3}]
)",
    "bad.yaml:5: bodies[0].anchors[0].node", { "node index -3 out of range" } },
  { "AnchorDuplicateName", R"(bodies:
  - name: b
    type: custom
    nodes: [{position: [0, 0, 0], mass: 1}, {position: [1, 0, 0], mass: 1}]
    anchors: [{name: end, node: 0}, {name: end, node: 1}]
)",
    "bad.yaml:5: bodies[0].anchors[1].name", { "duplicate anchor name 'end'" } },
  { "AnchorMissingNode", R"(bodies:
  - name: b
    type: custom
    nodes: [{position: [0, 0, 0], mass: 1}]
    anchors: [{name: end}]
)",
    "bad.yaml:5: bodies[0].anchors[0].node", { "missing required key" } },
  { "AnchorFrameWithLeadingSlash", R"(bodies:
  - name: b
    type: custom
    nodes: [{position: [0, 0, 0], mass: 1}]
    anchors: [{name: end, node: 0, frame: /gripper_link}]
)",
    "bad.yaml:5: bodies[0].anchors[0].frame", { "'/gripper_link' must not start with '/'" } },
  { "AnchorFrameEmpty", R"(bodies:
  - name: b
    type: custom
    nodes: [{position: [0, 0, 0], mass: 1}]
    anchors: [{name: end, node: 0, frame: ""}]
)",
    "bad.yaml:5: bodies[0].anchors[0].frame", { "empty" } },
  { "CarriageReturnInAValueStaysOneLine",
    "physics: {dt: 0.0\r}\nbodies: [{name: b, type: custom, nodes: [{position: [0, 0, 0], mass: 1}]}]\n",
    "bad.yaml:1: physics.dt", { "must be > 0, got 0.0?" } },
  { "MultiLineValueStaysOneLine", R"(physics:
  integrator: "semi\nimplicit"
bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 0], mass: 1}]}]
)",
    "bad.yaml:2: physics.integrator", { "unknown integrator 'semi\\nimplicit'" } },
};

class BadSceneTest : public ::testing::TestWithParam<BadScene>
{
};

TEST_P(BadSceneTest, IsRejectedWithSourceLineKeyPathAndReason)
{
  const BadScene& bad = GetParam();
  expectSceneError(bad.yaml, bad.location, bad.reason_words);
}

INSTANTIATE_TEST_SUITE_P(SceneLoader, BadSceneTest, ::testing::ValuesIn(kBadScenes),
                         [](const ::testing::TestParamInfo<BadScene>& info) { return std::string(info.param.name); });

TEST(SceneLoader, HugeBodiesAreRefusedBeforeTheyExhaustMemory)
{
  // Two ropes of 600,000 nodes each: 1.2 million nodes, over the scene's limit of one million.
  const std::string rope = "{type: rope, nodes: 600000, from: [0, 0, 0], to: [1, 0, 0], mass: 1, stiffness: 1}";
  expectSceneError("bodies:\n  - " + rope.substr(0, rope.size() - 1) + ", name: a}\n  - " +
                       rope.substr(0, rope.size() - 1) + ", name: b}\n",
                   "bad.yaml:3: bodies[1].nodes",
                   { "1200000 nodes", "more than 1000000", "600000 in the bodies before this one" });
  expectSceneError(R"(bodies:
  - {name: c, type: creature, tendrils: {segments: 2000000000}}
)",
                   "bad.yaml:2: bodies[0].tendrils.segments", { "4000000004 nodes", "more than 1000000" });
  expectSceneError(R"(bodies:
  - {name: l, type: limb, curve_samples: 2000000000}
)",
                   "bad.yaml:2: bodies[0].curve_samples", { "[2, 10000]" });
}

/// A body that would take the scene over its limit of 10^6 nodes after a rope of 999,998 nodes: each type
/// counts its nodes before building them (a volume once meshed: only then is its node count known).
struct OverBudget
{
  const char* name;
  const char* body;      ///< the second body, a flow mapping on line 3
  const char* location;  ///< "bad.yaml:3: bodies[1]..."
};

void PrintTo(const OverBudget& over, std::ostream* out) { *out << over.name; }

const OverBudget kOverBudget[] = {
  { "Custom", "{name: b, type: custom, nodes: [&n {position: [0, 0, 0], mass: 1}, *n, *n]}",
    "bad.yaml:3: bodies[1].nodes" },
  { "Rope", "{name: b, type: rope, nodes: 3, from: [0, 0, 0], to: [1, 0, 0], mass: 1, stiffness: 1}",
    "bad.yaml:3: bodies[1].nodes" },
  { "Cloth",
    "{name: b, type: cloth, nx: 3, ny: 2, top_left: [0, 0, 1], top_right: [1, 0, 1], bottom_left: [0, 0, 0], "
    "mass: 1, structural: {stiffness: 1}, shear: {stiffness: 1}}",
    "bad.yaml:3: bodies[1].ny" },
  { "Jelly",
    "{name: b, type: jelly, nx: 1, ny: 1, top_left: [0, 0, 1], top_right: [1, 0, 1], bottom_left: [0, 0, 0], "
    "mass: 1, edges: {stiffness: 1}, diagonals: {stiffness: 1}, pressure: 1}",
    "bad.yaml:3: bodies[1].ny" },
  { "Rod", "{name: b, type: rod, nodes: 3, from: [0, 0, 0], to: [1, 0, 0], radius: 0.01, youngs_modulus: 1e9, "
          "density: 1000}",
    "bad.yaml:3: bodies[1].nodes" },
  { "Volume", "{name: b, type: volume, shape: box, size: [0.04, 0.04, 0.04], resolution: 0.02, "
             "position: [0, 0, 1], youngs_modulus: 5e4, density: 100}",
    "bad.yaml:3: bodies[1].resolution" },
  { "Creature", "{name: b, type: creature}", "bad.yaml:3: bodies[1]" },
  { "CreatureTendrils", "{name: b, type: creature, tendrils: {segments: 1}}",
    "bad.yaml:3: bodies[1].tendrils.segments" },
  { "Limb", "{name: b, type: limb}", "bad.yaml:3: bodies[1]" },
  { "Humanoid", "{name: b, type: humanoid}", "bad.yaml:3: bodies[1]" },
};

class OverBudgetTest : public ::testing::TestWithParam<OverBudget>
{
};

TEST_P(OverBudgetTest, IsRefusedAtItsNodeCount)
{
  const OverBudget& over = GetParam();
  const std::string yaml = std::string("bodies:\n"
                                       "  - {name: a, type: rope, nodes: 999998, from: [0, 0, 0], to: [1, 0, 0], "
                                       "mass: 1, stiffness: 1}\n  - ") +
                           over.body + "\n";
  expectSceneError(yaml, over.location, { "more than 1000000", "999998 in the bodies before this one" });
}

INSTANTIATE_TEST_SUITE_P(SceneLoader, OverBudgetTest, ::testing::ValuesIn(kOverBudget),
                         [](const ::testing::TestParamInfo<OverBudget>& info) { return std::string(info.param.name); });

TEST(SceneLoader, RateIsReadWithADefaultOfSixtyHertz)
{
  const char* const body = "bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 1], mass: 1}]}]\n";
  EXPECT_EQ(parseScene(body, "rate.yaml").rate, 60.0);
  EXPECT_EQ(parseScene(std::string("rate: 25\n") + body, "rate.yaml").rate, 25.0);
}

TEST(SceneLoader, PlanesAndAnchorsAreRead)
{
  const SceneDef scene = parseScene(R"(planes:
  - {point: [0, 0, -1], normal: [0, 0, 2], restitution: 0.5, friction: 0.3}
  - {point: [1, 0, 0], normal: [-1, 0, 0]}
bodies:
  - name: b
    type: custom
    nodes: [{position: [0, 0, 0], mass: 1}, {position: [1, 0, 0], mass: 1}, {position: [2, 0, 0], mass: 1}]
    anchors: [{name: first, node: 0}, {name: last, node: -1, frame: gripper_link}]
)",
                                    "planes.yaml");
  ASSERT_EQ(scene.colliders.planes.size(), 2u);
  expectVec3(scene.colliders.planes[0].point, 0, 0, -1);
  expectVec3(scene.colliders.planes[0].normal, 0, 0, 2);
  EXPECT_EQ(scene.colliders.planes[0].restitution, 0.5);
  EXPECT_EQ(scene.colliders.planes[0].friction, 0.3);
  EXPECT_EQ(scene.colliders.planes[1].restitution, 0.0);
  EXPECT_EQ(scene.colliders.planes[1].friction, 0.0);
  const BodyDef& body = scene.bodies[0];
  ASSERT_EQ(body.anchors.size(), 2u);
  EXPECT_EQ(body.anchors[0].name, "first");
  EXPECT_EQ(body.anchors[0].node, 0);
  EXPECT_EQ(body.anchors[1].node, 2);
  EXPECT_EQ(body.anchors[0].frame, "");  // moved by its pose topic
  EXPECT_EQ(body.anchors[1].frame, "gripper_link");

  // Anchored nodes are pinned in the world.
  const World world = buildWorld(scene);
  EXPECT_EQ(world.model().inverse_mass[0], 0.0);
  EXPECT_EQ(world.model().inverse_mass[1], 1.0);
  EXPECT_EQ(world.model().inverse_mass[2], 0.0);
  // The world's anchors say which tf frame each follows (the ROS node asks the world).
  ASSERT_EQ(world.model().anchors.size(), 2u);
  EXPECT_EQ(world.model().anchors[0].frame, "");
  EXPECT_EQ(world.model().anchors[1].frame, "gripper_link");
  // The model holds the colliders as declared; the contact stage normalises its own copy (test_world's
  // bounce on a plane of normal (0, 0, 3)).
  EXPECT_EQ(world.model().colliders.planes[0].normal, Vec3(0, 0, 2));
}

TEST(SceneLoader, CollidersAndContactRadiiAreRead)
{
  const SceneDef scene = parseScene(R"(colliders:
  - name: table
    shape: box
    size: [1.0, 0.6, 0.05]
    position: [0.0, 0.0, 0.7]
    orientation: [0, 0, 1, 1]
    friction: 0.5
    restitution: 0.25
  - {name: ball, shape: sphere, radius: 0.2, position: [1, 0, 0.5]}
  - name: rod
    shape: capsule
    radius: 0.01
    length: 0.5
    velocity: [0.5, 0, 0]
    angular_velocity: [0, 0, 2]
  - {name: finger, shape: capsule, radius: 0.008, length: 0.06, frame: gripper_link}
  - {name: post, shape: cylinder, radius: 0.05, length: 1.2, position: [2, 0, 0.6]}
robot_colliders: {param: my_robot, friction: 0.4}
bodies:
  - {name: r, type: rope, nodes: 3, from: [0, 0, 1], to: [1, 0, 1], mass: 1, stiffness: 10, radius: 0.005}
  - {name: c, type: cloth, nx: 2, ny: 2, top_left: [0, 0, 1], top_right: [1, 0, 1], bottom_left: [0, 1, 1],
     mass: 1, structural: {stiffness: 10}, shear: {stiffness: 10}, thickness: 0.002}
)",
                                    "colliders.yaml");
  ASSERT_EQ(scene.colliders.boxes.size(), 1u);
  const Box& table = scene.colliders.boxes[0];
  EXPECT_EQ(table.at.name, "table");
  expectVec3(table.size, 1.0, 0.6, 0.05);
  expectVec3(table.at.position, 0.0, 0.0, 0.7);
  // [x y z w] = [0 0 1 1] as written; the world normalises it: a quarter turn about z.
  EXPECT_EQ(table.at.orientation.z(), 1.0);
  EXPECT_EQ(table.at.orientation.w(), 1.0);
  EXPECT_EQ(table.at.friction, 0.5);
  EXPECT_EQ(table.at.restitution, 0.25);
  ASSERT_EQ(scene.colliders.spheres.size(), 1u);
  EXPECT_EQ(scene.colliders.spheres[0].radius, 0.2);
  EXPECT_EQ(scene.colliders.spheres[0].at.friction, 0.0);
  ASSERT_EQ(scene.colliders.capsules.size(), 2u);
  EXPECT_EQ(scene.colliders.capsules[0].length, 0.5);
  EXPECT_EQ(scene.colliders.capsules[0].at.frame, "");
  EXPECT_EQ(scene.colliders.capsules[1].at.frame, "gripper_link");
  ASSERT_TRUE(scene.robot_colliders);
  EXPECT_EQ(scene.robot_colliders->param, "my_robot");
  EXPECT_EQ(scene.robot_colliders->friction, 0.4);
  EXPECT_EQ(scene.robot_colliders->restitution, 0.0);
  ASSERT_EQ(scene.colliders.cylinders.size(), 1u);
  EXPECT_EQ(scene.colliders.cylinders[0].radius, 0.05);
  EXPECT_EQ(scene.colliders.cylinders[0].length, 1.2);
  expectVec3(scene.colliders.capsules[0].at.velocity, 0.5, 0, 0);
  expectVec3(scene.colliders.capsules[0].at.angular_velocity, 0, 0, 2);
  EXPECT_EQ(scene.bodies[0].contact_radius, 0.005);
  EXPECT_EQ(scene.bodies[1].contact_radius, 0.002);
  const World world = buildWorld(scene);
  EXPECT_EQ(world.model().contact_radius[0], 0.005);
  EXPECT_EQ(world.model().contact_radius[3], 0.002);
  ASSERT_EQ(world.colliderPoses().size(), 4u);  // the finger appears once tf knows its frame
  const ColliderPose table_pose = world.colliderPoses()[2];  // ball, rod, table, post (the finger unplaced)
  EXPECT_EQ(table_pose.name, "table");
  EXPECT_NEAR(table_pose.orientation.z(), std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(table_pose.orientation.w(), std::sqrt(0.5), 1e-15);
}

TEST(SceneLoader, BadCollidersAreRejectedWithOneLineAtTheKey)
{
  const std::string body = "bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 1], mass: 1}]}]\n";
  expectSceneError("colliders: [{name: a, shape: cone, radius: 1}]\n" + body, "bad.yaml:1: colliders[0].shape",
                   { "unknown shape 'cone'", "sphere, capsule, cylinder, box, mesh" });
  expectSceneError("colliders: [{name: a, shape: sphere, radius: 0}]\n" + body, "bad.yaml:1: colliders[0].radius",
                   { "> 0" });
  expectSceneError("colliders: [{name: a, shape: box, size: [1, 0, 1]}]\n" + body, "bad.yaml:1: colliders[0].size",
                   { "> 0" });
  expectSceneError("colliders: [{name: a, shape: sphere, radius: 1, orientation: [0, 0, 0, 0]}]\n" + body,
                   "bad.yaml:1: colliders[0].orientation", { "zero quaternion" });
  expectSceneError("colliders: [{name: a, shape: sphere, radius: 1, friction: -1}]\n" + body,
                   "bad.yaml:1: colliders[0].friction", { ">= 0" });
  expectSceneError("colliders: [{name: a, shape: capsule, radius: 1}]\n" + body, "bad.yaml:1: colliders[0].length",
                   { "missing required key" });
  expectSceneError("colliders: [{name: a, shape: sphere, radius: 1, frame: hand, velocity: [1, 0, 0]}]\n" + body,
                   "bad.yaml:1: colliders[0].velocity", { "moves with its frame" });
  expectSceneError("colliders: [{name: a, shape: sphere, radius: 1, frame: /hand}]\n" + body,
                   "bad.yaml:1: colliders[0].frame", { "must not start with '/'" });
  expectSceneError("robot_colliders: {param: robot_description, friction: -0.5}\n" + body,
                   "bad.yaml:1: robot_colliders.friction", { ">= 0" });
  expectSceneError("robot_colliders: {urdf: robot.urdf}\n" + body, "bad.yaml:1: robot_colliders.urdf",
                   { "unknown key", "param, friction, restitution" });
  expectSceneError("colliders: [{name: a, shape: sphere, radius: 1}, {name: a, shape: sphere, radius: 2}]\n" + body,
                   "bad.yaml:1: colliders[1].name", { "duplicate collider name 'a'" });
  // A plane's name is a collider name too (each names a wrench).
  expectSceneError("planes: [{name: a, point: [0, 0, 0], normal: [0, 0, 1]}]\n"
                   "colliders: [{name: a, shape: sphere, radius: 1}]\n" + body,
                   "bad.yaml:2: colliders[0].name", { "duplicate collider name 'a'", "planes[0]" });
  expectSceneError("planes: [{name: '', point: [0, 0, 0], normal: [0, 0, 1]}]\n" + body, "bad.yaml:1: planes[0].name",
                   {});
  expectSceneError("bodies: [{name: r, type: rope, nodes: 3, from: [0, 0, 1], to: [1, 0, 1], mass: 1, stiffness: 1, "
                   "radius: -0.1}]\n",
                   "bad.yaml:1: bodies[0].radius", { "radius must be >= 0", "-0.1" });
}

TEST(SceneLoader, CamerasAndColoursAreReadWithTheirDefaults)
{
  const SceneDef scene = parseScene(
      "planes: [{point: [0, 0, 0], normal: [0, 0, 1], color: [0.1, 0.2, 0.3]}]\n"
      "colliders: [{name: ball, shape: sphere, radius: 0.1, color: [1, 0, 0]}]\n"
      "cameras:\n"
      "  - {name: camera, position: [1.2, 0, 1], orientation: [0, 0.2588, 0, 0.9659], width: 320, height: 240,\n"
      "     horizontal_fov: 90, rate: 15, min_range: 0.2, max_range: 4, background: [0, 0, 1],\n"
      "     noise: {depth_stddev: 0.001, seed: 7}}\n"
      "  - {name: wrist, frame: wrist_link}\n"
      "bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 1], mass: 1}], color: [0, 1, 0]},\n"
      "         {name: c, type: rope, nodes: 3, from: [0, 0, 1], to: [1, 0, 1], mass: 1, stiffness: 1}]\n",
      "cameras.yaml");
  EXPECT_EQ(scene.colliders.planes[0].color, Vec3(0.1, 0.2, 0.3));
  EXPECT_EQ(scene.colliders.spheres[0].at.color, Vec3(1, 0, 0));
  ASSERT_EQ(scene.cameras.size(), 2u);
  const CameraDef& camera = scene.cameras[0];
  EXPECT_EQ(camera.name, "camera");
  EXPECT_EQ(camera.position, Vec3(1.2, 0, 1));
  EXPECT_EQ(camera.orientation.coeffs(), Eigen::Vector4d(0, 0.2588, 0, 0.9659));
  EXPECT_EQ(camera.width, 320);
  EXPECT_EQ(camera.height, 240);
  EXPECT_EQ(camera.horizontal_fov, 90.0);
  EXPECT_EQ(camera.rate, 15.0);
  EXPECT_EQ(camera.min_range, 0.2);
  EXPECT_EQ(camera.max_range, 4.0);
  EXPECT_EQ(camera.background, Vec3(0, 0, 1));
  ASSERT_TRUE(camera.noise);
  EXPECT_EQ(camera.noise->depth_stddev, 0.001);
  EXPECT_EQ(camera.noise->seed, 7u);
  const CameraDef& wrist = scene.cameras[1];  // the contract's defaults
  EXPECT_EQ(wrist.frame, "wrist_link");
  EXPECT_EQ(wrist.width, 640);
  EXPECT_EQ(wrist.height, 480);
  EXPECT_EQ(wrist.horizontal_fov, 69.4);
  EXPECT_EQ(wrist.rate, 30.0);
  EXPECT_EQ(wrist.min_range, 0.1);
  EXPECT_EQ(wrist.max_range, 10.0);
  EXPECT_EQ(wrist.background, Vec3::Constant(0.2));
  EXPECT_FALSE(wrist.noise);
  // 640 px over 69.4 degrees: fx = 320 / tan(34.7 deg) = 462.1 px, the centre between the middle pixels.
  const CameraIntrinsics k = CameraIntrinsics::of(wrist);
  EXPECT_NEAR(k.fx, 320.0 / std::tan(34.7 * M_PI / 180.0), 1e-9);
  EXPECT_EQ(k.fy, k.fx);
  EXPECT_EQ(k.cx, 319.5);
  EXPECT_EQ(k.cy, 239.5);
  // A body's colour, else the golden-angle default by its index; its look from its type.
  const World world = buildWorld(scene);
  EXPECT_EQ(world.model().bodies[0].look.color, Vec3(0, 1, 0));
  EXPECT_EQ(world.model().bodies[1].look.color, defaultBodyColor(1));
  EXPECT_EQ(world.model().bodies[0].look.balls, std::vector<int>{ 0 });
  EXPECT_EQ(world.model().bodies[1].look.tubes.size(), 2u);  // the rope's two links
  EXPECT_EQ(world.model().bodies[1].look.radius, kDefaultLookRadius);
}

TEST(SceneLoader, BadCamerasAndColoursAreRejectedWithOneLineAtTheKey)
{
  const std::string body = "bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 1], mass: 1}]}]\n";
  expectSceneError("cameras: [{name: c, width: 0}]\n" + body, "bad.yaml:1: cameras[0].width", { "integer in [1," });
  expectSceneError("cameras: [{name: c, horizontal_fov: 180}]\n" + body, "bad.yaml:1: cameras[0].horizontal_fov",
                   { "between 0 and 180" });
  expectSceneError("cameras: [{name: c, min_range: 2, max_range: 1}]\n" + body, "bad.yaml:1: cameras[0].max_range",
                   { "greater than min_range" });
  expectSceneError("cameras: [{name: c, frame: /hand}]\n" + body, "bad.yaml:1: cameras[0].frame",
                   { "must not start with '/'" });
  expectSceneError("cameras: [{name: 'my camera'}]\n" + body, "bad.yaml:1: cameras[0].name",
                   { "letters, digits and underscores" });
  expectSceneError("cameras: [{name: c}, {name: c}]\n" + body, "bad.yaml:1: cameras[1].name",
                   { "duplicate camera name 'c'" });
  expectSceneError("cameras: [{name: c, noise: {depth_stddev: -1}}]\n" + body,
                   "bad.yaml:1: cameras[0].noise.depth_stddev", { ">= 0" });
  expectSceneError("cameras: [{name: c, zoom: 2}]\n" + body, "bad.yaml:1: cameras[0].zoom", { "unknown key" });
  expectSceneError("colliders: [{name: a, shape: sphere, radius: 1, color: [1, 0, 2]}]\n" + body,
                   "bad.yaml:1: colliders[0].color", { "each from 0 to 1" });
  expectSceneError("bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 1], mass: 1}], color: [1, 0]}]\n",
                   "bad.yaml:1: bodies[0].color", {});
}

TEST(SceneLoader, APlaneTakesAnOptionalName)
{
  const SceneDef scene = parseScene("planes: [{name: floor, point: [0, 0, 0], normal: [0, 0, 1]}, "
                                    "{point: [1, 0, 0], normal: [-1, 0, 0]}]\n"
                                    "bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 1], mass: 1}]}]\n",
                                    "planes.yaml");
  ASSERT_EQ(scene.colliders.planes.size(), 2u);
  EXPECT_EQ(scene.colliders.planes[0].name, "floor");
  EXPECT_EQ(scene.colliders.planes[1].name, "");
}

TEST(SceneLoader, RopeSelfCollisionAndFrictionAreReadAndNeedARadius)
{
  // Two sub-steps: a 2 m fall (there is no floor) at 6.3 m/s moves 3.1 mm per sub-step, within the radius.
  const std::string rope = "physics: {substeps: 2}\n"
                           "bodies: [{name: r, type: rope, nodes: 3, from: [0, 0, 1], to: [1, 0, 1], mass: 1, "
                           "stiffness: 1";
  const SceneDef scene = parseScene(rope + ", radius: 0.005, self_collision: true}]\n", "rope.yaml");
  ASSERT_EQ(scene.bodies.size(), 1u);
  EXPECT_TRUE(scene.bodies[0].self_collision);
  EXPECT_TRUE(buildWorld(scene).model().bodies[0].self_collision);
  EXPECT_FALSE(parseScene(rope + ", radius: 0.005}]\n", "rope.yaml").bodies[0].self_collision);
  expectSceneError(rope + ", self_collision: true}]\n", "bad.yaml:2: bodies[0].self_collision",
                   { "needs radius > 0" });
  expectSceneError(rope + ", radius: 0.005, self_collision: sometimes}]\n", "bad.yaml:2: bodies[0].self_collision",
                   { "sometimes" });
  const SceneDef rough = parseScene(rope + ", radius: 0.005, self_collision: true, self_friction: 0.4}]\n", "r.yaml");
  EXPECT_EQ(buildWorld(rough).model().bodies[0].self_friction, 0.4);
  EXPECT_EQ(scene.bodies[0].self_friction, 0.0);
  expectSceneError(rope + ", radius: 0.005, self_friction: 0.4}]\n", "bad.yaml:2: bodies[0].self_friction",
                   { "needs self_collision: true" });
  expectSceneError(rope + ", radius: 0.005, self_collision: true, self_friction: -0.1}]\n",
                   "bad.yaml:2: bodies[0].self_friction", { ">= 0" });
}

// The rule against passing through: a self-colliding rope's links move at most its radius per sub-step
// at the speed of a fall from its highest free node onto the floor (2 m without one). A rope 1 m above
// the floor falls at sqrt(2 g) = 4.43 m/s; at dt = 10 ms that is 44.3 mm per step, so a 5 mm rope needs
// 9 sub-steps. Reported at physics.substeps, or at the rope's self_collision if the file does not set
// them; `dt: auto` takes them itself; a rope pinned at every node (none free to fall) needs none.
TEST(SceneLoader, SelfCollisionNeedsSubStepsWithinTheRadiusOfAFallOntoTheFloor)
{
  const std::string floor = "planes: [{point: [0, 0, 0], normal: [0, 0, 1]}]\n";
  const std::string rope = "bodies: [{name: r, type: rope, nodes: 3, from: [0, 0, 1], to: [1, 0, 1], "
                           "mass: 1, stiffness: 1, radius: 0.005, self_collision: true}]\n";
  EXPECT_NO_THROW(parseScene("physics: {dt: 0.01, substeps: 9}\n" + floor + rope, "r.yaml"));
  expectSceneError("physics: {dt: 0.01, substeps: 8}\n" + floor + rope, "bad.yaml:1: physics.substeps",
                   { "body 'r' (self_collision)", "a fall of 1 m", "4.43 m/s", "5.54 mm per sub-step",
                     "needs substeps >= 9 at dt 0.01 s" });
  expectSceneError("physics: {dt: 0.01}\n" + floor + rope, "bad.yaml:3: bodies[0].self_collision",
                   { "needs substeps >= 9" });
  // Without the floor, the rule assumes a fall of 2 m: 6.26 m/s, 13 sub-steps.
  expectSceneError("physics: {dt: 0.01, substeps: 12}\n" + rope, "bad.yaml:1: physics.substeps",
                   { "a fall of 2 m", "needs substeps >= 13" });
  const SceneDef automatic = parseScene("physics: {dt: auto}\n" + floor + rope, "r.yaml");
  const World world = buildWorld(automatic);
  EXPECT_LE(std::sqrt(2.0 * 9.81 * 1.0) * world.settings().dt / world.settings().substeps, 0.005);
  EXPECT_GT(std::sqrt(2.0 * 9.81 * 1.0) * world.settings().dt / (world.settings().substeps - 1), 0.005);
  EXPECT_NO_THROW(parseScene("physics: {dt: 0.01, substeps: 8}\n" + floor +
                             "bodies: [{name: r, type: rope, nodes: 3, from: [0, 0, 1], to: [0, 0, 0.5], "
                             "mass: 1, stiffness: 1, radius: 0.005, self_collision: true, pinned: [0, 1, 2]}]\n",
                             "r.yaml"));
}

// A cloth's self_collision needs a thickness from 0.36 to 0.5 times its node spacing (here 0.5 m / 5 =
// 0.1 m); self_friction needs self_collision. Both read into the body.
TEST(SceneLoader, ClothSelfCollisionNeedsAThicknessThatKeepsItsNodesFromSlippingThrough)
{
  const std::string cloth = "bodies: [{name: c, type: cloth, nx: 6, ny: 6, top_left: [0, 0, 1], top_right: [0.5, 0, 1], "
                            "bottom_left: [0, 0.5, 1], mass: 1, structural: {stiffness: 100}, shear: {stiffness: 50}, ";
  const World world = buildWorld(
      parseScene(cloth + "thickness: 0.04, self_collision: true, self_friction: 0.2}]\n", "c.yaml"));
  EXPECT_TRUE(world.model().bodies[0].self_collision);
  EXPECT_EQ(world.model().bodies[0].self_friction, 0.2);
  expectSceneError(cloth + "thickness: 0.02, self_collision: true}]\n", "bad.yaml:1: bodies[0].thickness",
                   { "from 0.36 to 0.5 times the node spacing", "slips between four others" });
  expectSceneError(cloth + "thickness: 0.06, self_collision: true}]\n", "bad.yaml:1: bodies[0].thickness",
                   { "neighbours overlap at rest" });
  expectSceneError(cloth + "thickness: 0.04, self_friction: 0.2}]\n", "bad.yaml:1: bodies[0].self_friction",
                   { "needs self_collision: true" });
}

// A jelly's self_collision (its nodes out of its springs) needs a thickness of at most a quarter of the
// distance from a cell's corner to its diagonal: here 0.1 m x 0.05 m cells, 0.1 * 0.05 / sqrt(0.0125) =
// 0.0447 m, so at most 0.0112 m.
TEST(SceneLoader, JellySelfCollisionNeedsAThicknessClearOfItsCellsDiagonals)
{
  const std::string jelly = "bodies: [{name: j, type: jelly, nx: 4, ny: 4, top_left: [0, 0, 1], top_right: [0.4, 0, 1], "
                            "bottom_left: [0, 0, 0.8], mass: 1, edges: {stiffness: 100}, diagonals: {stiffness: 50}, "
                            "pressure: 100, ";
  const World world = buildWorld(
      parseScene(jelly + "thickness: 0.011, self_collision: true, self_friction: 0.3}]\n", "j.yaml"));
  EXPECT_TRUE(world.model().bodies[0].self_collision);
  EXPECT_TRUE(world.model().bodies[0].springs_collide);
  EXPECT_EQ(world.model().bodies[0].self_friction, 0.3);
  EXPECT_FALSE(buildWorld(parseScene(jelly + "thickness: 0.011}]\n", "j.yaml")).model().bodies[0].self_collision);
  expectSceneError(jelly + "thickness: 0.0113, self_collision: true}]\n", "bad.yaml:1: bodies[0].thickness",
                   { "a quarter of the distance from a cell's corner to its diagonal (0.0447", "0.0113" });
  expectSceneError(jelly + "self_collision: true}]\n", "bad.yaml:1: bodies[0].self_collision",
                   { "needs thickness > 0" });
  expectSceneError(jelly + "thickness: 0.01, self_friction: 0.2}]\n", "bad.yaml:1: bodies[0].self_friction",
                   { "needs self_collision: true" });
}

// A rope laid along a path: an L of two 1 m legs, 5 nodes at equal arc lengths of 0.5 m, the middle one
// at the corner; its links at rest as laid. Errors: from/to with path, fewer than 2 points, a repeated
// point (no length between them), each at its key.
TEST(SceneLoader, RopePathLaysTheNodesAtEqualArcLengths)
{
  const std::string rope = "bodies: [{name: r, type: rope, nodes: 5, mass: 1, stiffness: 1, ";
  const World world = buildWorld(parseScene(rope + "path: [[0, 0, 1], [1, 0, 1], [1, 1, 1]]}]\n", "r.yaml"));
  const NodeArray& x = world.state().position;
  const Vec3 expected[5] = { { 0, 0, 1 }, { 0.5, 0, 1 }, { 1, 0, 1 }, { 1, 0.5, 1 }, { 1, 1, 1 } };
  for (int i = 0; i < 5; ++i)
    EXPECT_NEAR((x.col(i) - expected[i]).norm(), 0.0, 1e-12) << "node " << i;
  for (const Spring& spring : world.model().springs)
    EXPECT_NEAR(spring.rest_length, 0.5, 1e-12);
  expectSceneError(rope + "path: [[0, 0, 1], [1, 0, 1]], from: [0, 0, 1]}]\n", "bad.yaml:1: bodies[0].from",
                   { "either from and to, or path" });
  expectSceneError(rope + "path: [[0, 0, 1]]}]\n", "bad.yaml:1: bodies[0].path", { "at least 2 points" });
  expectSceneError(rope + "path: [[0, 0, 1], [0, 0, 1], [1, 0, 1]]}]\n", "bad.yaml:1: bodies[0].path",
                   { "path point 1 repeats the one before it" });
}

TEST(SceneLoader, BadMeshCollidersAreRejectedWithOneLineAtTheKey)
{
  const std::string body = "bodies: [{name: b, type: custom, nodes: [{position: [0, 0, 1], mass: 1}]}]\n";
  const std::string part = std::string("file://") + SOURCE_DIR + "/config/meshes/part.stl";
  expectSceneError("colliders: [{name: a, shape: mesh, mesh: file:///nonexistent/part.stl}]\n" + body,
                   "bad.yaml:1: colliders[0].mesh", { "'/nonexistent/part.stl'", "cannot be read" });
  expectSceneError("colliders: [{name: a, shape: mesh, mesh: missing.stl}]\n" + body, "bad.yaml:1: colliders[0].mesh",
                   { "'missing.stl'", "cannot be read" });  // relative to the scene's folder: none for "bad.yaml"
  expectSceneError("colliders: [{name: a, shape: mesh, mesh: package://no_such_package_here/part.stl}]\n" + body,
                   "bad.yaml:1: colliders[0].mesh", { "ROS package 'no_such_package_here'", "not found" });
  expectSceneError("colliders: [{name: a, shape: mesh, mesh: http://example.com/part.stl}]\n" + body,
                   "bad.yaml:1: colliders[0].mesh", { "only package://, file:// and plain paths" });
  expectSceneError("colliders: [{name: a, shape: mesh, mesh: " + part + ", scale: [1, 0, 1]}]\n" + body,
                   "bad.yaml:1: colliders[0].scale", { "every factor of scale must be > 0" });
  expectSceneError("colliders: [{name: a, shape: mesh, mesh: " + part + ", scale: [1, 1, -1]}]\n" + body,
                   "bad.yaml:1: colliders[0].scale", { "every factor of scale must be > 0" });
  expectSceneError("colliders: [{name: a, shape: mesh, mesh: " + part + ", voxel_size: 0}]\n" + body,
                   "bad.yaml:1: colliders[0].voxel_size", { "> 0" });
  expectSceneError("colliders: [{name: a, shape: mesh, mesh: " + part + ", voxel_size: 0.00001}]\n" + body,
                   "bad.yaml:1: colliders[0].voxel_size", { "voxels, more than the 16777216 allowed" });
  // Printed as %g writes it: std::to_string's %f made this "voxel_size 0.000000 m".
  expectSceneError("colliders: [{name: a, shape: mesh, mesh: " + part + ", voxel_size: 1.0e-7}]\n" + body,
                   "bad.yaml:1: colliders[0].voxel_size", { "voxel_size 1e-07 m spans" });
  expectSceneError("colliders: [{name: a, shape: mesh}]\n" + body, "bad.yaml:1: colliders[0].mesh",
                   { "missing required key" });
  expectSceneError("colliders: [{name: a, shape: mesh, mesh: " + part + ", size: [1, 1, 1]}]\n" + body,
                   "bad.yaml:1: colliders[0].size", { "unknown key", "mesh, scale, voxel_size" });
}

// A mesh named by package://, file:// and a path relative to the scene file's folder is the same file
// (drawn by a URI rviz can load);
// its scale applies, and its field is built at load time, as wide as the thickest body needs.
TEST(SceneLoader, MeshCollidersAreReadFromPackageFileAndRelativeURIs)
{
  // The package as `source devel/setup.bash` would put it on the path.
  const char* previous = std::getenv("ROS_PACKAGE_PATH");
  ::setenv("ROS_PACKAGE_PATH", (std::string(SOURCE_DIR) + (previous ? ":" + std::string(previous) : "")).c_str(), 1);
  const SceneDef scene = parseScene(std::string(R"(colliders:
  - {name: by_package, shape: mesh, mesh: package://soft_body_sim/config/meshes/part.stl, scale: [2, 1, 1]}
  - {name: by_path, shape: mesh, mesh: ../meshes/part.stl, position: [1, 0, 0], voxel_size: 0.002, friction: 0.4}
  - {name: by_file, shape: mesh, mesh: file://)") + SOURCE_DIR + R"(/config/meshes/part.stl}
bodies:
  - {name: r, type: rope, nodes: 3, from: [0, 0, 1], to: [1, 0, 1], mass: 1, stiffness: 1, radius: 0.03}
)",
                                    std::string(SOURCE_DIR) + "/config/scenes/meshes.yaml");
  if (previous)
    ::setenv("ROS_PACKAGE_PATH", previous, 1);
  else
    ::unsetenv("ROS_PACKAGE_PATH");
  ASSERT_EQ(scene.colliders.meshes.size(), 3u);
  for (const Mesh& mesh : scene.colliders.meshes)
  {
    SCOPED_TRACE(mesh.at.name);
    ASSERT_TRUE(mesh.triangles);
    EXPECT_EQ(mesh.triangles->triangles.size(), 20u);  // scripts/make_part_stl.py's bracket
    ASSERT_TRUE(mesh.field);
    EXPECT_GE(mesh.field->exteriorBand(), 0.03 + 2.0 * mesh.field->voxelSize());
  }
  const Mesh& scaled = scene.colliders.meshes[0];
  EXPECT_EQ(scaled.uri, "package://soft_body_sim/config/meshes/part.stl");
  EXPECT_NEAR((scaled.triangles->upper() - scaled.triangles->lower()).x(), 0.2, 1e-6);  // 10 cm, doubled
  EXPECT_NEAR(scaled.field->voxelSize(), 0.2 / kDefaultVoxelsPerExtent, 1e-9);
  EXPECT_NEAR((scene.colliders.meshes[1].triangles->upper() - scene.colliders.meshes[1].triangles->lower()).x(), 0.1,
              1e-6);
  EXPECT_EQ(scene.colliders.meshes[1].voxel_size, 0.002);
  // rviz knows neither the scene's folder nor the node's: the relative path is drawn by its absolute one.
  EXPECT_EQ(scene.colliders.meshes[1].uri, std::string("file://") + SOURCE_DIR + "/config/meshes/part.stl");
  EXPECT_EQ(scene.colliders.meshes[1].at.friction, 0.4);
  const World world = buildWorld(scene);
  ASSERT_EQ(world.colliderPoses().size(), 3u);
  EXPECT_EQ(world.colliderPoses()[0].shape, ColliderPose::Shape::Mesh);
  EXPECT_EQ(world.colliderPoses()[0].mesh, "package://soft_body_sim/config/meshes/part.stl");
  EXPECT_EQ(world.colliderPoses()[0].size, Vec3(2, 1, 1));
}

// --- files -------------------------------------------------------------------------------------

TEST(SceneLoader, EveryExampleSceneLoads)
{
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(sceneDir()))
  {
    if (entry.path().extension() != ".yaml")
      continue;
    SCOPED_TRACE(entry.path().string());
    EXPECT_NO_THROW(loadSceneFile(entry.path().string()));
    ++count;
  }
  EXPECT_GE(count, 2);
}

TEST(SceneLoader, TumExercise1HasTheExerciseValues)
{
  const SceneDef scene = loadSceneFile(sceneDir() + "/tum_exercise_1.yaml");
  EXPECT_EQ(scene.physics.integrator, IntegratorType::ExplicitEuler);
  EXPECT_EQ(scene.physics.step.dt, 0.5);
  expectVec3(scene.physics.gravity, 0.0, 0.0, 0.0);
  ASSERT_EQ(scene.bodies.size(), 1u);
  const BodyDef& body = scene.bodies[0];
  ASSERT_EQ(body.nodes.size(), 2u);
  expectVec3(body.nodes[0].position, 2.0, 4.0, 0.0);
  expectVec3(body.nodes[1].position, 1.0, -3.0, 0.0);
  EXPECT_EQ(body.nodes[0].mass, 1.0);
  EXPECT_EQ(body.nodes[1].mass, 1.0);
  ASSERT_EQ(body.springs.size(), 1u);
  EXPECT_EQ(body.springs[0].stiffness, 2.0);
  ASSERT_TRUE(body.springs[0].rest_length.has_value());
  EXPECT_EQ(*body.springs[0].rest_length, 4.0);
}

TEST(SceneLoader, HangingChainIsOneMetreOfChainOverAnEightyCentimetreSpan)
{
  const SceneDef scene = loadSceneFile(sceneDir() + "/hanging_chain.yaml");
  EXPECT_EQ(scene.physics.integrator, IntegratorType::ImplicitEuler);
  EXPECT_EQ(scene.physics.step.dt, 0.005);
  EXPECT_EQ(scene.physics.drag, 0.5);
  ASSERT_EQ(scene.bodies.size(), 1u);
  const BodyDef& chain = scene.bodies[0];
  ASSERT_EQ(chain.nodes.size(), 21u);
  ASSERT_EQ(chain.springs.size(), 20u);

  double total_mass = 0.0;
  for (const NodeDef& node : chain.nodes)
    total_mass += node.mass;
  EXPECT_NEAR(total_mass, 0.1, 1e-12);
  for (std::size_t i = 0; i < chain.nodes.size(); ++i)
    EXPECT_EQ(chain.nodes[i].pinned, i == 0 || i + 1 == chain.nodes.size()) << "node " << i;
  EXPECT_NEAR((chain.nodes.front().position - chain.nodes.back().position).norm(), 0.8, 1e-12);

  double length = 0.0;
  for (std::size_t k = 0; k < chain.springs.size(); ++k)
  {
    const SpringDef& spring = chain.springs[k];
    EXPECT_EQ(spring.a, static_cast<int>(k));
    EXPECT_EQ(spring.b, static_cast<int>(k) + 1);
    EXPECT_EQ(spring.stiffness, 1000.0);
    EXPECT_GT(spring.damping, 0.0);
    ASSERT_TRUE(spring.rest_length.has_value());
    length += *spring.rest_length;
    // Springs start at rest: the initial distance is the rest length.
    const double distance = (chain.nodes[k].position - chain.nodes[k + 1].position).norm();
    EXPECT_NEAR(distance, *spring.rest_length, 1e-9) << "spring " << k;
  }
  EXPECT_NEAR(length, 1.0, 1e-12);
}

TEST(SceneLoader, MissingFileCannotBeOpened)
{
  const std::string path = sceneDir() + "/no_such_scene.yaml";
  try
  {
    loadSceneFile(path);
    ADD_FAILURE() << "loaded a missing file";
  }
  catch (const SceneError& e)
  {
    EXPECT_EQ(std::string(e.what()), path + ": cannot open scene file: no such file");
  }
}

TEST(SceneLoader, ARodIsReadByItsMaterial)
{
  const SceneDef scene = parseScene(R"(physics: {integrator: implicit_euler}
bodies:
  - name: cable
    type: rod
    nodes: 5
    from: [0, 0, 1]
    to: [1, 0, 1]
    radius: 0.01
    youngs_modulus: 2.0e9
    density: 1000.0
    damping: 0.01
    clamped: [0, 2]
    anchors: [{name: tip, node: -1}]
)",
                                     "cable.yaml");
  const World world = buildWorld(scene);
  ASSERT_EQ(world.model().rods.size(), 1u);
  const Rod& rod = world.model().rods[0];
  const double second_moment = M_PI * std::pow(0.01, 4) / 4.0;
  EXPECT_DOUBLE_EQ(rod.bending_stiffness, 2.0e9 * second_moment);
  EXPECT_DOUBLE_EQ(rod.twisting_stiffness, 2.0e9 / 2.6 * 2.0 * second_moment);  // G defaults to E / 2.6
  EXPECT_DOUBLE_EQ(rod.segment_length, 0.25);
  // Held at its clamped nodes (an inner one too) and at its anchored last node, in order.
  ASSERT_EQ(rod.stations.size(), 3u);
  EXPECT_EQ(rod.stations[0].first, 0);
  EXPECT_EQ(rod.stations[1].first, 2);
  EXPECT_EQ(rod.stations[2].first, 4);
  EXPECT_EQ(rod.end_moment, Vec3::Zero());
  EXPECT_DOUBLE_EQ(world.model().springs[0].stiffness, 2.0e9 * M_PI * 0.01 * 0.01 / 0.25);
  EXPECT_DOUBLE_EQ(world.model().mass[0], 0.5 * 1000.0 * M_PI * 0.01 * 0.01 * 0.25);
  EXPECT_DOUBLE_EQ(world.model().contact_radius[2], 0.01);
}

TEST(SceneLoader, ARodsMistakesAreNamedAtTheirKeys)
{
  const std::string rod = "{name: c, type: rod, nodes: 5, from: [0, 0, 1], to: [1, 0, 1], radius: 0.01, "
                          "youngs_modulus: 1e9, density: 1000";
  expectSceneError("bodies:\n  - " + rod + ", clamped: [5]}\n", "bad.yaml:2: bodies[0].clamped[0]", { "out of range" });
  expectSceneError("bodies:\n  - " + rod + ", end_moment: [0, .nan, 0]}\n", "bad.yaml:2: bodies[0].end_moment[1]", { "finite" });
  expectSceneError("bodies:\n  - " + rod + ", shear_modulus: 0}\n", "bad.yaml:2: bodies[0].shear_modulus", { "> 0" });
  expectSceneError("bodies:\n  - " + rod + ", pinned: [0]}\n", "bad.yaml:2: bodies[0].pinned", {});
  // Only implicit_euler bends and twists a rod: another integrator is refused, not silently a spring chain.
  try
  {
    buildWorld(parseScene("physics: {integrator: xpbd}\nbodies:\n  - " + rod + "}\n", "bad.yaml"));
    ADD_FAILURE() << "built a rod under xpbd";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_NE(std::string(e.what()).find("implicit_euler"), std::string::npos) << e.what();
  }
  // An end moment acts on a free end: on a held one the holder would take it.
  try
  {
    buildWorld(parseScene("physics: {integrator: implicit_euler}\nbodies:\n  - " + rod +
                              ", end_moment: [0, 1, 0], clamped: [-1]}\n", "bad.yaml"));
    ADD_FAILURE() << "built an end moment on a clamped end";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_NE(std::string(e.what()).find("end_moment"), std::string::npos) << e.what();
  }
  const SceneDef loaded =
      parseScene("physics: {integrator: implicit_euler}\nbodies:\n  - " + rod + ", end_moment: [0, -2, 0]}\n", "ok.yaml");
  EXPECT_EQ(buildWorld(loaded).model().rods[0].end_moment, Vec3(0.0, -2.0, 0.0));
  World world = buildWorld(parseScene("physics: {integrator: implicit_euler}\nbodies:\n  - " + rod + "}\n", "ok.yaml"));
  EXPECT_THROW(world.setIntegrator(IntegratorType::Rk4), std::invalid_argument);
  EXPECT_EQ(world.integrator(), IntegratorType::ImplicitEuler);
}

// --- type: volume ----------------------------------------------------------------------------------

/// The area [m^2] of a body's boundary triangles.
double surfaceArea(const BodyDef& body)
{
  double area = 0.0;
  for (const std::array<int, 3>& f : body.surface)
  {
    const Vec3& a = body.nodes[f[0]].position;
    area += 0.5 * (body.nodes[f[1]].position - a).cross(body.nodes[f[2]].position - a).norm();
  }
  return area;
}

/// The volume [m^3] a body's boundary encloses by the divergence theorem, sum a . (b x c) / 6 over its
/// triangles (independent of its tetrahedra), about the point `origin` to keep the round-off small.
double enclosedVolume(const BodyDef& body, const Vec3& origin)
{
  double volume = 0.0;
  for (const std::array<int, 3>& f : body.surface)
    volume += (body.nodes[f[0]].position - origin)
                  .dot((body.nodes[f[1]].position - origin).cross(body.nodes[f[2]].position - origin)) /
              6.0;
  return volume;
}

double totalMass(const BodyDef& body)
{
  double mass = 0.0;
  for (const NodeDef& node : body.nodes)
    mass += node.mass;
  return mass;
}

TEST(SceneLoader, ABoxVolumeIsFilledWithTetrahedraOfItsMaterial)
{
  const SceneDef scene = parseScene(R"(physics: {integrator: implicit_euler}
bodies:
  - name: sponge
    type: volume
    shape: box
    size: [0.1, 0.08, 0.05]
    resolution: 0.02
    position: [0.3, -0.2, 0.5]
    youngs_modulus: 5.0e4
    poisson_ratio: 0.3
    density: 100.0
    pinned: [z_max]
    pressure: 0.0
    anchors: [{name: corner, node: -1}]
)",
                                     "sponge.yaml");
  ASSERT_EQ(scene.bodies.size(), 1u);
  const BodyDef& body = scene.bodies[0];
  EXPECT_EQ(body.type, "volume");
  EXPECT_EQ(body.contact_radius, 0.0);
  const double a = 0.1, b = 0.08, c = 0.05, volume = a * b * c;
  // The box's mass, its volume filled exactly by positive tetrahedra, and its six faces' area.
  EXPECT_NEAR(totalMass(body), 100.0 * volume, 1e-9 * 100.0 * volume);
  ASSERT_FALSE(body.tetrahedra.empty());
  double filled = 0.0;
  for (const Tetrahedron& tet : body.tetrahedra)
  {
    EXPECT_GT(tet.rest_volume, 0.0);
    filled += tet.rest_volume;
    // Lame's parameters of E = 5e4 Pa, nu = 0.3 by hand.
    EXPECT_NEAR(tet.mu, 5.0e4 / 2.6, 1e-9);
    EXPECT_NEAR(tet.lambda, 5.0e4 * 0.3 / (1.3 * 0.4), 1e-9);
  }
  EXPECT_NEAR(filled, volume, 1e-9 * volume);
  EXPECT_NEAR(surfaceArea(body), 2.0 * (a * b + b * c + c * a), 1e-9 * 2.0 * (a * b + b * c + c * a));
  EXPECT_NEAR(enclosedVolume(body, Vec3(0.3, -0.2, 0.5)), volume, 1e-9 * volume);
  // z_max: the nodes of the boundary triangles that face up (normal +z) are pinned, and no other; the
  // box's four top corners among them.
  std::vector<bool> on_top(body.nodes.size(), false);
  for (const std::array<int, 3>& f : body.surface)
  {
    const Vec3 normal = (body.nodes[f[1]].position - body.nodes[f[0]].position)
                            .cross(body.nodes[f[2]].position - body.nodes[f[0]].position)
                            .normalized();
    if (normal.z() > 1.0 - 1e-9)
      for (int k : f)
        on_top[static_cast<std::size_t>(k)] = true;
  }
  int pinned = 0, corners = 0;
  for (std::size_t k = 0; k < body.nodes.size(); ++k)
  {
    EXPECT_EQ(body.nodes[k].pinned, on_top[k]) << "node " << k << " at " << body.nodes[k].position.transpose();
    pinned += body.nodes[k].pinned;
    const Vec3 offset = body.nodes[k].position - Vec3(0.3, -0.2, 0.5);
    corners += body.nodes[k].pinned && std::abs(std::abs(offset.x()) - a / 2) < 1e-12 &&
               std::abs(std::abs(offset.y()) - b / 2) < 1e-12 && std::abs(offset.z() - c / 2) < 1e-12;
  }
  EXPECT_EQ(corners, 4);
  EXPECT_GE(pinned, 4);
  EXPECT_LT(pinned, static_cast<int>(body.nodes.size()));
  // In the world: its tetrahedra and boundary, pinned nodes of inverse mass 0, its anchor on the last node.
  const World world = buildWorld(scene);
  EXPECT_EQ(world.model().tetrahedra.size(), body.tetrahedra.size());
  EXPECT_EQ(world.model().bodies[0].surface.size(), body.surface.size());
  for (std::size_t k = 0; k < body.nodes.size(); ++k)
  {
    if (on_top[k])
    {
      EXPECT_EQ(world.model().inverse_mass[static_cast<Eigen::Index>(k)], 0.0) << "node " << k;
    }
  }
  ASSERT_EQ(world.model().anchors.size(), 1u);
  EXPECT_EQ(world.model().anchors[0].node, static_cast<int>(body.nodes.size()) - 1);
}

TEST(SceneLoader, ASphereVolumeWeighsItsDensityTimesItsMeshVolume)
{
  const SceneDef scene = parseScene(R"(physics: {integrator: implicit_euler}
bodies:
  - {name: ball, type: volume, shape: sphere, radius: 0.05, resolution: 0.02, position: [0, 0, 1],
     youngs_modulus: 1.0e5, density: 250.0}
)",
                                     "ball.yaml");
  const BodyDef& body = scene.bodies[0];
  // The mesh's volume by the divergence theorem over its boundary, and within the bounds of volume_mesh.h's
  // inscribed polyhedron: below the ball's 4/3 pi r^3 by at most 0.51 (resolution / r)^2 of it.
  const double mesh_volume = enclosedVolume(body, Vec3(0.0, 0.0, 1.0)), ball = 4.0 / 3.0 * M_PI * std::pow(0.05, 3);
  EXPECT_LT(mesh_volume, ball);
  EXPECT_GT(mesh_volume, (1.0 - 0.51 * std::pow(0.02 / 0.05, 2)) * ball);
  EXPECT_NEAR(totalMass(body), 250.0 * mesh_volume, 1e-9 * 250.0 * mesh_volume);
  for (const NodeDef& node : body.nodes)
  {
    EXPECT_FALSE(node.pinned);
    EXPECT_LE((node.position - Vec3(0.0, 0.0, 1.0)).norm(), 0.05 * (1.0 + 1e-12));
  }
  EXPECT_EQ(buildWorld(scene).model().tetrahedra.size(), body.tetrahedra.size());
}

TEST(SceneLoader, AMeshVolumeFillsItsSurfaceFile)
{
  // The example bracket (scripts/make_part_stl.py): an L-shaped profile of area 0.1 x 0.02 + 0.02 x 0.06
  // [m^2] extruded 0.06 m, stored in single precision.
  const std::string part = std::string("file://") + SOURCE_DIR + "/config/meshes/part.stl";
  const SceneDef scene = parseScene("physics: {integrator: implicit_euler}\nbodies:\n"
                                    "  - {name: part, type: volume, shape: mesh, mesh: " + part +
                                        ", resolution: 0.01, position: [1, 0, 0], youngs_modulus: 1.0e6, "
                                        "poisson_ratio: 0.45, density: 1000.0, pinned: [0, -1]}\n",
                                    "part.yaml");
  const BodyDef& body = scene.bodies[0];
  const double volume = (0.1 * 0.02 + 0.02 * 0.06) * 0.06;
  EXPECT_NEAR(totalMass(body), 1000.0 * volume, 1e-6 * 1000.0 * volume);
  EXPECT_TRUE(body.nodes.front().pinned);
  EXPECT_TRUE(body.nodes.back().pinned);
  EXPECT_EQ(buildWorld(scene).model().tetrahedra.size(), body.tetrahedra.size());
}

TEST(SceneLoader, AVolumeFinerThanTheCallersLimitIsRefusedAtItsResolution)
{
  // A 4 cm cube at 1 cm: kTetsPerMaxVolume V / v_max = 3.5 x 6.4e-5 m^3 / (1e-6 m^3 / (2 sqrt 2)) = 634
  // tetrahedra estimated. Under a limit of 500 it is refused before meshing; under 1000 it meshes.
  const std::string yaml = "bodies:\n  - {name: s, type: volume, resolution: 0.01, position: [0, 0, 1], "
                           "youngs_modulus: 5e4, density: 100, shape: box, size: [0.04, 0.04, 0.04]}\n";
  expectSceneError([&] { parseScene(yaml, "bad.yaml", SceneLimits{ 500.0 }); }, yaml,
                   "bad.yaml:2: bodies[0].resolution", { "about 634 tetrahedra, over the limit of 500" });
  EXPECT_FALSE(parseScene(yaml, "good.yaml", SceneLimits{ 1000.0 }).bodies[0].tetrahedra.empty());
}

TEST(SceneLoader, AVolumesMistakesAreNamedAtTheirKeys)
{
  const std::string box = "{name: s, type: volume, resolution: 0.02, position: [0, 0, 1], youngs_modulus: 5e4, "
                          "density: 100, shape: box, size: [0.04, 0.04, 0.04]";
  const std::string ball = "{name: s, type: volume, resolution: 0.02, position: [0, 0, 1], youngs_modulus: 5e4, "
                           "density: 100, shape: sphere, radius: 0.03";
  expectSceneError("bodies:\n  - " + box + ", poisson_ratio: 0.5}\n", "bad.yaml:2: bodies[0].poisson_ratio",
                   { "[0, 0.5)" });
  expectSceneError("bodies:\n  - {name: s, type: volume, resolution: 0.02, position: [0, 0, 1], youngs_modulus: 0, "
                   "density: 100, shape: box, size: [0.04, 0.04, 0.04]}\n",
                   "bad.yaml:2: bodies[0].youngs_modulus", { "> 0" });
  expectSceneError("bodies:\n  - {name: s, type: volume, shape: cube}\n", "bad.yaml:2: bodies[0].shape",
                   { "unknown shape 'cube'", "box, sphere, mesh" });
  expectSceneError("bodies:\n  - " + ball + ", size: [0.1, 0.1, 0.1]}\n", "bad.yaml:2: bodies[0].size",
                   { "only for shape box" });
  expectSceneError("bodies:\n  - " + ball + ", pinned: [z_max]}\n", "bad.yaml:2: bodies[0].pinned",
                   { "z_max", "only for shape box" });
  expectSceneError("bodies:\n  - " + box + ", pinned: [top]}\n", "bad.yaml:2: bodies[0].pinned",
                   { "unknown face 'top'", "x_min, x_max, y_min, y_max, z_min, z_max" });
  expectSceneError("bodies:\n  - " + box + ", pinned: [100000]}\n", "bad.yaml:2: bodies[0].pinned",
                   { "out of range" });
  expectSceneError("bodies:\n  - " + box + ", pressure: -1000}\n", "bad.yaml:2: bodies[0].pressure",
                   { ">= 0 [Pa]" });
  expectSceneError("bodies:\n  - " + box + ", friction: -0.5}\n", "bad.yaml:2: bodies[0].friction",
                   { "friction must be >= 0" });
  expectSceneError("bodies:\n  - {name: s, type: volume, resolution: 0.02, position: [0, 0, 1], "
                   "youngs_modulus: 5e4, density: 100, shape: box}\n",
                   "bad.yaml:2: bodies[0].shape", { "needs size" });
  // Only implicit_euler runs a volume's elasticity: another integrator is refused, not silently a cloud of
  // free nodes.
  try
  {
    buildWorld(parseScene("physics: {integrator: semi_implicit_euler}\nbodies:\n  - " + box + "}\n", "bad.yaml"));
    ADD_FAILURE() << "built a volume under semi_implicit_euler";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_NE(std::string(e.what()).find("implicit_euler"), std::string::npos) << e.what();
  }
}

TEST(SceneLoader, AVolumeOfAnOpenSurfaceIsRefusedAtItsMesh)
{
  // A cube of 5 cm as an ASCII STL with its last triangle missing: three edges in one triangle only.
  const std::string path = (std::filesystem::temp_directory_path() / "soft_body_sim_open_cube.stl").string();
  {
    const int quads[6][4] = { { 0, 2, 3, 1 }, { 4, 5, 7, 6 }, { 0, 1, 5, 4 }, { 2, 6, 7, 3 }, { 0, 4, 6, 2 }, { 1, 3, 7, 5 } };
    const auto corner = [](int k) {
      return Vec3(k & 1 ? 0.025 : -0.025, k & 2 ? 0.025 : -0.025, k & 4 ? 0.025 : -0.025);
    };
    std::ofstream file(path);
    file << "solid open\n";
    for (int q = 0; q < 6; ++q)
      for (int half = 0; half < (q == 5 ? 1 : 2); ++half)
      {
        file << " facet normal 0 0 0\n  outer loop\n";
        for (int k : { quads[q][0], quads[q][1 + half], quads[q][2 + half] })
          file << "   vertex " << corner(k).x() << " " << corner(k).y() << " " << corner(k).z() << "\n";
        file << "  endloop\n endfacet\n";
      }
    file << "endsolid open\n";
  }
  expectSceneError("bodies:\n  - {name: s, type: volume, shape: mesh, mesh: " + path +
                       ", resolution: 0.02, position: [0, 0, 1], youngs_modulus: 5e4, density: 100}\n",
                   "bad.yaml:2: bodies[0].mesh", { "not closed", path });
  std::remove(path.c_str());
}

TEST(SceneLoader, DirectoryCannotBeOpened)
{
  try
  {
    loadSceneFile(sceneDir());
    ADD_FAILURE() << "loaded a directory";
  }
  catch (const SceneError& e)
  {
    EXPECT_EQ(std::string(e.what()), sceneDir() + ": cannot open scene file: it is a directory, not a regular file");
  }
}

TEST(SceneLoader, ErrorsInAFileNameThePath)
{
  const std::string path = (std::filesystem::temp_directory_path() / "soft_body_sim_bad_scene.yaml").string();
  {
    std::ofstream file(path);
    file << "physics:\n  dt: -1\nbodies: [{name: b, type: custom, nodes: [{position: [0, 0, 0], mass: 1}]}]\n";
  }
  try
  {
    loadSceneFile(path);
    ADD_FAILURE() << "loaded a scene with dt -1";
  }
  catch (const SceneError& e)
  {
    EXPECT_EQ(std::string(e.what()), path + ":2: physics.dt: must be > 0, got -1");
  }
  std::remove(path.c_str());
}

}  // namespace
}  // namespace soft_body_sim

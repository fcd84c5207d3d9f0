// The headless simulator's command-line contract (other tools drive it): CSV layout, row times,
// precision, overrides, and one-line errors with a non-zero status.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "soft_body_sim/tools/camera_images.h"
#include "soft_body_sim/tools/simulate.h"
#include "test_util.h"

namespace soft_body_sim
{
namespace
{
// The TUM tutorial's exercise 1 (explicit Euler, h = 0.5): after two steps P1 = (2, 4) + 0.25 f u.
const char* const kTumScene = R"(
frame_id: world
physics: {integrator: explicit_euler, dt: 0.5, gravity: [0, 0, 0]}
bodies:
  - name: pair
    type: custom
    nodes:
      - {position: [2, 4, 0], mass: 1}
      - {position: [1, -3, 0], mass: 1}
    springs:
      - {nodes: [0, 1], stiffness: 2, rest_length: 4}
)";

std::string writeScene(const std::string& name, const std::string& text)
{
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

struct Outcome
{
  int status;
  std::string out;
  std::string err;
};

Outcome runWith(const std::vector<std::string>& args)
{
  std::ostringstream out, err;
  const int status = runSimulate(args, out, err);
  return { status, out.str(), err.str() };
}

std::vector<std::vector<std::string>> rows(const std::string& csv)
{
  std::vector<std::vector<std::string>> table;
  std::istringstream lines(csv);
  for (std::string line; std::getline(lines, line);)
  {
    std::vector<std::string> cells;
    std::istringstream fields(line);
    for (std::string cell; std::getline(fields, cell, ',');)
      cells.push_back(cell);
    table.push_back(cells);
  }
  return table;
}

TEST(Simulate, ReportsEachCatchOfTheDivergenceGuardOnStderr)
{
  test::expectGuardEvents();  // about divergence: the guard catches it
  // w h = 50 for symplectic Euler: the spring diverges within a few steps and the guard catches it.
  const std::string scene = writeScene("stiff.yaml", R"(physics:
  integrator: semi_implicit_euler
  dt: 0.05
  gravity: [0, 0, 0]
  guard: {policy: freeze}
bodies:
  - name: spring
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 1, pinned: true}
      - {position: [1.001, 0, 0], mass: 1}
    springs:
      - {nodes: [0, 1], stiffness: 1.0e6, rest_length: 1.0}
)");
  const Outcome r = runWith({ "--scene", scene, "--duration", "1" });
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string caught = "simulate: warning: body 'spring' diverged at t = ";
  ASSERT_NE(r.err.find(caught), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find(caught, r.err.find(caught) + 1), std::string::npos) << "reported more than once: " << r.err;
  EXPECT_NE(r.err.find("frozen (its free nodes pinned at rest)"), std::string::npos) << r.err;
  for (const auto& row : rows(r.out))
    for (const std::string& cell : row)
      EXPECT_EQ(cell.find("nan"), std::string::npos) << "a non-finite value in the CSV";
}

TEST(Simulate, WritesHeaderInitialAndFinalRowsAtFullPrecision)
{
  const std::string scene = writeScene("tum.yaml", kTumScene);
  const Outcome r = runWith({ "--scene", scene, "--duration", "1" });
  ASSERT_EQ(r.status, 0) << r.err;
  // The exercise's undamped spring makes explicit Euler gain energy: it is reported, once, on stderr.
  EXPECT_EQ(r.err.rfind("simulate: warning: explicit_euler: under-damped springs", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  const auto table = rows(r.out);
  ASSERT_EQ(table.size(), 5u);  // header, 2 nodes at t = 0, 2 nodes at t = 1
  EXPECT_EQ(table[0], (std::vector<std::string>{ "t", "body", "node", "x", "y", "z" }));
  EXPECT_EQ(table[1], (std::vector<std::string>{ "0", "pair", "0", "2", "4", "0" }));
  EXPECT_EQ(table[3][0], "1");
  EXPECT_EQ(table[3][1], "pair");
  EXPECT_EQ(table[3][2], "0");
  // 17 significant digits round-trip the double exactly.
  const double f = -2.0 * (5.0 * std::sqrt(2.0) - 4.0);
  const double expected_x = 2.0 + 0.25 * f / (5.0 * std::sqrt(2.0));
  EXPECT_EQ(std::stod(table[3][3]), expected_x);
  const std::string digits = table[3][3].substr(0, table[3][3].find('e'));
  EXPECT_EQ(std::count_if(digits.begin(), digits.end(), ::isdigit), 17) << table[3][3];
}

TEST(Simulate, RowsEveryKStepsAndAlwaysAfterTheLast)
{
  const std::string scene = writeScene("every.yaml", kTumScene);
  // round(2.6 / 0.5) = 5 steps; every 2 -> t = 0, 1, 2 and the last, 2.5.
  const Outcome r = runWith({ "--scene", scene, "--duration", "2.6", "--every", "2" });
  ASSERT_EQ(r.status, 0) << r.err;
  std::vector<std::string> times;
  for (const auto& row : rows(r.out))
    if (row[0] != "t" && row[2] == "0")
      times.push_back(row[0]);
  EXPECT_EQ(times, (std::vector<std::string>{ "0", "1", "2", "2.5" }));
}

TEST(Simulate, CommandLineOverridesTheSceneAndCsvGoesToTheFile)
{
  const std::string scene = writeScene("override.yaml", kTumScene);
  const std::string csv = ::testing::TempDir() + "override.csv";
  const Outcome r = runWith({ "--scene", scene, "--duration", "1", "--dt", "0.25", "--integrator", "rk4", "--substeps", "2",
                      "--iterations", "3", "--csv", csv });
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, "");
  std::ifstream file(csv);
  const std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  const auto table = rows(text);
  ASSERT_EQ(table.size(), 5u);
  EXPECT_EQ(table[3][0], "1");  // 4 steps of 0.25 s
  // rk4 at h = 0.125 differs from the explicit Euler answer of the file's settings.
  const double f = -2.0 * (5.0 * std::sqrt(2.0) - 4.0);
  EXPECT_NE(std::stod(table[3][3]), 2.0 + 0.25 * f / (5.0 * std::sqrt(2.0)));
}

TEST(Simulate, ForcesAndTensionsGoToTheirFilesAtTheRowsTimes)
{
  // A 0.5 kg mass hanging at rest from an anchored 0.1 kg node on a spring of 49.05 N/m, stretched
  // 0.1 m by the mass's weight: the spring's tension is 0.5 g, the anchor carries both weights; a 0.2 kg
  // ball rests on the named floor below them.
  const std::string scene = writeScene("hanging.yaml", R"(
frame_id: world
physics: {integrator: semi_implicit_euler, dt: 0.01, gravity: [0, 0, -9.81]}
bodies:
  - name: weight
    type: custom
    nodes:
      - {position: [0, 0, 0], mass: 0.1, pinned: true}
      - {position: [0, 0, -1.1], mass: 0.5}
    springs:
      - {nodes: [0, 1], stiffness: 49.05, rest_length: 1.0}
    anchors:
      - {name: hook, node: 0}
  - name: ball
    type: custom
    nodes:
      - {position: [1, 0, -2], mass: 0.2}
planes:
  - {name: floor, point: [0, 0, -2], normal: [0, 0, 1]}
)");
  const std::string forces = ::testing::TempDir() + "forces.csv";
  const std::string tensions = ::testing::TempDir() + "tensions.csv";
  const Outcome r = runWith({ "--scene", scene, "--duration", "0.1", "--every", "5", "--forces", forces,
                              "--tensions", tensions });
  ASSERT_EQ(r.status, 0) << r.err;
  const auto read = [](const std::string& path) {
    std::ifstream file(path);
    return rows(std::string((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>()));
  };
  const auto force_rows = read(forces);
  ASSERT_EQ(force_rows.size(), 7u);  // header, then the hook and the floor at t = 0, 0.05, 0.1
  EXPECT_EQ(force_rows[0], (std::vector<std::string>{ "t", "body", "anchor", "fx", "fy", "fz", "tx", "ty", "tz" }));
  EXPECT_EQ(force_rows[3][0], "0.050000000000000003");
  EXPECT_EQ(force_rows[5][1], "weight");
  EXPECT_EQ(force_rows[5][2], "hook");
  EXPECT_NEAR(std::stod(force_rows[5][5]), -0.6 * 9.81, 1e-9);
  for (int column : { 3, 4, 6, 7, 8 })
    EXPECT_NEAR(std::stod(force_rows[5][column]), 0.0, 1e-12) << column;
  // The ball resting on the floor, 1 m from its point: its weight, and about the point the torque
  // (1, 0, 0) x (0, 0, -m g) = (0, m g, 0).
  EXPECT_EQ(force_rows[6][1], "");
  EXPECT_EQ(force_rows[6][2], "floor");
  EXPECT_NEAR(std::stod(force_rows[6][5]), -0.2 * 9.81, 1e-9);
  EXPECT_NEAR(std::stod(force_rows[6][7]), 0.2 * 9.81, 1e-9);
  for (int column : { 3, 4, 6, 8 })
    EXPECT_NEAR(std::stod(force_rows[6][column]), 0.0, 1e-12) << column;
  const auto tension_rows = read(tensions);
  ASSERT_EQ(tension_rows.size(), 4u);
  EXPECT_EQ(tension_rows[0], (std::vector<std::string>{ "t", "body", "kind", "index", "a", "b", "tension" }));
  EXPECT_EQ(tension_rows[3], (std::vector<std::string>{ "0.10000000000000001", "weight", "spring", "0", "0", "1",
                                                        tension_rows[3][6] }));
  EXPECT_NEAR(std::stod(tension_rows[3][6]), 0.5 * 9.81, 1e-9);
}

TEST(Simulate, ImagesWritesEachCamerasFramesAtItsRateAsPngs)
{
  // A camera at rate 10 Hz over 0.25 s: frames 0, 1 and 2 (t = 0, 0.1, 0.2). It looks along +x at a box's
  // face 1.5 m away, which fills its 21 x 11 px: every depth 1500 mm, every mask 1000 (the box). A camera on
  // a tf frame takes none, with a note.
  const std::string scene = writeScene("camera.yaml", R"(
physics: {integrator: semi_implicit_euler, dt: 0.05}
colliders: [{name: wall, shape: box, size: [0.2, 10, 10], position: [1.6, 0, 1]}]
cameras:
  - {name: eye, position: [0, 0, 1], width: 21, height: 11, rate: 10}
  - {name: wrist, frame: hand}
bodies: [{name: b, type: custom, nodes: [{position: [-5, 0, 1], mass: 1, pinned: true}]}]
)");
  const std::string directory = ::testing::TempDir() + "images";
  std::filesystem::create_directories(directory);
  const Outcome r = runWith({ "--scene", scene, "--duration", "0.25", "--images", directory });
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("camera 'wrist' rides on tf frame 'hand'"), std::string::npos) << r.err;
  for (const char* frame : { "000000", "000001", "000002" })
  {
    const GreyImage16 depth = readGreyPng16(directory + "/eye_depth_" + frame + ".png");
    ASSERT_EQ(depth.width, 21);
    ASSERT_EQ(depth.height, 11);
    for (const std::uint16_t mm : depth.samples)
      ASSERT_EQ(mm, 1500);
    for (const std::uint16_t mask : readGreyPng16(directory + "/eye_mask_" + frame + ".png").samples)
      ASSERT_EQ(mask, 1000);
    EXPECT_TRUE(std::filesystem::exists(directory + "/eye_color_" + std::string(frame) + ".png"));
  }
  EXPECT_FALSE(std::filesystem::exists(directory + "/eye_depth_000003.png"));
}

struct BadInput
{
  const char* name;
  std::vector<std::string> args;  ///< "SCENE" stands for a valid scene file
  const char* reason;             ///< a substring of the one-line message
};

class SimulateRejects : public ::testing::TestWithParam<BadInput>
{
};

TEST_P(SimulateRejects, WithOneLineAndNonZeroStatus)
{
  const std::string scene = writeScene("valid.yaml", kTumScene);
  std::vector<std::string> args = GetParam().args;
  for (std::string& a : args)
    if (a == "SCENE")
      a = scene;
  const Outcome r = runWith(args);
  EXPECT_NE(r.status, 0);
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(GetParam().reason), std::string::npos) << r.err;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, SimulateRejects,
    ::testing::Values(BadInput{ "NoScene", {}, "--scene is required" },
                      BadInput{ "UnknownOption", { "--scene", "SCENE", "--speed", "2" }, "unknown option '--speed'" },
                      BadInput{ "MissingValue", { "--scene", "SCENE", "--dt" }, "--dt: missing value" },
                      BadInput{ "NegativeDt", { "--scene", "SCENE", "--dt", "-1" }, "--dt: must be > 0" },
                      BadInput{ "ZeroDt", { "--scene", "SCENE", "--dt", "0" }, "--dt: must be > 0" },
                      BadInput{ "TextDt", { "--scene", "SCENE", "--dt", "fast" }, "--dt: expected a finite number" },
                      BadInput{ "NanDuration", { "--scene", "SCENE", "--duration", "nan" }, "--duration: expected a finite" },
                      BadInput{ "NegativeDuration", { "--scene", "SCENE", "--duration", "-2" }, "--duration: must be >= 0" },
                      BadInput{ "ZeroSubsteps", { "--scene", "SCENE", "--substeps", "0" }, "--substeps: expected an integer >= 1" },
                      BadInput{ "FractionalIterations", { "--scene", "SCENE", "--iterations", "1.5" }, "--iterations: expected an integer" },
                      BadInput{ "ZeroEvery", { "--scene", "SCENE", "--every", "0" }, "--every: expected an integer >= 1" },
                      BadInput{ "UnknownIntegrator", { "--scene", "SCENE", "--integrator", "euler" }, "unknown integrator 'euler' (valid: explicit_euler," },
                      BadInput{ "MissingSceneFile", { "--scene", "/nonexistent/scene.yaml" }, "/nonexistent/scene.yaml: cannot open" },
                      BadInput{ "UnwritableCsv", { "--scene", "SCENE", "--csv", "/nonexistent/out.csv" }, "--csv: cannot write" },
                      BadInput{ "UnwritableForces", { "--scene", "SCENE", "--forces", "/nonexistent/f.csv" }, "--forces: cannot write" },
                      BadInput{ "GivenTwice", { "--scene", "SCENE", "--dt", "1", "--dt", "2" }, "--dt: given twice" },
                      BadInput{ "NoImageDirectory", { "--scene", "SCENE", "--images", "/nonexistent" }, "--images: no directory" },
                      BadInput{ "ImagesWithoutCameras", { "--scene", "SCENE", "--images", "/tmp" }, "--images: the scene declares no cameras" }),
    [](const ::testing::TestParamInfo<BadInput>& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace soft_body_sim

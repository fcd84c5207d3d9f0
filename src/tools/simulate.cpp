#include "soft_body_sim/tools/simulate.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>

#include "soft_body_sim/core/sensing/depth_camera.h"
#include "soft_body_sim/core/stability.h"
#include "soft_body_sim/scene/scene_loader.h"
#include "soft_body_sim/tools/camera_images.h"

namespace soft_body_sim
{
namespace
{
/// Bad command-line input; what() is the one-line reason.
struct UsageError : std::runtime_error
{
  using std::runtime_error::runtime_error;
};

const char* const kUsage =
    "usage: simulate --scene FILE [--duration S] [--integrator NAME] [--dt S] [--substeps N] "
    "[--iterations N] [--every K] [--csv FILE] [--forces FILE] [--tensions FILE] [--images DIR]";

struct Options
{
  std::string scene;
  double duration = 1.0;  ///< [s]
  std::optional<std::string> integrator;
  std::optional<double> dt;
  bool auto_dt = false;  ///< --dt auto
  std::optional<int> substeps;
  std::optional<int> iterations;
  std::optional<long long> every;
  std::optional<std::string> csv;
  std::optional<std::string> forces;    ///< anchors' and colliders' wrenches
  std::optional<std::string> tensions;  ///< links' tensions
  std::optional<std::string> images;    ///< a directory for the cameras' frames
};

double parseNumber(const std::string& option, const std::string& text)
{
  std::size_t used = 0;
  double value = 0.0;
  try
  {
    value = std::stod(text, &used);
  }
  catch (const std::exception&)
  {
    used = 0;
  }
  if (used != text.size() || text.empty() || !std::isfinite(value))
    throw UsageError(option + ": expected a finite number, got '" + text + "'");
  return value;
}

long long parsePositiveInteger(const std::string& option, const std::string& text)
{
  std::size_t used = 0;
  long long value = 0;
  try
  {
    value = std::stoll(text, &used);
  }
  catch (const std::exception&)
  {
    used = 0;
  }
  if (used != text.size() || text.empty() || value < 1)
    throw UsageError(option + ": expected an integer >= 1, got '" + text + "'");
  return value;
}

Options parseOptions(const std::vector<std::string>& args)
{
  Options options;
  std::map<std::string, std::string> values;
  for (std::size_t k = 0; k < args.size(); k += 2)
  {
    const std::string& option = args[k];
    static const char* const kKnown[] = { "--scene", "--duration", "--integrator", "--dt",
                                          "--substeps", "--iterations", "--every", "--csv",
                                          "--forces", "--tensions", "--images" };
    if (std::find(std::begin(kKnown), std::end(kKnown), option) == std::end(kKnown))
      throw UsageError("unknown option '" + option + "'; " + kUsage);
    if (k + 1 >= args.size())
      throw UsageError(option + ": missing value");
    if (!values.emplace(option, args[k + 1]).second)
      throw UsageError(option + ": given twice");
  }
  if (!values.count("--scene"))
    throw UsageError(std::string("--scene is required; ") + kUsage);
  options.scene = values["--scene"];
  if (values.count("--duration"))
  {
    options.duration = parseNumber("--duration", values["--duration"]);
    if (options.duration < 0.0)
      throw UsageError("--duration: must be >= 0, got '" + values["--duration"] + "'");
  }
  if (values.count("--integrator"))
    options.integrator = values["--integrator"];
  if (values.count("--dt") && values["--dt"] == "auto")
    options.auto_dt = true;
  else if (values.count("--dt"))
  {
    options.dt = parseNumber("--dt", values["--dt"]);
    if (!(*options.dt > 0.0))
      throw UsageError("--dt: must be > 0 or auto, got '" + values["--dt"] + "'");
  }

  const long long int_max = std::numeric_limits<int>::max();
  if (values.count("--substeps"))
    options.substeps = static_cast<int>(std::min(int_max, parsePositiveInteger("--substeps", values["--substeps"])));
  if (values.count("--iterations"))
    options.iterations =
        static_cast<int>(std::min(int_max, parsePositiveInteger("--iterations", values["--iterations"])));
  if (values.count("--every"))
    options.every = parsePositiveInteger("--every", values["--every"]);
  if (values.count("--csv"))
    options.csv = values["--csv"];
  if (values.count("--forces"))
    options.forces = values["--forces"];
  if (values.count("--tensions"))
    options.tensions = values["--tensions"];
  if (values.count("--images"))
  {
    options.images = values["--images"];
    if (!std::filesystem::is_directory(*options.images))
      throw UsageError("--images: no directory '" + *options.images + "'");
  }
  return options;
}

/// Command-line values replace the scene file's.
void applyOverrides(const Options& options, SceneDef& scene)
{
  if (options.integrator && !integratorFromName(*options.integrator, scene.physics.integrator))
  {
    std::string valid;
    for (const std::string& name : integratorNames())
      valid += (valid.empty() ? "" : ", ") + name;
    throw UsageError("--integrator: unknown integrator '" + *options.integrator + "' (valid: " + valid + ")");
  }
  if (options.dt)
  {
    scene.physics.step.dt = *options.dt;
    scene.physics.auto_dt = false;
  }
  if (options.auto_dt)
    scene.physics.auto_dt = true;
  if (options.substeps)
    scene.physics.step.substeps = *options.substeps;
  if (options.iterations)
    scene.physics.step.iterations = *options.iterations;
}

void writeRows(std::ostream& csv, const World& world)
{
  const double t = world.time();
  for (const BodyRange& body : world.model().bodies)
  {
    for (int k = 0; k < body.count; ++k)
    {
      const auto x = world.state().position.col(body.first + k);
      csv << t << ',' << body.name << ',' << k << ',' << x.x() << ',' << x.y() << ',' << x.z() << '\n';
    }
  }
}

/// Per anchor, the wrench its body exerts on it (World::anchorWrenches); then per named collider, with an
/// empty body (no body is unnamed), the wrench the bodies exerted on it over the last step
/// (World::colliderWrenches).
void writeForces(std::ostream& csv, const World& world)
{
  const std::vector<Wrench> wrenches = world.anchorWrenches();
  for (std::size_t k = 0; k < wrenches.size(); ++k)
  {
    const Anchor& anchor = world.model().anchors[k];
    const Vec3& f = wrenches[k].force;
    const Vec3& m = wrenches[k].torque;
    csv << world.time() << ',' << anchor.body << ',' << anchor.name << ',' << f.x() << ',' << f.y() << ',' << f.z()
        << ',' << m.x() << ',' << m.y() << ',' << m.z() << '\n';
  }
  for (const ColliderWrench& collider : world.colliderWrenches())
  {
    const Vec3& f = collider.wrench.force;
    const Vec3& m = collider.wrench.torque;
    csv << world.time() << ",," << collider.name << ',' << f.x() << ',' << f.y() << ',' << f.z() << ',' << m.x()
        << ',' << m.y() << ',' << m.z() << '\n';
  }
}

/// Per spring and constraint, its tension (World::linkTensions), with its body, its place among the body's
/// springs (constraints) and its ends' indices in the body. buildWorld adds each body's links in order.
void writeTensions(std::ostream& csv, const World& world)
{
  const Model& model = world.model();
  const Eigen::VectorXd tension = world.linkTensions();
  std::vector<int> count(model.bodies.size());
  const auto row = [&](const char* kind, int a, int b, double t) {
    const std::size_t body = model.bodyOf(a);
    const int first = model.bodies[body].first;
    csv << world.time() << ',' << model.bodies[body].name << ',' << kind << ',' << count[body]++ << ','
        << a - first << ',' << b - first << ',' << t << '\n';
  };
  for (std::size_t k = 0; k < model.springs.size(); ++k)
    row("spring", model.springs[k].a, model.springs[k].b, tension[static_cast<Eigen::Index>(k)]);
  std::fill(count.begin(), count.end(), 0);
  for (std::size_t k = 0; k < model.constraints.size(); ++k)
    row("constraint", model.constraints[k].a, model.constraints[k].b,
        tension[static_cast<Eigen::Index>(model.springs.size() + k)]);
}

/// An output file named by `option`, or none.
/// The scene's cameras that take pictures without ROS, each with its next frame number: one on a tf frame
/// does not (noted on `err`), as a collider on one never appears.
struct Photographer
{
  const CameraDef* def = nullptr;
  std::unique_ptr<DepthCamera> camera;
  CameraImage image;  ///< its buffers reused frame after frame
  std::uint64_t frame = 0;

  /// Writes every frame due by the world's time: frame n at n / rate.
  void shoot(const World& world, const std::string& directory)
  {
    while (static_cast<double>(frame) / def->rate <= world.time() + 1e-9 / def->rate)
    {
      const RigidPose link{ def->position, def->orientation.normalized() };
      camera->render(world.state(), world.colliderPoses(), link, frame, image);
      writeCameraImages(directory, def->name, frame, image);
      ++frame;
    }
  }
};

std::vector<Photographer> photographers(const SceneDef& scene, const World& world, std::ostream& err)
{
  if (scene.cameras.empty())
    throw UsageError("--images: the scene declares no cameras");
  std::vector<Photographer> all;
  for (const CameraDef& camera : scene.cameras)
    if (camera.frame.empty())
      all.push_back({ &camera, std::make_unique<DepthCamera>(camera, world.model()), CameraImage{}, 0 });
    else
      err << "simulate: note: camera '" << camera.name << "' rides on tf frame '" << camera.frame
          << "': without tf it takes no pictures\n";
  return all;
}

std::optional<std::ofstream> openOutput(const std::string& option, const std::optional<std::string>& path)
{
  if (!path)
    return std::nullopt;
  std::ofstream file(*path);
  if (!file)
    throw UsageError(option + ": cannot write '" + *path + "'");
  file << std::setprecision(17);
  return file;
}

void simulate(const Options& options, std::ostream& out, std::ostream& err)
{
  SceneDef scene = loadSceneFile(options.scene);
  applyOverrides(options, scene);
  World world = buildWorld(scene);
  const long long steps = std::llround(options.duration / world.settings().dt);

  std::optional<std::ofstream> file = openOutput("--csv", options.csv);
  std::optional<std::ofstream> forces = openOutput("--forces", options.forces);
  std::optional<std::ofstream> tensions = openOutput("--tensions", options.tensions);
  std::vector<Photographer> cameras = options.images ? photographers(scene, world, err) : std::vector<Photographer>();
  if (scene.physics.auto_dt)
    err << "simulate: note: dt auto chose dt = " << world.settings().dt << " s in " << world.settings().substeps
        << " sub-step(s) for " << integratorName(world.integrator()) << '\n';
  // Reported, not clamped: the run goes ahead with the scene as written (after the last input check,
  // so that bad input still gets its one line).
  for (const std::string& warning : stabilityWarnings(world.model(), world.state(), world.integrator(), world.settings()))
    err << "simulate: warning: " << warning << '\n';
  std::ostream& csv = file ? *file : out;
  csv << std::setprecision(17) << "t,body,node,x,y,z\n";
  if (forces)
    *forces << "t,body,anchor,fx,fy,fz,tx,ty,tz\n";
  if (tensions)
    *tensions << "t,body,kind,index,a,b,tension\n";
  const auto record = [&] {
    writeRows(csv, world);
    if (forces)
      writeForces(*forces, world);
    if (tensions)
      writeTensions(*tensions, world);
  };
  const auto shoot = [&] {
    for (Photographer& camera : cameras)
      camera.shoot(world, *options.images);
  };
  record();
  shoot();
  for (long long n = 1; n <= steps; ++n)
  {
    world.step();
    for (const DivergenceEvent& event : world.takeDivergenceEvents())
      err << "simulate: warning: " << event.describe() << '\n';
    if (n == steps || (options.every && n % *options.every == 0))
      record();
    shoot();
  }
  csv.flush();
  if (!csv || (forces && !forces->flush()) || (tensions && !tensions->flush()))
    throw UsageError("failed writing the CSV output");
}
}  // namespace

int runSimulate(const std::vector<std::string>& args, std::ostream& out, std::ostream& err)
{
  try
  {
    simulate(parseOptions(args), out, err);
    return 0;
  }
  catch (const std::exception& e)
  {
    err << "simulate: " << e.what() << '\n';
    return 2;
  }
}

}  // namespace soft_body_sim

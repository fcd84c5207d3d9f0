// The Python module soft_body_sim.sim (pybind11): a World loaded from a scene file, its snapshots and
// batched rollouts (docs/python.md). What Python is told of bad input: a name the scene does not know is a
// sim.UnknownName (a KeyError) naming the known ones; an array of the wrong shape or a number that is not finite a ValueError;
// a scene file the loader refuses a sim.SceneError (a ValueError) with the loader's one line; whatever the
// core refuses (std::invalid_argument: another scene's snapshot, a grasp with no node in reach) a ValueError
// with the core's message.
#include <sched.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <thread>

#include <pybind11/eval.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "python/holder.h"
#include "python/names.h"
#include "python/python_world.h"
#include "python/rollouts.h"
#include "soft_body_sim/core/format_number.h"
#include "soft_body_sim/scene/scene_loader.h"

namespace py = pybind11;

namespace soft_body_sim::python
{
namespace
{
/// Doubles in C order, converted from whatever numpy can convert.
using Numbers = py::array_t<double, py::array::c_style | py::array::forcecast>;

std::string shapeOf(const py::array& array)
{
  std::string text = "(";
  for (py::ssize_t k = 0; k < array.ndim(); ++k)
    text += (k ? ", " : "") + std::to_string(array.shape(k));
  return text + (array.ndim() == 1 ? ",)" : ")");
}

/// `value` (a sequence or an array) as doubles; ValueError naming `what` if numpy cannot make numbers of it.
Numbers numbers(const py::handle& value, const std::string& what)
{
  Numbers array = Numbers::ensure(value);
  if (!array)
    throw py::value_error(what + ": expected numbers, got " + py::repr(value).cast<std::string>());
  return array;
}

/// `value` as `size` finite numbers (shape (size,)); ValueError naming `what` otherwise.
Numbers finiteVector(const py::handle& value, py::ssize_t size, const std::string& what)
{
  Numbers array = numbers(value, what);
  if (array.ndim() != 1 || array.shape(0) != size)
    throw py::value_error(what + ": expected " + std::to_string(size) + " numbers, got an array of shape " +
                          shapeOf(array));
  for (py::ssize_t k = 0; k < size; ++k)
    if (!std::isfinite(array.at(k)))
      throw py::value_error(what + ": not finite: " + py::repr(value).cast<std::string>());
  return array;
}

/// A position [m]: 3 finite numbers.
Vec3 position(const py::handle& value, const std::string& what = "position")
{
  const Numbers array = finiteVector(value, 3, what);
  return Vec3(array.at(0), array.at(1), array.at(2));
}

/// True if x, y, z, w can be normalized: their squared norm is > 0 and finite.
bool normalizable(double x, double y, double z, double w)
{
  const double squared = x * x + y * y + z * z + w * w;
  return squared > 0.0 && std::isfinite(squared);
}

const char* const kNoOrientation = ": no orientation: a quaternion's norm must be > 0 (and its square finite)";

/// An orientation: 4 finite numbers x, y, z, w (ROS's order) that normalize, as given (the core normalizes
/// every orientation it is sent, as it does rollouts').
Eigen::Quaterniond orientation(const py::handle& value, const std::string& what = "orientation")
{
  const Numbers array = finiteVector(value, 4, what);
  if (!normalizable(array.at(0), array.at(1), array.at(2), array.at(3)))
    throw py::value_error(what + kNoOrientation);
  return Eigen::Quaterniond(array.at(3), array.at(0), array.at(1), array.at(2));
}

/// A new (rows, 3) array of the 3 x rows column-major block at `data` (a NodeArray's columns).
py::array_t<double> rows3(const double* data, py::ssize_t rows)
{
  py::array_t<double> array({ rows, py::ssize_t{ 3 } });
  std::memcpy(array.mutable_data(), data, static_cast<std::size_t>(rows) * 3 * sizeof(double));
  return array;
}

py::array_t<double> vector3(const Vec3& v) { return py::array_t<double>(3, v.data()); }

/// A node array's columns of body `body` (None: every node) as (N, 3).
py::array_t<double> nodeRows(const World& world, const NodeArray& array, const py::object& body)
{
  if (body.is_none())
    return rows3(array.data(), array.cols());
  const BodyRange& range = world.model().bodies[findBody(world.model(), body.cast<std::string>())];
  return rows3(array.col(range.first).data(), range.count);
}

py::tuple wrench(const Wrench& w) { return py::make_tuple(vector3(w.force), vector3(w.torque)); }

/// The CPUs this process may run on (a container's or taskset's limit, which hardware_concurrency ignores).
int cores()
{
  cpu_set_t set;
  if (sched_getaffinity(0, sizeof set, &set) == 0)
    return std::max(1, CPU_COUNT(&set));
  return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

/// sim.rollouts: checks the input, copies the world, runs runRollouts without the GIL.
py::array_t<double> rollouts(const PythonWorld& w, const std::string& holder_name, const py::object& goals_value,
                             int steps_per_goal, int threads)
{
  if (steps_per_goal < 1)
    throw py::value_error("steps_per_goal: must be >= 1, got " + std::to_string(steps_per_goal));
  if (threads < 0)
    throw py::value_error("threads: must be >= 0 (0: one per core), got " + std::to_string(threads));
  const Numbers goals = numbers(goals_value, "goals");
  if (goals.ndim() != 3 || (goals.shape(2) != 3 && goals.shape(2) != 7))
    throw py::value_error("goals: expected shape (B, T, 3) positions or (B, T, 7) poses (x, y, z, qx, qy, qz, qw), "
                          "got " + shapeOf(goals));
  GoalBatch batch{ goals.data(), static_cast<std::size_t>(goals.shape(0)), static_cast<std::size_t>(goals.shape(1)),
                   static_cast<int>(goals.shape(2)) };
  for (std::size_t b = 0; b < batch.rollouts; ++b)
    for (std::size_t t = 0; t < batch.count; ++t)
    {
      const double* goal = batch.goals + (b * batch.count + t) * static_cast<std::size_t>(batch.width);
      const auto where = [b, t] { return "goals[" + std::to_string(b) + ", " + std::to_string(t) + "]"; };
      if (!std::all_of(goal, goal + batch.width, [](double x) { return std::isfinite(x); }))
        throw py::value_error(where() + " is not finite");
      if (batch.width == 7 && !normalizable(goal[3], goal[4], goal[5], goal[6]))
        throw py::value_error(where() + kNoOrientation);
    }
  // A copy taken under the world's lock: the workers read it while other Python threads may change `w`.
  const World source = w.read([](const World& world) { return world; });
  const Holder holder = Holder::find(source, holder_name);
  const auto nodes = static_cast<py::ssize_t>(source.model().nodeCount());
  py::array_t<double> out({ static_cast<py::ssize_t>(batch.rollouts), static_cast<py::ssize_t>(batch.count), nodes,
                            py::ssize_t{ 3 } });
  const auto wanted = static_cast<std::size_t>(threads == 0 ? cores() : threads);
  const int workers = static_cast<int>(std::max<std::size_t>(1, std::min(wanted, batch.rollouts)));
  double* data = out.mutable_data();
  {
    py::gil_scoped_release release;
    runRollouts(source, holder, batch, steps_per_goal, workers, data);
  }
  return out;
}

py::object pathString(const py::object& path) { return py::module_::import("os").attr("fspath")(path); }

/// WorldSnapshot::fromBytes of any bytes-like object (bytes, bytearray, memoryview).
WorldSnapshot snapshotOfBytes(const py::object& data)
{
  const auto bytes = py::reinterpret_steal<py::bytes>(PyBytes_FromObject(data.ptr()));
  if (!bytes)
    throw py::error_already_set();  // a TypeError naming what is not bytes-like
  return WorldSnapshot::fromBytes(static_cast<std::string>(bytes));
}

}  // namespace
}  // namespace soft_body_sim::python

PYBIND11_MODULE(sim, m)
{
  using namespace soft_body_sim;
  using namespace soft_body_sim::python;

  m.doc() = "The soft-body simulator as a library: a World loaded from a scene file, as the headless `simulate` "
            "loads it, stepped, driven, snapshotted and cloned, and batched rollouts on threads (docs/python.md).";

  py::register_exception<SceneError>(m, "SceneError", PyExc_ValueError);
  // A KeyError whose str() is its message: KeyError's own shows the repr of it, every quote escaped.
  py::dict scope;
  scope["__builtins__"] = py::module_::import("builtins");
  py::exec(R"(
class UnknownName(KeyError):
    """A body, anchor, grasp or collider that the scene does not know; the message names those it knows."""
    __module__ = "soft_body_sim.sim"

    def __str__(self):
        return str(self.args[0]) if self.args else ""
)",
           scope);
  m.attr("UnknownName") = scope["UnknownName"];
  static const py::handle unknown_name = m.attr("UnknownName");  // the module keeps it alive
  py::register_exception_translator([](std::exception_ptr error) {
    try
    {
      if (error)
        std::rethrow_exception(error);
    }
    catch (const UnknownName& e)
    {
      PyErr_SetString(unknown_name.ptr(), e.what());
    }
  });

  py::class_<DivergenceEvent>(m, "DivergenceEvent", "A body the divergence guard caught (docs/physics.md).")
      .def_readonly("body", &DivergenceEvent::body)
      .def_readonly("time", &DivergenceEvent::time, "[s] simulated, at the end of the step that diverged")
      .def_readonly("reason", &DivergenceEvent::reason)
      .def_readonly("action", &DivergenceEvent::action, "what the guard's policy did")
      .def("__str__", &DivergenceEvent::describe)
      .def("__repr__", [](const DivergenceEvent& e) { return "<DivergenceEvent " + e.describe() + ">"; });

  py::class_<WorldSnapshot>(m, "Snapshot",
                            "A moment of a world (World.snapshot), to go back to with World.restore; bytes "
                            "(to_bytes, from_bytes) and pickle carry it to a file or another process.")
      .def_property_readonly("time", &WorldSnapshot::time, "[s] the world's simulated time then")
      .def_property_readonly("step_count", &WorldSnapshot::stepCount)
      .def("to_bytes", [](const WorldSnapshot& s) { return py::bytes(s.toBytes()); },
           "The snapshot as bytes: a versioned header with the scene's fingerprint, then every value of it.")
      .def_static("from_bytes", &snapshotOfBytes, py::arg("data"),
                  "A snapshot of to_bytes' bytes (or a bytearray, a memoryview), to restore into a world of the "
                  "same scene; ValueError, saying why, for bytes that are no snapshot, damaged or cut short.")
      .def("__copy__", [](const WorldSnapshot& s) { return s; })
      .def("__deepcopy__", [](const WorldSnapshot& s, const py::dict&) { return s; }, py::arg("memo"))
      .def(py::pickle([](const WorldSnapshot& s) { return py::make_tuple(py::bytes(s.toBytes())); },
                      [](const py::tuple& state) { return snapshotOfBytes(state[0]); }));

  py::class_<PythonWorld>(m, "World",
                          "A running simulation of a scene file: the same loader, messages and world as `simulate`.")
      .def(py::init([](const py::object& scene) {
             const std::string path = pathString(scene).cast<std::string>();
             py::gil_scoped_release release;  // a solid's meshing takes seconds
             return std::make_unique<PythonWorld>(path);
           }),
           py::arg("scene"), "Loads a scene file; sim.SceneError with the loader's line if it refuses it.")
      .def_static(
          "from_yaml",
          [](const std::string& text, const py::object& source) {
            const std::string path = pathString(source).cast<std::string>();
            py::gil_scoped_release release;
            return std::make_unique<PythonWorld>(text, path);
          },
          py::arg("text"), py::arg("source"),
          "A world of scene YAML text, parsed as if it were the file `source` (which need not exist): meshes "
          "by a relative path are found from source's folder, and sim.SceneError's line names source. The "
          "same bits as World(path) of a file holding the text.")
      .def(
          "step",
          [](PythonWorld& w, std::int64_t steps) {
            if (steps < 0)
              throw py::value_error("steps: must be >= 0, got " + std::to_string(steps));
            py::gil_scoped_release release;
            w.step(steps);
          },
          py::arg("steps") = 1, "Takes `steps` steps of dt, without holding the GIL.")
      .def_property_readonly("scene", &PythonWorld::scene, "the scene file's path as given")
      .def_property_readonly("time", [](const PythonWorld& w) { return w.read([](const World& world) { return world.time(); }); },
                             "[s] simulated time")
      .def_property_readonly("dt", [](const PythonWorld& w) { return w.read([](const World& world) { return world.settings().dt; }); },
                             "[s] one step (the scene's, or what `dt: auto` chose)")
      .def_property_readonly("step_count", [](const PythonWorld& w) { return w.read([](const World& world) { return world.stepCount(); }); })
      .def_property_readonly("bodies",
                             [](const PythonWorld& w) {
                               return w.read([](const World& world) {
                                 std::vector<std::string> names;
                                 for (const BodyRange& body : world.model().bodies)
                                   names.push_back(body.name);
                                 return names;
                               });
                             },
                             "the bodies' names, in the scene's order (the order of the nodes)")
      .def(
          "anchors",
          [](const PythonWorld& w, const std::string& body) {
            return w.read([&](const World& world) {
              findBody(world.model(), body);
              std::vector<std::string> names;
              for (const Anchor& anchor : world.model().anchors)
                if (anchor.body == body)
                  names.push_back(anchor.name);
              return names;
            });
          },
          py::arg("body"), "The names of body `body`'s anchors.")
      .def(
          "node_slice",
          [](const PythonWorld& w, const std::string& body) {
            return w.read([&](const World& world) {
              const BodyRange& range = world.model().bodies[findBody(world.model(), body)];
              return py::slice(range.first, range.first + range.count, 1);
            });
          },
          py::arg("body"), "Where body `body`'s nodes are among all nodes: positions()[w.node_slice(body)].")
      .def(
          "positions",
          [](const PythonWorld& w, const py::object& body) {
            return w.read([&](const World& world) { return nodeRows(world, world.state().position, body); });
          },
          py::arg("body") = py::none(), "[m] (N, 3) float64, a copy: body `body`'s nodes, or every node (None).")
      .def(
          "velocities",
          [](const PythonWorld& w, const py::object& body) {
            return w.read([&](const World& world) { return nodeRows(world, world.state().velocity, body); });
          },
          py::arg("body") = py::none(), "[m/s] (N, 3) float64, a copy: body `body`'s nodes, or every node (None).")
      .def(
          "pose",
          [](const PythonWorld& w, const std::string& holder) {
            const RigidPose pose = w.read([&](const World& world) { return Holder::find(world, holder).pose(world); });
            const Eigen::Quaterniond& q = pose.orientation;
            const double values[7] = { pose.position.x(), pose.position.y(), pose.position.z(), q.x(), q.y(), q.z(), q.w() };
            return py::array_t<double>(7, values);
          },
          py::arg("holder"),
          "[x, y, z, qx, qy, qz, qw] of a holder, as rollouts names it: an anchor \"body/anchor\" (its node; turned "
          "as its rod end is, else identity) or a grasp's frame.")
      .def(
          "move_anchor",
          [](PythonWorld& w, const std::string& body, const std::string& anchor, const py::object& to,
             const py::object& turn) {
            const Vec3 p = position(to);
            const bool turns = !turn.is_none();
            const Eigen::Quaterniond q = turns ? orientation(turn) : Eigen::Quaterniond::Identity();
            w.change([&](World& world) {
              const int k = findAnchor(world, body, anchor);
              if (turns)
                world.moveAnchor(k, p, q);
              else
                world.moveAnchor(k, p);
            });
          },
          py::arg("body"), py::arg("anchor"), py::arg("position"), py::arg("orientation") = py::none(),
          "Moves the anchor to `position` [m] during the next step (the latest call before a step wins); an "
          "anchor on a rod also turns to `orientation` [x, y, z, w].")
      .def(
          "set_target",
          [](PythonWorld& w, const std::string& body, const py::object& target) {
            const Vec3 p = position(target, "target");
            w.change([&](World& world) {
              const std::size_t b = findBody(world.model(), body);
              if (!world.takesTarget(b))
              {
                std::vector<std::string> takers;
                for (std::size_t k = 0; k < world.model().bodies.size(); ++k)
                  if (world.takesTarget(k))
                    takers.push_back(world.model().bodies[k].name);
                throw py::value_error("body '" + body + "' takes no target; those that do: " + listed(takers));
              }
              world.setTarget(body, p);
            });
          },
          py::arg("body"), py::arg("target"), "Sends a creature or humanoid toward `target` [m].")
      .def(
          "grasp",
          [](PythonWorld& w, const std::string& frame, const std::string& body, const py::object& at, double radius,
             const py::object& turn, double max_force) {
            const RigidPose pose{ position(at), turn.is_none() ? Eigen::Quaterniond::Identity() : orientation(turn) };
            return w.change([&](World& world) {
              findBody(world.model(), body);
              return world.grasp(frame, body, pose, radius, max_force);
            });
          },
          py::arg("frame"), py::arg("body"), py::arg("position"), py::kw_only(), py::arg("radius"),
          py::arg("orientation") = py::none(), py::arg("max_force") = std::numeric_limits<double>::infinity(),
          "Holds every free node of `body` within `radius` [m] of `position` rigidly in a frame `frame` at that "
          "pose, until release; slips above `max_force` [N]. Returns how many nodes it holds.")
      .def(
          "move_grasp",
          [](PythonWorld& w, const std::string& frame, const py::object& to, const py::object& turn) {
            const Vec3 p = position(to);
            const bool turns = !turn.is_none();
            const Eigen::Quaterniond q = turns ? orientation(turn) : Eigen::Quaterniond::Identity();
            w.change([&](World& world) {
              const GraspedNodes& grasp = world.grasps()[findGrasp(world, frame)];
              world.moveGrasp(frame, RigidPose{ p, turns ? q : grasp.pose.orientation });
            });
          },
          py::arg("frame"), py::arg("position"), py::arg("orientation") = py::none(),
          "Moves the grasp's frame to `position` [m] and `orientation` [x, y, z, w] (None: as it is) during the next step.")
      .def(
          "release",
          [](PythonWorld& w, const std::string& frame) {
            w.change([&](World& world) {
              findGrasp(world, frame);
              world.release(frame);
            });
          },
          py::arg("frame"), "Lets the grasp go; its nodes keep their velocities.")
      .def(
          "move_collider",
          [](PythonWorld& w, const std::string& name, const py::object& to, const py::object& turn) {
            const Vec3 p = position(to);
            const bool turns = !turn.is_none();
            const Eigen::Quaterniond q = turns ? orientation(turn) : Eigen::Quaterniond::Identity();
            w.change([&](World& world) {
              RigidPose pose{ p, q };
              if (!turns)  // as it is now; one never placed (on a tf frame) appears unturned
                for (const ColliderPose& now : world.colliderPoses())
                  if (now.name == name)
                    pose.orientation = now.orientation;
              if (!world.moveCollider(name, pose))
                throw UnknownName("no collider '" + name + "' that moves; the scene's: " +
                                  listed(movableColliders(world.model())));
            });
          },
          py::arg("name"), py::arg("position"), py::arg("orientation") = py::none(),
          "Moves the collider to `position` [m] and `orientation` [x, y, z, w] (None: as it is) during the next step; "
          "it holds still there after.")
      .def(
          "wrench",
          [](const PythonWorld& w, const std::string& body, const std::string& anchor) {
            return wrench(w.read([&](const World& world) {
              return world.anchorWrenches()[static_cast<std::size_t>(findAnchor(world, body, anchor))];
            }));
          },
          py::arg("body"), py::arg("anchor"),
          "(force [N], torque [N m] about its node): what the body exerts on the anchor, in the last sub-step.")
      .def(
          "grasp_wrench",
          [](const PythonWorld& w, const std::string& frame) {
            return wrench(w.read([&](const World& world) { return world.graspWrenches()[findGrasp(world, frame)]; }));
          },
          py::arg("frame"),
          "(force [N], torque [N m] about the frame's origin): what the body exerts on the grasp.")
      .def(
          "tensions",
          [](const PythonWorld& w, const std::string& body) {
            return w.read([&](const World& world) {
              const Model& model = world.model();
              const std::size_t b = findBody(model, body);
              const Eigen::VectorXd all = world.linkTensions();
              std::vector<double> mine;
              for (std::size_t k = 0; k < model.springs.size(); ++k)
                if (model.bodyOf(model.springs[k].a) == b)
                  mine.push_back(all[static_cast<Eigen::Index>(k)]);
              for (std::size_t k = 0; k < model.constraints.size(); ++k)
                if (model.bodyOf(model.constraints[k].a) == b)
                  mine.push_back(all[static_cast<Eigen::Index>(model.springs.size() + k)]);
              return py::array_t<double>(static_cast<py::ssize_t>(mine.size()), mine.data());
            });
          },
          py::arg("body"),
          "[N] the tension of each of the body's springs, then of its constraints, in the scene's order (> 0 stretched).")
      .def_property_readonly("divergence_events", &PythonWorld::lastEvents,
                             "the divergence guard's catches in the last step() call, oldest first")
      .def_property_readonly("divergence_count", [](const PythonWorld& w) { return w.read([](const World& world) { return world.divergenceCount(); }); },
                             "catches since the world was made (restore sets it back with the rest)")
      .def(
          "snapshot", [](const PythonWorld& w) { return w.read([](const World& world) { return world.snapshot(); }); },
          "This moment, to come back to with restore.")
      .def("restore", &PythonWorld::restore, py::arg("snapshot"),
           "Back to the snapshot's moment; ValueError, naming both, for a snapshot of another scene.")
      .def(
          "clone", [](const PythonWorld& w) { return std::make_unique<PythonWorld>(w); },
          "A copy that, given the same inputs, steps on to the same bits (copy.copy and copy.deepcopy too).")
      .def("__copy__", [](const PythonWorld& w) { return std::make_unique<PythonWorld>(w); })
      .def(
          "__deepcopy__", [](const PythonWorld& w, const py::dict&) { return std::make_unique<PythonWorld>(w); },
          py::arg("memo"))
      // Pickled as its scene file's absolute path and a snapshot's bytes: unpickling loads the file again
      // (refused, naming both scenes, if it changed) and restores the moment into it. A world of text
      // (from_yaml) carries its text as a third item, there being no file to load again.
      .def(py::pickle(
          [](const PythonWorld& w) {
            const WorldSnapshot now = w.read([](const World& world) { return world.snapshot(); });
            const std::string source = std::filesystem::absolute(w.scene()).string();
            if (!w.yamlText())
              return py::make_tuple(source, py::bytes(now.toBytes()));
            return py::make_tuple(source, py::bytes(now.toBytes()), *w.yamlText());
          },
          [](const py::tuple& state) {
            auto w = state.size() == 3 ?
                         std::make_unique<PythonWorld>(state[2].cast<std::string>(), state[0].cast<std::string>()) :
                         std::make_unique<PythonWorld>(state[0].cast<std::string>());
            w->restore(snapshotOfBytes(state[1]));
            return w;
          }))
      .def("__repr__", [](const PythonWorld& w) {
        return w.read([&](const World& world) {
          std::string bodies;
          for (const BodyRange& body : world.model().bodies)
            bodies += (bodies.empty() ? "" : ", ") + body.name;
          return "<sim.World '" + w.scene() + "' at t = " + formatNumber(world.time()) + " s: " + bodies + ">";
        });
      });

  m.def(
      "rollouts", &rollouts, py::arg("world"), py::arg("holder"), py::arg("goals"), py::arg("steps_per_goal") = 1,
      py::arg("threads") = 0,
      "X[b, t] = every node's position [m] after goal t of rollout b: (B, T, nodes, 3) for goals (B, T, 3) "
      "positions or (B, T, 7) poses of `holder` (an anchor \"body/anchor\" or a grasp's frame). Each rollout "
      "starts from the world's state (the world is not changed); within a goal's steps_per_goal steps the "
      "holder moves from the previous goal to this one in equal parts, to be there at their end. threads=0: "
      "one per core. The result is the same for any number of threads.");
}

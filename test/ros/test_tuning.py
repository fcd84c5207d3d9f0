#!/usr/bin/python3
"""Live tuning through dynamic_reconfigure's standard command-line client, `dynparam`, and the node's
health on /diagnostics (launched by tuning.test on test/ros/node_test_scene.yaml: a 5-node rope,
k = 50 N/m, 0.01 kg per node, hanging from both anchored ends, dt = 1 ms, semi_implicit_euler)."""
import ast
import math

import dynamic_reconfigure.client
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from dynamic_reconfigure.msg import Config, DoubleParameter, StrParameter
from dynamic_reconfigure.srv import Reconfigure
from rosgraph_msgs.msg import Log
from std_srvs.srv import Empty

from node_client import NodeTestCase, StateWatcher, run, wait_for

NODE = "/soft_body_sim"


def dynparam(*args):
    return run("rosrun", "dynamic_reconfigure", "dynparam", *args)


def assert_no_jump(test, states, label=""):
    """Between consecutive states every node moves as its velocities say: by the trapezoid rule
    (v_a + v_b) / 2 dt, whose error is dt^2 |da| / 12, below a millimetre at 20 ms for this rope, and
    5 mm allows for it. A jump (a reset state, a lost velocity) is centimetres."""
    for a, b in zip(states, states[1:]):
        dt = (b.header.stamp - a.header.stamp).to_sec()
        for p, q, u, w in zip(a.bodies[0].positions, b.bodies[0].positions, a.bodies[0].velocities,
                              b.bodies[0].velocities):
            predicted = [x + 0.5 * (vu + vw) * dt for x, vu, vw in ((p.x, u.x, w.x), (p.y, u.y, w.y), (p.z, u.z, w.z))]
            test.assertLess(math.dist(predicted, (q.x, q.y, q.z)), 5e-3, f"{label}: {dt} s between states")


def get_config(server=NODE):
    return ast.literal_eval(dynparam("get", server))


SCENE_PHYSICS = {"integrator": "semi_implicit_euler", "dt": 0.001, "substeps": 1, "iterations": 1,
                 "gravity_x": 0.0, "gravity_y": 0.0, "gravity_z": -9.81, "drag": 1.0}
UNSCALED = {"stiffness_scale": 1.0, "damping_scale": 1.0, "pressure_scale": 1.0}


class TuningTest(NodeTestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_tuning")
        cls.state = StateWatcher()
        cls.log = []
        cls.diagnostics = None
        rospy.Subscriber("/rosout", Log, lambda m: cls.log.append(m), queue_size=100)
        rospy.Subscriber("/diagnostics", DiagnosticArray, cls._on_diagnostics, queue_size=10)
        rospy.wait_for_service(NODE + "/reset", 20.0)
        rospy.wait_for_service(NODE + "/set_parameters", 20.0)
        cls.physics = dynamic_reconfigure.client.Client(NODE, timeout=10)
        cls.rope = dynamic_reconfigure.client.Client(NODE + "/rope", timeout=10)
        cls.state.next(1, 20.0)

    @classmethod
    def _on_diagnostics(cls, message):
        for status in message.status:
            if status.name.endswith("simulation"):
                cls.diagnostics = status

    def setUp(self):
        # Back to the scene's physics and a fresh rope before each test (the Python client: quicker
        # than a dynparam process; the tests themselves use dynparam).
        self.physics.update_configuration(SCENE_PHYSICS)
        self.rope.update_configuration(UNSCALED)
        rospy.ServiceProxy(NODE + "/reset", Empty)()
        self.state.next(2)

    def test_the_scene_values_are_the_starting_configuration(self):
        config = get_config()
        self.assertEqual(config["integrator"], "semi_implicit_euler")
        self.assertAlmostEqual(config["dt"], 0.001, places=12)
        self.assertAlmostEqual(config["drag"], 1.0, places=12)
        self.assertAlmostEqual(config["gravity_z"], -9.81, places=12)
        self.assertEqual(get_config(NODE + "/rope")["stiffness_scale"], 1.0)

    def test_a_new_dt_steps_the_stamps_by_it_without_a_jump(self):
        self.state.next(20)
        dynparam("set", NODE, "dt", "0.002")
        self.assertTrue(wait_for(lambda: self.physics.get_configuration(5)["dt"] == 0.002, 5.0))
        first = self.state.count()
        self.state.next(30)
        states = self.state.states[first + 2:]
        for before, after in zip(states, states[1:]):
            advance_ms = (after.header.stamp - before.header.stamp).to_sec() * 1e3
            # Whole steps of 2 ms (to the stamp's nanosecond), never a step back.
            self.assertGreaterEqual(advance_ms, 0.0)
            self.assertAlmostEqual(advance_ms / 2.0, round(advance_ms / 2.0), delta=1e-5)
        assert_no_jump(self, self.state.states[first - 5:], "dt 1 ms -> 2 ms")

    def test_an_out_of_range_value_is_refused_with_a_message(self):
        start = len(self.log)
        dynparam("set", NODE, "dt", "-1")
        self.assertAlmostEqual(get_config()["dt"], 0.001, places=12)  # unchanged
        self.assertTrue(wait_for(lambda: any("dt = -1 is out of range" in m.msg and m.level == Log.WARN
                                              for m in self.log[start:]), 10.0),
                        [m.msg for m in self.log[start:]])
        dynparam("set", NODE, "integrator", "leapfrog")
        self.assertEqual(self.physics.get_configuration(5)["integrator"], "semi_implicit_euler")
        self.assertTrue(wait_for(lambda: any("integrator 'leapfrog' is unknown" in m.msg for m in self.log[start:]), 10.0))
        dynparam("set", NODE + "/rope", "stiffness_scale", "0")
        self.assertEqual(self.rope.get_configuration(5)["stiffness_scale"], 1.0)
        self.state.next(5)  # still running

    def test_a_nan_a_huge_or_an_unknown_request_changes_nothing(self):
        # Straight to the service: dynparam cannot send NaN, and would refuse unknown names itself.
        set_parameters = rospy.ServiceProxy(NODE + "/set_parameters", Reconfigure)
        start = len(self.log)
        answer = set_parameters(Config(doubles=[DoubleParameter("dt", float("nan"))]))
        self.assertEqual({d.name: d.value for d in answer.config.doubles}["dt"], 0.001)
        self.assertTrue(wait_for(lambda: any("dt = nan is out of range" in m.msg for m in self.log[start:]), 10.0))
        # 100,000 unknown names and a 1 MB integrator name: answered, nothing applied, still running.
        answer = set_parameters(Config(doubles=[DoubleParameter(f"unknown_{k}", float(k)) for k in range(100000)]))
        self.assertEqual({d.name: d.value for d in answer.config.doubles}["dt"], 0.001)
        answer = set_parameters(Config(strs=[StrParameter("integrator", "x" * 1000000)]))
        self.assertEqual({s.name: s.value for s in answer.config.strs}["integrator"], "semi_implicit_euler")
        config = get_config()
        self.assertEqual({name: config[name] for name in SCENE_PHYSICS}, SCENE_PHYSICS)
        self.state.next(5)

    def test_gravity_turned_upside_down_lifts_the_rope(self):
        dynparam("set", NODE, "gravity_z", "9.81")
        # The free middle node starts at z = 1 and sags below it under normal gravity; now it rises.
        self.assertTrue(wait_for(lambda: self.state.node("rope", 2)[2] > 1.002, 10.0), self.state.node("rope", 2))

    def test_an_integrator_switch_continues_the_motion(self):
        self.state.next(10)  # well after setUp's reset
        for name in ("xpbd", "implicit_euler", "verlet"):
            first = self.state.count() - 5
            dynparam("set", NODE, "integrator", name)
            self.assertTrue(wait_for(lambda: self.physics.get_configuration(5)["integrator"] == name, 5.0), name)
            self.state.next(5)
            assert_no_jump(self, self.state.states[first:], name)

    def test_a_softer_rope_sags_further(self):
        # Hanging from its ends, the middle node of the 0.4 m rope sags by ~m g / k at k = 50 N/m (a few
        # millimetres); at 1 % of that stiffness the springs stretch by decimetres.
        dynparam("set", NODE + "/rope", "stiffness_scale", "0.01")
        self.assertTrue(wait_for(lambda: self.state.node("rope", 2)[2] < 0.9, 10.0), self.state.node("rope", 2))

    def test_diagnostics_report_health_and_a_divergence(self):
        self.assertTrue(wait_for(lambda: self.diagnostics is not None and self.diagnostics.level == DiagnosticStatus.OK, 10.0))
        values = {kv.key: kv.value for kv in self.diagnostics.values}
        for key in ("real-time factor", "step cost [s]", "max strain", "divergence events"):
            self.assertIn(key, values)
        self.assertLess(float(values["max strain"]), 1.0)
        events = int(values["divergence events"])
        # Explicit Euler on stiff springs at 20 ms: w h = sqrt(2 k / m) h = 20 > 2, it explodes. The
        # divergence guard restores the rope and steps it with implicit_euler from then on: one event,
        # a warning, and never a non-finite value on ~state.
        start = len(self.log)
        dynparam("set", NODE, "{integrator: explicit_euler, dt: 0.02}")
        dynparam("set", NODE + "/rope", "stiffness_scale", "100")
        self.assertTrue(wait_for(lambda: self.diagnostics.level == DiagnosticStatus.WARN, 20.0))
        values = {kv.key: kv.value for kv in self.diagnostics.values}
        self.assertEqual(int(values["divergence events"]), events + 1)
        rope = self.state.next(5).bodies[0]
        self.assertEqual((rope.integrator, rope.divergence_events, rope.frozen), ("implicit_euler", 1, False))
        self.assertEqual(self.state.latest.divergence_events, events + 1)
        self.state.expect_guard_events()
        for state in self.state.states:
            for p in state.bodies[0].positions:
                self.assertTrue(all(map(math.isfinite, (p.x, p.y, p.z))))
        self.assertTrue(wait_for(lambda: any("body 'rope' diverged at t = " in m.msg and "switched from explicit_euler "
                                             "to implicit_euler" in m.msg for m in self.log[start:]), 5.0))

    def test_step_statistics_are_plottable_fields(self):
        # rqt_plot reads numeric fields by path, as `rostopic echo` does.
        self.state.next(30)
        factor = float(run("rostopic", "echo", "-n", "1", "--noarr", NODE + "/state/real_time_factor").split()[0])
        self.assertGreater(factor, 0.5)
        cost = float(run("rostopic", "echo", "-n", "1", NODE + "/state/wall_seconds_per_step").split()[0])
        self.assertGreater(cost, 0.0)


if __name__ == "__main__":
    rostest.rosrun("soft_body_sim", "tuning", TuningTest)

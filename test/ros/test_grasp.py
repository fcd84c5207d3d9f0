#!/usr/bin/python3
"""Grasping and forces the ROS way (launched by grasp.test on grasp_test_scene.yaml): the anchor's wrench
topic and the state's holders, wrenches and tensions against the hanging rope's statics; ~grasp holds the
nodes within its radius in a turning tf frame, ~release lets go, a grasp above its max_force slips and
says so; bad requests are refused with their reason."""
import math

import rospy
import rostest
from geometry_msgs.msg import WrenchStamped
from rosgraph_msgs.msg import Log

from node_client import FrameBroadcaster, NodeTestCase, StateWatcher, wait_for
from soft_body_sim.srv import Detach, Grasp

NODE = "/soft_body_sim"
GRAVITY = 9.81
NODE_MASS = 0.01  # [kg], 11 nodes
STIFFNESS = 2000.0  # [N/m] per segment


def rest_z(j):
    """z [m] of node j of the rope at rest: segment i (above node i) carries the 11 - i nodes below it."""
    return 2.0 - sum(0.1 + (11 - i) * NODE_MASS * GRAVITY / STIFFNESS for i in range(1, j + 1))


class GraspTest(NodeTestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_grasp")
        cls.state = StateWatcher()
        cls.frames = FrameBroadcaster()
        cls.log = []
        rospy.Subscriber("/rosout", Log, cls.log.append, queue_size=100)
        rospy.wait_for_service(NODE + "/grasp", 20.0)
        cls.grasp = rospy.ServiceProxy(NODE + "/grasp", Grasp)
        cls.release = rospy.ServiceProxy(NODE + "/release", Detach)
        cls.state.next(1, 20.0)

    def wait_for_rest(self):
        """The rope starts straight at its rest length, and swings after a test lets it go: it settles
        under drag."""
        self.assertTrue(wait_for(lambda: max(math.sqrt(v.x ** 2 + v.y ** 2 + v.z ** 2)
                                             for v in self.state.latest.bodies[0].velocities) < 1e-5, 30.0),
                        "the rope did not come to rest")

    def set_frame(self, child, pose):
        self.frames.set(child, pose)

    def body(self):
        return self.state.latest.bodies[0]

    def test_an_anchor_publishes_the_ropes_weight_and_the_state_its_tensions(self):
        weight = 11 * NODE_MASS * GRAVITY
        self.wait_for_rest()
        wrenches = []
        subscriber = rospy.Subscriber(NODE + "/rope/top/wrench", WrenchStamped, wrenches.append, queue_size=10)
        try:
            self.assertTrue(wait_for(lambda: len(wrenches) >= 3, 10.0))
        finally:
            subscriber.unregister()
        message = wrenches[-1]
        self.assertEqual(message.header.frame_id, "world")
        # Stamped with the simulated instant, as the state of the same tick. The two topics have their own
        # connections, so that state may arrive after the wrench: wait for it.
        self.assertTrue(wait_for(lambda: message.header.stamp in (s.header.stamp for s in self.state.states), 5.0),
                        f"no state stamped {message.header.stamp.to_sec()} s, as the wrench is")
        force, torque = message.wrench.force, message.wrench.torque
        self.assertAlmostEqual(force.z, -weight, delta=1e-3 * weight)
        self.assertAlmostEqual(math.hypot(force.x, force.y), 0.0, delta=1e-3 * weight)
        self.assertAlmostEqual(math.sqrt(torque.x ** 2 + torque.y ** 2 + torque.z ** 2), 0.0, delta=1e-9)
        body = self.body()
        self.assertIn("top", body.holders)
        self.assertAlmostEqual(body.wrenches[list(body.holders).index("top")].force.z, -weight, delta=1e-3 * weight)
        # Ten segments; segment i carries the 11 - i nodes below it.
        self.assertEqual(len(body.tensions), 10)
        for i, tension in enumerate(body.tensions):
            self.assertAlmostEqual(tension, (10 - i) * NODE_MASS * GRAVITY, delta=1e-3 * weight, msg=f"segment {i}")

    def test_a_grasp_turns_its_nodes_with_its_frame_and_release_lets_them_go(self):
        # The hand closes between the rope's last two nodes, then turns a quarter turn about x in 2 s:
        # the nodes 5 cm above and below its origin end 5 cm to either side of it along y.
        self.wait_for_rest()
        origin = (0.0, 0.0, (rest_z(9) + rest_z(10)) / 2)
        start = rospy.Time.now().to_sec() + 1.0

        def hand(t):
            angle = 0.5 * math.pi * min(1.0, max(0.0, (t - start) / 2.0))
            return origin, (math.sin(angle / 2), 0.0, 0.0, math.cos(angle / 2))

        self.set_frame("hand", hand)
        self.assertTrue(wait_for(lambda: rospy.Time.now().to_sec() > start - 0.5, 5.0))
        response = self.grasp(frame="hand", body="rope", radius=0.08, max_force=0.0)
        self.assertTrue(response.success, response.message)
        self.assertEqual(list(response.nodes), [9, 10])
        wrenches = []
        subscriber = rospy.Subscriber(NODE + "/rope/hand/wrench", WrenchStamped, wrenches.append, queue_size=10)
        try:
            self.assertTrue(wait_for(lambda: rospy.Time.now().to_sec() > start + 3.0, 10.0))
            self.state.next(3)
            self.assertTrue(wrenches, "nothing on ~rope/hand/wrench")
        finally:
            subscriber.unregister()
        half = (rest_z(9) - rest_z(10)) / 2
        for node, expected in ((9, (0.0, -half, origin[2])), (10, (0.0, half, origin[2]))):
            self.assertLess(math.dist(self.state.node("rope", node), expected), 1e-4, node)
        self.assertEqual(list(self.body().holders), ["top", "hand"])
        self.assertEqual(self.release(frame="hand").success, True)
        self.state.next(2)
        self.assertEqual(list(self.body().holders), ["top"])
        again = self.release(frame="hand")
        self.assertFalse(again.success)
        self.assertIn("holds no grasp", again.message)

    def test_a_grasp_above_its_max_force_slips_and_says_so(self):
        # The weak hand holds the rope's end and pulls it down at 5 cm/s: stretching the rope (200 N/m
        # over its ten segments) raises the force past 0.5 N within about 0.05 s, and the grasp lets go.
        self.wait_for_rest()
        origin = (0.0, 0.0, rest_z(10))
        start = rospy.Time.now().to_sec() + 1.0
        self.set_frame("weak_hand", lambda t: ((origin[0], origin[1], origin[2] - 0.05 * max(0.0, t - start)),
                                               (0.0, 0.0, 0.0, 1.0)))
        self.assertTrue(wait_for(lambda: rospy.Time.now().to_sec() > start - 0.5, 5.0))
        first_log = len(self.log)
        first_state = self.state.count()
        response = self.grasp(frame="weak_hand", body="rope", radius=0.02, max_force=0.5)
        self.assertTrue(response.success, response.message)
        self.assertEqual(list(response.nodes), [10])
        self.assertTrue(wait_for(lambda: any("slipped" in m.msg and m.level == Log.WARN for m in self.log[first_log:]),
                                 10.0))
        self.assertTrue(wait_for(lambda: [line for s in self.state.states[first_state:] for line in s.bodies[0].slips],
                                 5.0))
        slips = [line for s in self.state.states[first_state:] for line in s.bodies[0].slips]
        self.assertEqual(len(slips), 1, slips)
        self.assertIn("grasp 'weak_hand' on body 'rope' slipped", slips[0])
        self.assertIn("max_force 0.5 N", slips[0])
        self.assertEqual(list(self.body().holders), ["top"])
        self.assertFalse(self.release(frame="weak_hand").success)

    def test_a_frame_whose_name_is_no_ros_name_grasps_without_a_wrench_topic(self):
        # tf frames may hold characters that ROS names may not: the grasp holds, its wrench is in ~state.
        self.wait_for_rest()
        self.set_frame("hand-2", lambda t: ((0.0, 0.0, rest_z(10)), (0.0, 0.0, 0.0, 1.0)))
        rospy.sleep(0.2)  # the frame reaches tf
        response = self.grasp(frame="hand-2", body="rope", radius=0.02, max_force=0.0)
        self.assertTrue(response.success, response.message)
        self.state.next(5)
        body = self.body()
        self.assertEqual(list(body.holders), ["top", "hand-2"])
        self.assertTrue(math.isfinite(body.wrenches[1].force.z))
        self.assertTrue(self.release(frame="hand-2").success)
        self.state.next(2)

    def test_bad_grasp_requests_are_refused_with_their_reason(self):
        self.set_frame("far_hand", lambda t: ((5.0, 5.0, 5.0), (0.0, 0.0, 0.0, 1.0)))
        self.assertTrue(wait_for(lambda: rospy.Time.now().to_sec() > 0.0, 5.0))
        rospy.sleep(0.2)  # the frame reaches tf
        requests = [  # (frame, body, radius, max_force), a part of the reason
            ("", "rope", 0.1, 0.0, "no frame given"),
            ("far_hand", "", 0.1, 0.0, "no body given"),
            ("far_hand", "cable", 0.1, 0.0, "no body 'cable'"),
            ("far_hand", "rope", 0.0, 0.0, "radius must be"),
            ("far_hand", "rope", 0.1, -1.0, "max_force must be"),
            ("far_hand", "rope", 0.1, float("nan"), "max_force must be"),
            ("no_such_frame", "rope", 0.1, 0.0, "no transform"),
            ("far_hand", "rope", 0.1, 0.0, "no free node of body 'rope'"),
        ]
        for frame, body, radius, max_force, reason in requests:
            response = self.grasp(frame=frame, body=body, radius=radius, max_force=max_force)
            self.assertFalse(response.success, (frame, body, radius, max_force))
            self.assertIn(reason, response.message)
        self.assertEqual(list(self.body().holders), ["top"])


if __name__ == "__main__":
    rostest.rosrun("soft_body_sim", "grasp", GraspTest)

#!/usr/bin/python3
"""Inputs the ROS way (launched by inputs.test on frame_test_scene.yaml): the rope's first node follows
the tf frame gripper_link, its last node has an rviz handle, and ~attach / ~detach grasp and release
a node at another frame; bad requests and bad input parameters are refused with their reason."""
import math
import os
import subprocess

import roslib.packages
import rospy
import rostest
from geometry_msgs.msg import PoseStamped, WrenchStamped
from rosgraph_msgs.msg import Log
from std_srvs.srv import Empty, SetBool
from visualization_msgs.msg import InteractiveMarkerFeedback, InteractiveMarkerInit, MarkerArray

from node_client import FrameBroadcaster, NodeTestCase, StateWatcher, wait_for
from soft_body_sim.srv import Attach, Detach, Grasp

NODE = "/soft_body_sim"
GRIPPER_CENTER = (0.0, 0.0, 1.0)  # [m] the gripper circles about this point in the x-z plane
GRIPPER_RADIUS = 0.1              # [m]
GRIPPER_PERIOD = 4.0              # [s] one turn: 0.16 m/s
FAR = 1.0e30                      # [m] finite, and far beyond ~workspace_radius (default 1e4 m)
# [N] on an anchor of the 0.05 kg rope: its weight (0.5 N) plus its springs stretched by the anchors
# (k = 50 N/m each, four in series: 12.5 N/m, stretched by well under a metre) and their swing. A pose
# that reached the world at 1e30 m pulls with ~1e34 N.
MAX_ANCHOR_FORCE = 100.0


def gripper_position(t):
    w = 2.0 * math.pi / GRIPPER_PERIOD
    return (GRIPPER_CENTER[0] + GRIPPER_RADIUS * math.cos(w * t), GRIPPER_CENTER[1],
            GRIPPER_CENTER[2] + GRIPPER_RADIUS * math.sin(w * t))


class InputsTest(NodeTestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_inputs")
        cls.state = StateWatcher()
        cls.frames = FrameBroadcaster()  # gripper_link moves on its circle; others stand where a test puts them
        cls.frames.set("gripper_link", lambda t: (gripper_position(t), (0.0, 0.0, 0.0, 1.0)))
        cls.handles = None
        rospy.Subscriber(NODE + "/handles/update_full", InteractiveMarkerInit,
                         lambda m: setattr(cls, "handles", m), queue_size=1)
        cls.end_poses = []
        cls.log = []
        rospy.Subscriber("/rosout", Log, cls.log.append, queue_size=100)
        rospy.Subscriber(NODE + "/rope/end/pose", PoseStamped, cls.end_poses.append, queue_size=10)
        cls.feedback = rospy.Publisher(NODE + "/handles/feedback", InteractiveMarkerFeedback, queue_size=10)
        cls.end_pose = rospy.Publisher(NODE + "/rope/end/pose", PoseStamped, queue_size=10)
        cls.end_forces = []
        rospy.Subscriber(NODE + "/rope/end/wrench", WrenchStamped,
                         lambda m: cls.end_forces.append(math.hypot(m.wrench.force.x, m.wrench.force.y, m.wrench.force.z)),
                         queue_size=100)
        rospy.wait_for_service(NODE + "/attach", 20.0)
        cls.attach = rospy.ServiceProxy(NODE + "/attach", Attach)
        cls.detach = rospy.ServiceProxy(NODE + "/detach", Detach)
        cls.grasp = rospy.ServiceProxy(NODE + "/grasp", Grasp)
        cls.reset = rospy.ServiceProxy(NODE + "/reset", Empty)
        cls.state.next(1, 20.0)

    def set_frame(self, child, position):
        self.frames.set_position(child, position)

    def send_end_pose(self, x, y, z):
        pose = PoseStamped()
        pose.header.frame_id = "world"  # stamp 0: now
        pose.pose.position.x, pose.pose.position.y, pose.pose.position.z = x, y, z
        pose.pose.orientation.w = 1.0
        self.assertTrue(wait_for(lambda: self.end_pose.get_num_connections() > 0, 10.0))
        self.end_pose.publish(pose)

    def assert_rope_bounded(self, states, label):
        for state in states:
            for p in state.bodies[0].positions:
                self.assertLess(math.dist((p.x, p.y, p.z), GRIPPER_CENTER), 2.0, label)

    def logged(self, start, level, *texts):
        return wait_for(lambda: any(m.level == level and all(t in m.msg for t in texts) for m in self.log[start:]), 10.0)

    def test_an_anchor_follows_its_tf_frame(self):
        # Each step's end asks tf for the frame at that instant. The broadcasts are stamped now, so steps end
        # past the newest transform, which glides in over its 20 ms period from the step that sees it
        # (input_glide.h): behind by a period and the transport, 0.16 m/s * 50 ms = 8 mm.
        self.state.next(25)
        errors = []
        for _ in range(50):
            s = self.state.next(1)
            x = s.bodies[0].positions[0]
            errors.append(math.dist((x.x, x.y, x.z), gripper_position(s.header.stamp.to_sec())))
        self.assertLess(max(errors), 0.01, errors)

    def test_a_collider_follows_its_tf_frame_and_is_drawn_there(self):
        # The finger sits 0.3 m along y from gripper_link, turned along x; its marker (the capsule's
        # cylinder, id 0 of namespace colliders) is where the frame was at the marker's stamp, within the
        # anchor's tolerance above.
        drawn = []
        subscriber = rospy.Subscriber(NODE + "/markers", MarkerArray,
                                      lambda a: drawn.extend(m for m in a.markers if m.ns == "colliders" and m.id == 0),
                                      queue_size=10)
        try:
            self.assertTrue(wait_for(lambda: len(drawn) >= 30, 20.0))
        finally:
            subscriber.unregister()
        errors = []
        for m in drawn[5:]:
            expected = gripper_position(m.header.stamp.to_sec())
            p = m.pose.position
            errors.append(math.dist((p.x, p.y, p.z), (expected[0], expected[1] + 0.3, expected[2])))
            self.assertEqual(m.type, m.CYLINDER)
            self.assertAlmostEqual(m.pose.orientation.y, math.sqrt(0.5), places=6)
            self.assertAlmostEqual(m.scale.z, 0.06)
        self.assertLess(max(errors), 0.01, errors)

    def test_a_handle_drag_publishes_on_the_anchor_topic_and_moves_the_anchor(self):
        self.assertTrue(wait_for(lambda: self.handles is not None, 10.0))
        # A handle for the topic anchor; none for the anchor that follows its frame.
        self.assertEqual(sorted(m.name for m in self.handles.markers), ["rope/end"])
        handle = self.handles.markers[0]
        self.assertEqual(handle.header.frame_id, "world")
        self.assertAlmostEqual(handle.pose.position.x, 0.4)
        feedback = InteractiveMarkerFeedback()
        feedback.header.frame_id = "world"
        feedback.client_id = "/test_inputs/rviz"
        feedback.marker_name = "rope/end"
        feedback.control_name = "move_3d"
        feedback.event_type = InteractiveMarkerFeedback.POSE_UPDATE
        feedback.pose.position.x, feedback.pose.position.y, feedback.pose.position.z = 0.6, 0.1, 1.1
        feedback.pose.orientation.w = 1.0
        self.assertTrue(wait_for(lambda: self.feedback.get_num_connections() > 0, 10.0))
        self.end_poses.clear()  # those that other tests sent on the topic
        self.feedback.publish(feedback)
        # The same pose on the anchor's topic, as another node would send it, stamped now ...
        self.assertTrue(wait_for(lambda: self.end_poses, 10.0))
        pose = self.end_poses[-1]
        self.assertEqual(pose.header.frame_id, "world")
        self.assertGreater(pose.header.stamp.to_sec(), 0.0)
        self.assertEqual((pose.pose.position.x, pose.pose.position.y, pose.pose.position.z), (0.6, 0.1, 1.1))
        # ... and the anchored node goes exactly there.
        self.assertTrue(wait_for(lambda: self.state.node("rope", 4) == (0.6, 0.1, 1.1), 10.0), self.state.node("rope", 4))

    def test_attach_grasps_the_nearest_node_and_detach_releases_it(self):
        self.set_frame("gripper2", (5.0, 5.0, 5.0))
        rospy.sleep(0.3)
        refused = self.attach(frame="gripper2", body="rope", radius=0.05)
        self.assertFalse(refused.success)
        self.assertIn("no free node", refused.message)
        unknown = self.attach(frame="no_such_frame", body="rope", radius=0.05)
        self.assertFalse(unknown.success)
        self.assertIn("no transform", unknown.message)

        # Next to node 2, closer than to its neighbours 0.1 m away; paused, so that the rope swinging
        # below the circling gripper_link does not carry node 2 away meanwhile.
        pause = rospy.ServiceProxy(NODE + "/pause", SetBool)
        pause(True)
        self.state.next(2)
        x, y, z = self.state.node("rope", 2)
        self.set_frame("gripper2", (x, y, z + 0.01))
        rospy.sleep(0.3)
        grasp = self.attach(frame="gripper2", body="", radius=0.05)
        pause(False)
        self.assertTrue(grasp.success, grasp.message)
        self.assertEqual((grasp.node, grasp.anchor), (2, "gripper2"))
        again = self.attach(frame="gripper2", body="rope", radius=0.5)
        self.assertFalse(again.success)

        # The gripper carries the node up and aside.
        self.set_frame("gripper2", (0.25, 0.2, 1.3))
        self.assertTrue(wait_for(lambda: math.dist(self.state.node("rope", 2), (0.25, 0.2, 1.3)) < 1e-9, 10.0),
                        self.state.node("rope", 2))
        released = self.detach(frame="gripper2")
        self.assertTrue(released.success, released.message)
        self.assertFalse(self.detach(frame="gripper2").success)
        # Free again: it falls back below the gripper.
        self.assertTrue(wait_for(lambda: self.state.node("rope", 2)[2] < 1.2, 10.0), self.state.node("rope", 2))

    def test_bad_attach_and_detach_requests_are_refused_with_their_reason_and_a_log_line(self):
        start = len(self.log)
        attaches = [  # (frame, body, radius), a part of the reason
            ("", "rope", 0.05, "no frame given"),
            ("g" * 1000000, "rope", 0.05, "frame name of 1000000 characters"),
            ("grip\nper", "rope", 0.05, "control"),
            ("gripper_link", "b" * 300, 0.05, "body name of 300 characters"),
            ("gripper_link", "no_such_body", 0.05, "no body 'no_such_body'"),
            ("gripper_link", "rope", float("nan"), "radius must be a finite number > 0"),
            ("gripper_link", "rope", float("inf"), "radius must be a finite number > 0"),
            ("gripper_link", "rope", -0.1, "radius must be a finite number > 0"),
            ("gripper_link", "rope", 0.0, "radius must be a finite number > 0"),
        ]
        for frame, body, radius, reason in attaches:
            response = self.attach(frame=frame, body=body, radius=radius)
            self.assertFalse(response.success, reason)
            self.assertIn(reason, response.message)
            self.assertLess(len(response.message), 200)  # a huge name is measured, not echoed
        for frame, reason in (("", "no frame given"), ("d" * 1000000, "frame name of 1000000 characters"),
                              ("gripper_link", "holds nothing"), ("never_attached", "holds nothing")):
            response = self.detach(frame=frame)
            self.assertFalse(response.success, reason)
            self.assertIn(reason, response.message)
        self.assertTrue(wait_for(lambda: sum("attach refused" in m.msg and m.level == Log.WARN for m in self.log[start:])
                                 >= len(attaches) and sum("detach refused" in m.msg for m in self.log[start:]) >= 4, 10.0),
                        [m.msg[:100] for m in self.log[start:]])
        # Nothing was grasped: node 2 still hangs free (it moves), the first node still follows its frame.
        self.state.next(5)
        x = self.state.node("rope", 2)
        self.assertTrue(wait_for(lambda: math.dist(self.state.node("rope", 2), x) > 1e-6, 10.0))
        s = self.state.next(1)
        first = s.bodies[0].positions[0]
        self.assertLess(math.dist((first.x, first.y, first.z), gripper_position(s.header.stamp.to_sec())), 0.01)

    def test_a_pose_beyond_the_workspace_is_dropped_and_a_sane_one_still_followed(self):
        start, first, forces = len(self.log), self.state.count(), len(self.end_forces)
        try:
            self.send_end_pose(FAR, 0.0, 1.0)
            self.assertTrue(self.logged(start, Log.WARN, NODE + "/rope/end/pose: pose dropped", "workspace_radius"),
                            [m.msg for m in self.log[start:]])
            self.state.next(10)
            self.assert_rope_bounded(self.state.states[first:], "after a pose at x = 1e30")
            self.send_end_pose(0.5, 0.0, 1.0)
            self.assertTrue(wait_for(lambda: self.state.node("rope", 4) == (0.5, 0.0, 1.0), 10.0),
                            self.state.node("rope", 4))
            self.state.next(5)
            self.assertTrue(self.end_forces[forces:])
            self.assertLess(max(self.end_forces[forces:]), MAX_ANCHOR_FORCE)
        finally:
            self.reset()  # on a node that took the pose: the rope back for the other tests

    def test_a_followed_frame_beyond_the_workspace_is_not_followed(self):
        start, first = len(self.log), self.state.count()
        try:
            self.set_frame("gripper_link", (FAR, 0.0, 1.0))
            self.assertTrue(self.logged(start, Log.WARN, "tf frame 'gripper_link' is", "workspace_radius"),
                            [m.msg for m in self.log[start:]])
            self.state.next(10)
            self.assert_rope_bounded(self.state.states[first:], "while gripper_link is at x = 1e30")
        finally:
            self.frames.set("gripper_link", lambda t: (gripper_position(t), (0.0, 0.0, 0.0, 1.0)))
        # The frame back on its circle: the anchor follows it again.
        self.assertTrue(wait_for(lambda: math.dist(self.state.node("rope", 0),
                                                   gripper_position(self.state.latest.header.stamp.to_sec())) < 0.01,
                                 10.0))
        self.reset()

    def test_attach_and_grasp_at_a_frame_beyond_the_workspace_are_refused(self):
        self.set_frame("far_gripper", (FAR, 0.0, 1.0))
        rospy.sleep(0.3)
        try:
            # A radius that reaches the rope from there: only the frame's distance is left to refuse.
            for response in (self.attach(frame="far_gripper", body="rope", radius=1e31),
                             self.grasp(frame="far_gripper", body="rope", radius=1e31, max_force=0.0)):
                self.assertFalse(response.success)
                self.assertIn("tf frame 'far_gripper' is 1e+30 m from the origin", response.message)
                self.assertIn("~workspace_radius = 10000 m", response.message)
            self.assert_rope_bounded([self.state.next(5)], "after the refused requests")
        finally:
            self.reset()  # on a node that took the frame: nothing left held there

    def test_a_divergence_after_an_input_jump_names_the_jump(self):
        # 9 km in one step, within the workspace: the free node beside the anchor swings at sqrt(2 k / m)
        # * 9 km ~ 1e6 m/s, past the guard's max_speed (1e5 m/s) within a few 1 ms steps of the tick.
        start = len(self.log)
        try:
            self.send_end_pose(9000.0, 0.0, 1.0)
            self.assertTrue(self.logged(start, Log.ERROR, "body 'rope' diverged", "likely cause: an input jump",
                                        "anchor 'end' moved its node"),
                            [m.msg for m in self.log[start:]])
        finally:
            self.reset()
            self.state.next(3)
            self.state.expect_guard_events()

    def test_an_input_parameter_of_a_wrong_type_or_range_stops_the_node_naming_it(self):
        node = roslib.packages.find_node("soft_body_sim", "soft_body_sim_node")[0]
        scene = os.path.join(os.path.dirname(os.path.abspath(__file__)), "frame_test_scene.yaml")
        cases = [  # (parameter, value, what the node says)
            ("max_input_age", "abc", "max_input_age: must be a finite number of seconds > 0, not 'abc'"),
            ("max_input_lead", "true", "max_input_lead: must be a finite number of seconds > 0, not true"),
            ("max_input_age", "0", "max_input_age: must be a finite number of seconds > 0, not 0"),
            ("max_input_lead", "-1.5", "max_input_lead: must be a finite number of seconds > 0, not -1.5"),
            ("max_held_inputs", "0", "max_held_inputs: must be an integer >= 1, not 0"),
            ("max_held_inputs", "2.5", "max_held_inputs: must be an integer >= 1, not 2.5"),
            ("tick_budget", "abc", "tick_budget: must be a finite number > 0 [s]"),
            ("tick_budget", "0", "tick_budget: must be a finite number > 0 [s]"),
            ("workspace_radius", "-1", "workspace_radius: must be a finite number > 0 [m]"),
            # The rope hangs at z = 1 m: a workspace of half a metre would refuse every input near it.
            ("workspace_radius", "0.5", "workspace_radius: the scene's node 0 lies outside it: 1 m from the origin"),
        ]
        for k, (parameter, value, message) in enumerate(cases):
            name = f"bad_input_parameter_{k}"  # its own private namespace: no parameter left from the last
            result = subprocess.run([node, f"__name:={name}", f"_scene:={scene}", f"_{parameter}:={value}"],
                                    capture_output=True, text=True, timeout=60)
            self.assertEqual(result.returncode, 1, result.stderr)
            self.assertIn(f"/{name}/{message}", result.stderr)


if __name__ == "__main__":
    rostest.rosrun("soft_body_sim", "inputs", InputsTest)

#!/usr/bin/python3
"""A rod the ROS way (launched by rod.test on config/scenes/cable.yaml): a pose with an orientation
published to the tip anchor's topic turns the cable's end, and the anchor's wrench topic carries the
twisting moment G J phi / L; a pose whose orientation is all zeros moves the tip without turning it;
a grasp on its middle in a turning tf frame twists both halves, and its wrench topic carries both
halves' moments; the markers draw the cable as a strip of its diameter and its segments' frames."""
import math

import rospy
import rostest
from geometry_msgs.msg import PoseStamped, WrenchStamped
from visualization_msgs.msg import Marker, MarkerArray

from node_client import FrameBroadcaster, NodeTestCase, StateWatcher, wait_for
from soft_body_sim.srv import Detach, Grasp

NODE = "/soft_body_sim"
RADIUS = 0.005           # [m], cable.yaml
SHEAR_MODULUS = 1.9e7    # [Pa]
LENGTH = 1.0             # [m]
TWISTING = SHEAR_MODULUS * math.pi * RADIUS ** 4 / 2  # G J [N m^2]
TIP = (0.5, 0.0, 1.0)    # [m] where the scene holds it


def tip_pose(position, quaternion):
    pose = PoseStamped()
    pose.header.frame_id = "world"
    pose.pose.position.x, pose.pose.position.y, pose.pose.position.z = position
    (pose.pose.orientation.x, pose.pose.orientation.y, pose.pose.orientation.z,
     pose.pose.orientation.w) = quaternion
    return pose


class RodNodeTest(NodeTestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_rod_node")
        cls.state = StateWatcher()
        cls.wrenches = []
        rospy.Subscriber(NODE + "/cable/tip/wrench", WrenchStamped, cls.wrenches.append, queue_size=100)
        cls.markers = []
        rospy.Subscriber(NODE + "/markers", MarkerArray, cls.markers.append, queue_size=10)
        cls.tip = rospy.Publisher(NODE + "/cable/tip/pose", PoseStamped, queue_size=100)
        cls.frames = FrameBroadcaster()
        rospy.wait_for_service(NODE + "/grasp", 20.0)
        cls.grasp = rospy.ServiceProxy(NODE + "/grasp", Grasp)
        cls.release = rospy.ServiceProxy(NODE + "/release", Detach)
        cls.state.next(1, 20.0)

    def settle(self):
        self.assertTrue(wait_for(lambda: max(math.sqrt(v.x ** 2 + v.y ** 2 + v.z ** 2)
                                             for v in self.state.latest.bodies[0].velocities) < 1e-4, 30.0),
                        "the cable did not come to rest")

    def latest_torque(self):
        count = len(self.wrenches)
        self.assertTrue(wait_for(lambda: len(self.wrenches) > count + 2, 10.0), "no wrench on ~cable/tip/wrench")
        return self.wrenches[-1].wrench.torque

    def test_a_grasp_turned_in_the_middle_twists_both_halves(self):
        # A gripper closes on the middle node (the cable is level there) and turns 1 rad about the cable in
        # 2 s: each half, 0.5 m between it and a held end, twists by 1 rad, and the gripper feels both,
        # -G J phi (1 / 0.5 + 1 / 0.5) about x. Released, the two twists cancel: the cable is untwisted.
        self.settle()
        middle = self.state.node("cable", 20)
        start = rospy.Time.now().to_sec() + 1.0

        def hand(t):
            angle = min(1.0, max(0.0, (t - start) / 2.0))
            return middle, (math.sin(angle / 2), 0.0, 0.0, math.cos(angle / 2))

        self.frames.set("hand", hand)
        self.assertTrue(wait_for(lambda: rospy.Time.now().to_sec() > start - 0.5, 5.0))
        response = self.grasp(frame="hand", body="cable", radius=0.01, max_force=0.0)
        self.assertTrue(response.success, response.message)
        self.assertEqual(list(response.nodes), [20])
        wrenches = []
        subscriber = rospy.Subscriber(NODE + "/cable/hand/wrench", WrenchStamped, wrenches.append, queue_size=10)
        try:
            self.assertTrue(wait_for(lambda: rospy.Time.now().to_sec() > start + 2.5, 10.0))
            self.settle()
            count = len(wrenches)
            self.assertTrue(wait_for(lambda: len(wrenches) > count + 2, 10.0), "no wrench on ~cable/hand/wrench")
            self.assertAlmostEqual(wrenches[-1].wrench.torque.x, -TWISTING * 1.0 * (2 / LENGTH + 2 / LENGTH),
                                   delta=0.05 * 4 * TWISTING)
        finally:
            subscriber.unregister()
        self.assertTrue(self.release(frame="hand").success)
        self.settle()
        self.assertAlmostEqual(self.latest_torque().x, 0.0, delta=1e-6)

    def test_the_tip_pose_twists_the_cable_and_its_wrench_carries_the_twisting_moment(self):
        self.settle()
        self.assertAlmostEqual(self.latest_torque().x, 0.0, delta=1e-9)
        # Position only (orientation all zeros): the tip moves 5 cm in, 5 mm at a time (less than a
        # segment per step: docs/scenes.md, "Rods"), untwisted.
        moved = (0.45, 0.0, 1.0)
        for k in range(1, 11):
            self.tip.publish(tip_pose((0.5 - 0.005 * k, 0.0, 1.0), (0.0, 0.0, 0.0, 0.0)))
            rospy.sleep(0.05)
        self.settle()
        self.assertLess(math.dist(self.state.node("cable", 40), moved), 1e-9)
        self.assertAlmostEqual(self.latest_torque().x, 0.0, delta=1e-6)
        # Turned 1 rad about the cable's axis (x) in steps of 0.1 rad: the cable resists with G J phi / L
        # about -x (less the little that its sag turns into writhe).
        for k in range(1, 11):
            angle = 0.1 * k
            self.tip.publish(tip_pose(moved, (math.sin(angle / 2), 0.0, 0.0, math.cos(angle / 2))))
            rospy.sleep(0.05)
        self.settle()
        torque = self.latest_torque()
        self.assertAlmostEqual(torque.x, -TWISTING * 1.0 / LENGTH, delta=0.05 * TWISTING)

    def test_the_markers_draw_the_cable_with_its_frames(self):
        count = len(self.markers)
        self.assertTrue(wait_for(lambda: len(self.markers) > count, 10.0), "no markers")
        by_namespace = {(m.ns, m.type): m for m in self.markers[-1].markers if m.action == Marker.ADD}
        strip = by_namespace[("cable", Marker.LINE_STRIP)]
        self.assertEqual(len(strip.points), 41)
        self.assertAlmostEqual(strip.scale.x, 2 * RADIUS)
        frames = by_namespace[("cable/frames", Marker.LINE_LIST)]
        self.assertEqual(len(frames.points), 40 * 6)
        self.assertNotIn(("cable", Marker.SPHERE_LIST), by_namespace)


if __name__ == "__main__":
    rostest.rosrun("soft_body_sim", "rod", RodNodeTest)

#!/usr/bin/python3
"""A soft solid the ROS way (launched by volume.test on config/scenes/soft_box.yaml): the markers draw
the box as its surface (a TRIANGLE_LIST, every point finite) and its nodes in a namespace of their own;
it lands and rests on the table, whose wrench topic (and ~state) carries the box's weight, rho a^3 g (its
lumped masses sum to rho times its volume); a gripper closing on its top and rising lifts it off the
table, and the gripper's wrench topic carries that weight."""
import math

import rospy
import rostest
from geometry_msgs.msg import WrenchStamped
from visualization_msgs.msg import Marker, MarkerArray

from node_client import FrameBroadcaster, NodeTestCase, StateWatcher, wait_for
from soft_body_sim.srv import Detach, Grasp

NODE = "/soft_body_sim"
SIZE = 0.08                 # [m] soft_box.yaml: the cube's edge
DENSITY = 200.0             # [kg/m^3]
TABLE_TOP = 0.4             # [m]
WEIGHT = DENSITY * SIZE ** 3 * 9.81   # [N]


class VolumeNodeTest(NodeTestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_volume_node")
        cls.state = StateWatcher()
        cls.markers = []
        rospy.Subscriber(NODE + "/markers", MarkerArray, cls.markers.append, queue_size=10)
        cls.frames = FrameBroadcaster()
        cls.frames.set_position("press", (0.0, 0.0, 0.68))  # the pad held high, clear of the box
        rospy.wait_for_service(NODE + "/grasp", 20.0)
        cls.grasp = rospy.ServiceProxy(NODE + "/grasp", Grasp)
        cls.release = rospy.ServiceProxy(NODE + "/release", Detach)
        cls.state.next(1, 20.0)

    def box(self):
        return [(p.x, p.y, p.z) for p in self.state.latest.bodies[0].positions]

    def settle(self, speed=1e-3, timeout=40.0):
        self.assertTrue(wait_for(lambda: max(math.sqrt(v.x ** 2 + v.y ** 2 + v.z ** 2)
                                             for v in self.state.latest.bodies[0].velocities) < speed, timeout),
                        "the box did not come to rest")

    def test_a_grasp_on_its_top_lifts_it_and_reads_its_weight(self):
        self.settle()
        self.assertAlmostEqual(min(p[2] for p in self.box()), TABLE_TOP, delta=1e-3)
        self.the_table_carries_the_box()
        top = max(p[2] for p in self.box())
        start = rospy.Time.now().to_sec() + 1.0

        def hand(t):
            rise = min(0.1, max(0.0, 0.05 * (t - start)))  # 10 cm up in 2 s
            return (0.0, 0.0, top + rise), (0.0, 0.0, 0.0, 1.0)

        self.frames.set("hand", hand)
        self.assertTrue(wait_for(lambda: rospy.Time.now().to_sec() > start - 0.5, 5.0))
        response = self.grasp(frame="hand", body="box", radius=0.025, max_force=0.0)
        self.assertTrue(response.success, response.message)
        self.assertGreater(len(response.nodes), 0)
        wrenches = []
        subscriber = rospy.Subscriber(NODE + "/box/hand/wrench", WrenchStamped, wrenches.append, queue_size=100)
        try:
            self.assertTrue(wait_for(lambda: rospy.Time.now().to_sec() > start + 2.5, 10.0))
            self.settle()
            self.assertGreater(min(p[2] for p in self.box()), TABLE_TOP + 0.05, "the box did not leave the table")
            count = len(wrenches)
            self.assertTrue(wait_for(lambda: len(wrenches) > count + 30, 10.0), "no wrench on ~box/hand/wrench")
            forces = [w.wrench.force for w in wrenches[-30:]]
            # The box pulls the gripper down with its weight; nothing else holds it.
            self.assertAlmostEqual(sum(f.z for f in forces) / len(forces), -WEIGHT, delta=0.02 * WEIGHT)
            self.assertLess(max(math.hypot(f.x, f.y) for f in forces), 0.02 * WEIGHT)
        finally:
            subscriber.unregister()
        self.assertTrue(self.release(frame="hand").success)

    def the_table_carries_the_box(self):
        """The box at rest presses on the table with its weight, in the scene frame (~colliders/table/wrench,
        the mean over 20 ticks: a tick's wrench is its last step's), the pad above it feels nothing, and
        ~state lists both with the same wrenches."""
        tables, pads = [], []
        subscribers = [rospy.Subscriber(NODE + "/colliders/" + name + "/wrench", WrenchStamped, into.append,
                                        queue_size=100) for name, into in (("table", tables), ("pad", pads))]
        try:
            self.assertTrue(wait_for(lambda: len(tables) > 20 and len(pads) > 0, 10.0),
                            "no wrench on ~colliders/table/wrench or ~colliders/pad/wrench")
        finally:
            for subscriber in subscribers:
                subscriber.unregister()
        self.assertEqual(tables[-1].header.frame_id, "world")
        forces = [w.wrench.force for w in tables[-20:]]
        self.assertAlmostEqual(sum(f.z for f in forces) / len(forces), -WEIGHT, delta=0.02 * WEIGHT)
        self.assertLess(max(math.hypot(f.x, f.y) for f in forces), 0.02 * WEIGHT)
        self.assertEqual(pads[-1].wrench.force.z, 0.0)
        state = self.state.next(1)
        self.assertEqual(list(state.colliders), ["table", "pad"])
        self.assertAlmostEqual(state.collider_wrenches[0].force.z, -WEIGHT, delta=0.05 * WEIGHT)

    def test_the_markers_draw_its_surface_and_its_nodes_apart(self):
        count = len(self.markers)
        self.assertTrue(wait_for(lambda: len(self.markers) > count, 10.0), "no markers")
        by_namespace = {(m.ns, m.type): m for m in self.markers[-1].markers if m.action == Marker.ADD}
        surface = by_namespace[("box", Marker.TRIANGLE_LIST)]
        self.assertGreater(len(surface.points), 0)
        self.assertEqual(len(surface.points) % 3, 0)
        self.assertTrue(all(math.isfinite(p.x) and math.isfinite(p.y) and math.isfinite(p.z) for p in surface.points))
        nodes = by_namespace[("box/nodes", Marker.SPHERE_LIST)]
        self.assertEqual(len(nodes.points), len(self.state.latest.bodies[0].positions))


if __name__ == "__main__":
    rostest.rosrun("soft_body_sim", "volume", VolumeNodeTest)

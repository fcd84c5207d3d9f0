#!/usr/bin/python3
"""Colliders from a URDF (launched by robot_colliders.test): the table, post, knob and bracket (a mesh) of
test_robot.urdf follow their links as robot_state_publisher moves them; a rope dropped onto the table
rests on its top, pressing the table's collider (named by its link) with its weight; the table's and the
bracket's markers follow the prismatic joint."""
import threading

import rospy
import rostest
from geometry_msgs.msg import WrenchStamped
from sensor_msgs.msg import JointState
from std_srvs.srv import Empty
from visualization_msgs.msg import MarkerArray

from node_client import NodeTestCase, StateWatcher, wait_for

NODE = "/soft_body_sim"
TABLE_TOP = 0.25     # [m] the box's top: its origin 0.2 m above the link, half its 0.1 m height
ROPE_RADIUS = 0.005  # [m]
ROPE_WEIGHT = 0.04 * 9.81  # [N]


class RobotCollidersTest(NodeTestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_robot_colliders")
        cls.state = StateWatcher()
        cls.slide = 0.0
        cls.lock = threading.Lock()
        cls.joints = rospy.Publisher("/joint_states", JointState, queue_size=10)
        cls.timer = rospy.Timer(rospy.Duration(0.02), cls._publish_joints)
        cls.markers = []
        rospy.Subscriber(NODE + "/markers", MarkerArray,
                         lambda a: cls.markers.append([m for m in a.markers if m.ns == "colliders"]), queue_size=10)
        cls.state.next(1, 20.0)

    @classmethod
    def _publish_joints(cls, _event):
        with cls.lock:
            position = cls.slide
        message = JointState()
        message.header.stamp = rospy.Time.now()
        message.name = ["slide"]
        message.position = [position]
        cls.joints.publish(message)

    def shapes(self):
        """The latest collider markers by type: CUBE, CYLINDER, SPHERE, MESH_RESOURCE."""
        latest = self.markers[-1] if self.markers else []
        return {m.type: m for m in latest}

    def test_1_the_rope_drapes_on_the_table_and_the_markers_follow_the_joint(self):
        # Every collision of the URDF is drawn once robot_state_publisher's tf arrives. The rope fell
        # through before that (the node simulates from its start); ~reset drops it again, onto the table.
        self.assertTrue(wait_for(lambda: len(self.shapes()) == 4, 20.0), self.shapes())
        rospy.wait_for_service(NODE + "/reset", 10.0)
        rospy.ServiceProxy(NODE + "/reset", Empty)()
        # Dropped 0.15 m, the rope lies on the table's top within a few seconds: no node below it, the
        # middle ones on it (the table is 0.6 m long, the rope 0.4 m: all of it is over the table).
        self.state.next(150)
        z = [p.z for p in self.state.next(1).bodies[0].positions]
        self.assertGreater(min(z), TABLE_TOP + ROPE_RADIUS - 1e-3, z)
        self.assertLess(abs(z[10] - (TABLE_TOP + ROPE_RADIUS)), 2e-3, z)
        self.assertLess(abs(self.shapes()[1].pose.position.x), 1e-3)  # 1 = CUBE: the table at slide 0
        # The rope at rest presses the table down with its weight (the mean over 20 ticks).
        wrenches = []
        subscriber = rospy.Subscriber(NODE + "/colliders/table/wrench", WrenchStamped, wrenches.append,
                                      queue_size=100)
        try:
            self.assertTrue(wait_for(lambda: len(wrenches) > 20, 10.0), "no wrench on ~colliders/table/wrench")
        finally:
            subscriber.unregister()
        self.assertEqual(wrenches[-1].header.frame_id, "world")
        mean_z = sum(w.wrench.force.z for w in wrenches[-20:]) / 20
        self.assertAlmostEqual(mean_z, -ROPE_WEIGHT, delta=0.02 * ROPE_WEIGHT)
        # The joint moves the table 0.1 m along x; its marker and the post on it follow.
        with self.lock:
            type(self).slide = 0.1  # the class's: the timer publishes it
        self.assertTrue(wait_for(lambda: abs(self.shapes()[1].pose.position.x - 0.1) < 1e-3, 10.0),
                        self.shapes()[1].pose.position)
        post = self.shapes()[3]  # 3 = CYLINDER
        self.assertAlmostEqual(post.pose.position.x, 0.35, delta=1e-3)
        self.assertAlmostEqual(post.pose.position.z, 0.35, delta=1e-3)
        knob = self.shapes()[2]  # 2 = SPHERE
        self.assertAlmostEqual(knob.pose.position.z, 0.48, delta=1e-3)
        bracket = self.shapes()[10]  # 10 = MESH_RESOURCE: the bracket, on the table at x = -0.2 + 0.1
        self.assertEqual(bracket.mesh_resource, "package://soft_body_sim/config/meshes/part.stl")
        self.assertAlmostEqual(bracket.pose.position.x, -0.1, delta=1e-3)
        self.assertAlmostEqual(bracket.scale.x, 1.0)


if __name__ == "__main__":
    rostest.rosrun("soft_body_sim", "robot_colliders", RobotCollidersTest)

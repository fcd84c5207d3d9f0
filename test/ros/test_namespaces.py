#!/usr/bin/python3
"""Two simulators side by side (launched by namespaces.test): /a runs node_test_scene.yaml (a 5-node
rope with anchors start and end), /b config/scenes/rope.yaml (a 21-node rope with anchors left and
right). Both bodies are called rope; what is done to one must not reach the other."""

import dynamic_reconfigure.client
import rospy
import rostest
from geometry_msgs.msg import PoseStamped
from std_srvs.srv import Empty, SetBool
from visualization_msgs.msg import InteractiveMarkerInit

from node_client import NodeTestCase, StateWatcher, wait_for


def pose(x, y, z):
    message = PoseStamped()
    message.header.frame_id = "world"
    message.pose.position.x, message.pose.position.y, message.pose.position.z = x, y, z
    message.pose.orientation.w = 1.0
    return message


class NamespacesTest(NodeTestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_namespaces")
        cls.a = StateWatcher("/a/soft_body_sim/state")
        cls.b = StateWatcher("/b/soft_body_sim/state")
        cls.handles = {}
        for ns in ("a", "b"):
            rospy.Subscriber(f"/{ns}/soft_body_sim/handles/update_full", InteractiveMarkerInit,
                             lambda m, ns=ns: cls.handles.__setitem__(ns, sorted(h.name for h in m.markers)))
            rospy.wait_for_service(f"/{ns}/soft_body_sim/reset", 20.0)
        cls.a.next(1, 20.0)
        cls.b.next(1, 20.0)

    def test_each_runs_its_own_scene_with_its_own_handles(self):
        self.assertEqual([(b.name, len(b.positions)) for b in self.a.latest.bodies], [("rope", 5)])
        self.assertEqual([(b.name, len(b.positions)) for b in self.b.latest.bodies], [("rope", 21)])
        self.assertTrue(wait_for(lambda: len(self.handles) == 2, 10.0))
        self.assertEqual(self.handles["a"], ["rope/end", "rope/start"])
        self.assertEqual(self.handles["b"], ["rope/left", "rope/right"])

    def test_inputs_services_and_tuning_stay_in_their_namespace(self):
        b_end = self.b.node("rope", 20)
        publisher = rospy.Publisher("/a/soft_body_sim/rope/end/pose", PoseStamped, queue_size=10)
        self.assertTrue(wait_for(lambda: publisher.get_num_connections() > 0, 10.0))
        publisher.publish(pose(0.9, 0.0, 1.0))
        self.assertTrue(wait_for(lambda: self.a.node("rope", 4) == (0.9, 0.0, 1.0), 10.0))
        self.b.next(5)
        self.assertEqual(self.b.node("rope", 20), b_end)  # b's anchored end did not move

        # Resetting b leaves a's dragged end where it is.
        rospy.ServiceProxy("/b/soft_body_sim/reset", Empty)()
        self.a.next(5)
        self.assertEqual(self.a.node("rope", 4), (0.9, 0.0, 1.0))

        # Pausing a stops a's motion only (b's rope swings after its reset).
        pause = rospy.ServiceProxy("/a/soft_body_sim/pause", SetBool)
        pause(True)
        self.a.next(2)
        held = self.a.node("rope", 2)
        b_before = self.b.next(1) and self.b.node("rope", 10)
        self.a.next(10)
        self.b.next(10)
        self.assertEqual(self.a.node("rope", 2), held)
        self.assertNotEqual(self.b.node("rope", 10), b_before)
        pause(False)

        # Tuning a's gravity leaves b's.
        a_config = dynamic_reconfigure.client.Client("/a/soft_body_sim", timeout=10)
        b_config = dynamic_reconfigure.client.Client("/b/soft_body_sim", timeout=10)
        self.assertEqual(a_config.update_configuration({"gravity_z": -1.0})["gravity_z"], -1.0)
        self.assertTrue(wait_for(lambda: a_config.get_configuration(5)["gravity_z"] == -1.0, 5.0))
        self.assertEqual(b_config.get_configuration(5)["gravity_z"], -9.81)
        a_config.update_configuration({"gravity_z": -9.81})


if __name__ == "__main__":
    rostest.rosrun("soft_body_sim", "namespaces", NamespacesTest)

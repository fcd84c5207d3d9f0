#!/usr/bin/python3
"""grasp_example.py on the demo scene (grasp_example.test, 2 s of motion and 2 s of holding): it grasps
the string's free end, the state lists its grasp while it holds, it prints the force on its gripper every
second, which is the same as the simulator's wrench topic says, and it lets go."""
import math
import re

import rospy
import rostest
from geometry_msgs.msg import WrenchStamped
from rosgraph_msgs.msg import Log

from node_client import NodeTestCase, StateWatcher, wait_for

NODE = "/soft_body_sim"


class GraspExampleTest(NodeTestCase):
    def test_the_client_grasps_prints_the_force_and_lets_go(self):
        rospy.init_node("test_grasp_example")
        state = StateWatcher()
        log = []
        rospy.Subscriber("/rosout", Log, lambda m: log.append(m) if m.name == "/grasp_example" else None,
                         queue_size=100)
        wrenches = []
        rospy.Subscriber(NODE + "/string/hand/wrench", WrenchStamped, wrenches.append, queue_size=100)
        state.next(1, 20.0)
        self.assertTrue(wait_for(lambda: any("holds" in m.msg for m in log), 30.0), [m.msg for m in log])
        held = state.next(5)
        string = next(b for b in held.bodies if b.name == "string")
        self.assertIn("hand", string.holders)
        self.assertTrue(wait_for(lambda: any("released" in m.msg for m in log), 30.0), [m.msg for m in log])
        printed = [m.msg for m in log if "|F| =" in m.msg]
        self.assertGreaterEqual(len(printed), 3, [m.msg for m in log])
        # Each printed force is one that the simulator published.
        magnitudes = [math.sqrt(w.wrench.force.x ** 2 + w.wrench.force.y ** 2 + w.wrench.force.z ** 2) for w in wrenches]
        for line in printed:
            value = float(re.search(r"\|F\| = ([0-9.]+) N", line).group(1))
            self.assertLess(min(abs(value - m) for m in magnitudes), 1e-3, line)
        state.next(3)
        string = next(b for b in state.latest.bodies if b.name == "string")
        self.assertNotIn("hand", string.holders)


if __name__ == "__main__":
    rostest.rosrun("soft_body_sim", "grasp_example_test", GraspExampleTest)

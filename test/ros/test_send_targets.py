#!/usr/bin/python3
"""send_targets.py with its defaults on the demo scene (send_targets.test): the rope's right end is
driven around a circle of 0.25 m about (-6.75, 0, 1.5) in the x-z plane, one turn in 4 s, and the
codeling's target along a figure eight about (3.6, 0, 1.2)."""
import math

import rospy
import rostest

from node_client import NodeTestCase, StateWatcher

CENTER = (-6.75, 0.0, 1.5)
RADIUS = 0.25


class SendTargetsTest(NodeTestCase):
    def test_the_anchor_circles_and_the_creature_swims(self):
        rospy.init_node("test_send_targets")
        state = StateWatcher()
        state.next(1, 20.0)
        state.next(60)  # the first poses have arrived and taken effect
        lead_start = state.node("codeling", 0)
        angles = []
        for _ in range(120):  # 2 s at 60 Hz
            state.next(1)
            x, y, z = state.node("rope", 20)
            # An anchor ends each step exactly at its last pose, and every pose is on the circle.
            self.assertAlmostEqual(math.hypot(x - CENTER[0], z - CENTER[2]), RADIUS, delta=1e-9)
            self.assertEqual(y, CENTER[1])
            angles.append(math.atan2(z - CENTER[2], x - CENTER[0]))
        turned = sum(abs(math.remainder(b - a, 2.0 * math.pi)) for a, b in zip(angles, angles[1:]))
        self.assertGreater(turned, 0.5 * math.pi)  # half a turn in 2 s, give or take the ticks
        self.assertGreater(math.dist(state.node("codeling", 0), lead_start), 0.05)


if __name__ == "__main__":
    rostest.rosrun("soft_body_sim", "example_client", SendTargetsTest)

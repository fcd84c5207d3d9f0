#!/usr/bin/python3
"""demo.launch as shipped, rviz off (demo_launch.test): for 60 s the codeling swims send_targets.py's
figure eight and the rope's right end circles, and ~state shows no catch of the divergence guard, no
frozen body and a real-time factor near 1, and the codeling swims its figure."""
import math

import rospy
import rostest

from node_client import NodeTestCase, StateWatcher

DURATION = 60.0  # [s] of ROS time


class DemoLaunchTest(NodeTestCase):
    def test_a_minute_of_the_demo_as_shipped(self):
        rospy.init_node("test_demo_launch")
        state = StateWatcher()
        state.next(1, 30.0)
        start = state.latest.header.stamp
        leads = []
        while (state.latest.header.stamp - start).to_sec() < DURATION:
            latest = state.next(30)  # a second: demo.launch publishes ~state at 30 Hz
            leads.append(state.node("codeling", 0))
            self.assertEqual(latest.divergence_events, 0, [b.name for b in latest.bodies if b.divergence_events])
            self.assertEqual([b.name for b in latest.bodies if b.frozen], [])
            self.assertEqual([b.integrator for b in latest.bodies], ["xpbd"] * len(latest.bodies))
        # Every published value is finite. (Speeds are bounded in test_streamed_inputs, where the input
        # timing is exact; here a tick that falls behind can land several poses of an anchor in one step.)
        for message in state.states:
            for body in message.bodies:
                for p, v in zip(body.positions, body.velocities):
                    self.assertTrue(all(map(math.isfinite, (p.x, p.y, p.z, v.x, v.y, v.z))), body.name)
        # The node keeps up with real time: the factor over the last half of the run (the first second
        # includes start-up).
        factors = [s.real_time_factor for s in state.states[len(state.states) // 2:]]
        self.assertAlmostEqual(sum(factors) / len(factors), 1.0, delta=0.05)
        # The codeling swims: its lead stays within 0.15 m of the figure eight's box
        # (3.6 +- 0.5, 0 +- 0.25) and crosses most of its width.
        xs = [p[0] for p in leads[5:]]
        self.assertGreater(max(xs) - min(xs), 0.7)
        for x, y, _ in leads[5:]:
            self.assertLess(abs(x - 3.6), 0.65)
            self.assertLess(abs(y), 0.4)


if __name__ == "__main__":
    rostest.rosrun("soft_body_sim", "demo_launch", DemoLaunchTest)

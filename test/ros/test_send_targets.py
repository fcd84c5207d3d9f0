#!/usr/bin/python3
"""send_targets.py with its defaults on the demo scene (send_targets.test): the rope's right end is
driven around a circle of 0.25 m about (-6.75, 0, 1.5) in the x-z plane, one turn in 4 s, by poses at
20 Hz, and the codeling's target along a figure eight about (3.6, 0, 1.2). The node glides between the
poses (~max_input_interval, input_glide.h): the end moves along the chords between them, from step to
step never faster than 1.5 times the circle's speed in simulated time, with each integrator that keeps
the demo stable (xpbd, the scene's, and implicit_euler), where reaching each pose in one step moved it at
up to 4.2 m/s, eleven times the circle's 0.39 m/s (measured with ~max_input_interval 0)."""
import math

import rospy
import rostest

from node_client import NodeTestCase, StateWatcher, run

CENTER = (-6.75, 0.0, 1.5)
RADIUS = 0.25
SPEED = RADIUS * 2.0 * math.pi / 4.0  # [m/s] along the circle
# The chord between poses up to two periods apart (a missed tick) sags this far inside the circle.
SAG = RADIUS * (1.0 - math.cos(2.0 * math.pi / 4.0 * 0.1 / 2.0))


class SendTargetsTest(NodeTestCase):
    def test_the_anchor_circles_smoothly_and_the_creature_swims(self):
        rospy.init_node("test_send_targets")
        state = StateWatcher()
        state.next(1, 20.0)
        state.next(200)  # the first poses have arrived and taken effect
        for integrator in ["xpbd", "implicit_euler"]:
            run("rosrun", "dynamic_reconfigure", "dynparam", "set", "/soft_body_sim", "integrator", integrator)
            state.next(100)
            self.assertEqual({body.integrator for body in state.latest.bodies}, {integrator})
            lead_start = state.node("codeling", 0)
            angles, fastest, factors = [], 0.0, []
            last = None
            begin = state.latest.header.stamp.to_sec()
            while state.latest.header.stamp.to_sec() < begin + 2.0:
                message = state.next(1)
                x, y, z = state.node("rope", 20)
                distance = math.hypot(x - CENTER[0], z - CENTER[2])
                self.assertLessEqual(distance, RADIUS + 1e-9)  # on a chord of the circle
                self.assertGreaterEqual(distance, RADIUS - SAG)
                self.assertEqual(y, CENTER[1])
                angles.append(math.atan2(z - CENTER[2], x - CENTER[0]))
                stamp = message.header.stamp.to_sec()
                if last is not None and stamp > last[0]:
                    fastest = max(fastest, math.dist((x, y, z), last[1]) / (stamp - last[0]))
                last = (stamp, (x, y, z))
                factors.append(message.real_time_factor)
            # A node that cannot keep real time drops time (~tick_budget): in simulated time the poses come
            # faster, and the circle is run faster by 1 / its real-time factor.
            factor = min(1.0, sum(factors) / len(factors))
            print(f"{integrator}: the rope's end at most {fastest:.3f} m/s from step to step; the circle "
                  f"{SPEED:.3f} m/s of ROS time, real-time factor {factor:.2f}", flush=True)
            self.assertLessEqual(fastest, 1.5 * SPEED / factor)
            turned = sum(abs(math.remainder(b - a, 2.0 * math.pi)) for a, b in zip(angles, angles[1:]))
            self.assertGreater(turned, 0.5 * math.pi)  # half a turn in 2 s, give or take the ticks
            self.assertGreater(math.dist(state.node("codeling", 0), lead_start), 0.05)


if __name__ == "__main__":
    rostest.rosrun("soft_body_sim", "example_client", SendTargetsTest)

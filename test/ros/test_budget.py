#!/usr/bin/python3
"""The wall-time budget of a tick (launched by budget.test on config/scenes/cloth.yaml: a 15 x 15 xpbd
cloth, dt = 10 ms, 10 substeps, 1 iteration). At substeps 100, iterations 100, dt = 10 us, each value
within its reconfigure range, a step sweeps every constraint 10^4 times: tens of milliseconds, and the
two ticks' worth of steps that the catch-up cap allows (3333) would hold the node for minutes."""
import threading
import time

import dynamic_reconfigure.client
import rospy
import rostest
from rosgraph_msgs.msg import Log
from std_srvs.srv import SetBool

from node_client import NodeTestCase, StateWatcher, wait_for

NODE = "/soft_body_sim"
HEAVY = {"substeps": 100, "iterations": 100, "dt": 1.0e-5}
# [s] for a service answer. A tick ends after ~tick_budget (0.8 / 60 Hz = 13 ms) plus the one step it
# always takes; 3 s leaves room for a loaded machine, and the stall this guards against lasts minutes.
ANSWER_WITHIN = 3.0


def timed_call(proxy, *args):
    """The proxy's answer and the wall time it took [s], or None if none came within ANSWER_WITHIN."""
    answer = []
    start = time.monotonic()
    caller = threading.Thread(target=lambda: answer.append(proxy(*args)), daemon=True)
    caller.start()
    caller.join(ANSWER_WITHIN)
    return (answer[0] if answer else None), time.monotonic() - start


class BudgetTest(NodeTestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_budget")
        cls.state = StateWatcher()
        cls.log = []
        rospy.Subscriber("/rosout", Log, cls.log.append, queue_size=100)
        rospy.wait_for_service(NODE + "/set_parameters", 20.0)
        rospy.wait_for_service(NODE + "/pause", 20.0)
        cls.physics = dynamic_reconfigure.client.Client(NODE, timeout=10)
        cls.state.next(10, 20.0)  # the node has measured its step cost

    def warned(self, text, start):
        return wait_for(lambda: any(text in m.msg and m.level == Log.WARN for m in self.log[start:]), 10.0)

    def test_heavy_settings_slow_the_simulation_not_the_answers(self):
        start = len(self.log)
        self.physics.update_configuration(HEAVY)
        pause = rospy.ServiceProxy(NODE + "/pause", SetBool)
        for _ in range(3):
            answer, took = timed_call(pause, False)
            self.assertIsNotNone(answer, f"~pause not answered within {took:.1f} s")
            self.assertEqual(answer.message, "running")
        # States keep coming, each tick stopping at its budget ...
        first = self.state.count()
        self.state.next(5, 10.0)
        self.assertGreater(self.state.states[-1].header.stamp, self.state.states[first].header.stamp)
        # ... and the node says why: the reconfigure answer beforehand, the ticks as they run out.
        self.assertTrue(self.warned("cannot keep real time on this scene", start),
                        [m.msg for m in self.log[start:]])
        self.assertTrue(self.warned("ran out of ~tick_budget", start), [m.msg for m in self.log[start:]])


if __name__ == "__main__":
    rostest.rosrun("soft_body_sim", "budget", BudgetTest)

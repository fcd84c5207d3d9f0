"""Helpers shared by the Python rostests: wait for a condition while rospy delivers messages, keep
the latest state of a simulator, run the standard command-line clients."""
import subprocess
import time

import rospy
from soft_body_sim.msg import SimState


def wait_for(condition, timeout, period=0.005):
    """True as soon as condition() holds, False after `timeout` seconds of wall time; condition() is
    asked every `period` seconds (longer for a question to the master)."""
    end = time.monotonic() + timeout
    while time.monotonic() < end and not rospy.is_shutdown():
        if condition():
            return True
        time.sleep(period)
    return condition()


def run(*command, timeout=30):
    """Runs a command-line client (dynparam, rostopic, rosservice) and returns its stdout."""
    result = subprocess.run(command, capture_output=True, text=True, timeout=timeout)
    if result.returncode != 0:
        raise AssertionError(f"{' '.join(command)} exited {result.returncode}: {result.stderr.strip()}")
    return result.stdout


class StateWatcher:
    """Keeps every SimState of one simulator (stamp -> message) and the latest one."""

    def __init__(self, topic="/soft_body_sim/state"):
        self.states = []
        self.latest = None
        self.subscriber = rospy.Subscriber(topic, SimState, self._on_state, queue_size=100)

    def _on_state(self, message):
        self.states.append(message)
        self.latest = message

    def count(self):
        return len(self.states)

    def next(self, n=1, timeout=10.0):
        """Waits for n more states and returns the latest."""
        target = len(self.states) + n
        if not wait_for(lambda: len(self.states) >= target, timeout):
            raise AssertionError(f"no state for {timeout} s")
        return self.latest

    def node(self, body, index):
        """(x, y, z) of a node in the latest state."""
        for b in self.latest.bodies:
            if b.name == body:
                p = b.positions[index]
                return (p.x, p.y, p.z)
        raise KeyError(body)

"""Helpers shared by the Python rostests: wait for a condition while rospy delivers messages, keep
the latest state of a simulator, broadcast tf frames, run the standard command-line clients."""
import subprocess
import threading
import time
import unittest

import rospy
import tf2_ros
from geometry_msgs.msg import TransformStamped
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


class FrameBroadcaster:
    """Broadcasts tf frames, children of `parent`, every `period` seconds: each given by a function of the
    ROS time [s] that returns its (position, quaternion (x, y, z, w)). Stamped `lead` seconds ahead of now
    (the pose at that time), a frame is known at every instant up to then: tf interpolates it exactly."""

    def __init__(self, parent="world", period=0.02, lead=0.0):
        self.parent = parent
        self.lead = rospy.Duration(lead)
        self.frames = {}
        self.lock = threading.Lock()
        self.broadcaster = tf2_ros.TransformBroadcaster()
        self.timer = rospy.Timer(rospy.Duration(period), self._broadcast)

    def set(self, child, pose):
        with self.lock:
            self.frames[child] = pose

    def set_position(self, child, position):
        """A frame standing still at `position`, unrotated."""
        self.set(child, lambda _t: (position, (0.0, 0.0, 0.0, 1.0)))

    def _broadcast(self, _event):
        now = rospy.Time.now() + self.lead
        with self.lock:
            frames = dict(self.frames)
        transforms = []
        for child, pose in frames.items():
            (x, y, z), (qx, qy, qz, qw) = pose(now.to_sec())
            t = TransformStamped()
            t.header.stamp = now
            t.header.frame_id = self.parent
            t.child_frame_id = child
            t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = x, y, z
            t.transform.rotation.x, t.transform.rotation.y, t.transform.rotation.z = qx, qy, qz
            t.transform.rotation.w = qw
            transforms.append(t)
        if not transforms:
            return
        try:
            self.broadcaster.sendTransform(transforms)
        except rospy.ROSException:
            if not rospy.core.is_shutdown_requested():
                raise  # else the test is over: its timer's last tick found the topic closed


class StateWatcher:
    """Keeps every SimState of one simulator (stamp -> message) and the latest one."""

    instances = []  # every watcher of this test process, for NodeTestCase's check

    def __init__(self, topic="/soft_body_sim/state"):
        self.states = []
        self.latest = None
        self.expected_events = 0
        self.subscriber = rospy.Subscriber(topic, SimState, self._on_state, queue_size=100)
        StateWatcher.instances.append(self)

    def expect_guard_events(self):
        """The divergence guard's catches so far were the test's purpose (and it checked them)."""
        self.expected_events = self.latest.divergence_events

    def unexpected_guard_events(self):
        """Catches of the divergence guard that no test expected."""
        return 0 if self.latest is None else self.latest.divergence_events - self.expected_events

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


class NodeTestCase(unittest.TestCase):
    """A rostest case that fails when the divergence guard of a watched simulator caught a body that the
    test did not expect (StateWatcher.expect_guard_events): the guard is a safety net for users, and in a
    test it would turn an explosion into a log line that nobody reads."""

    def tearDown(self):
        for watcher in StateWatcher.instances:
            events = watcher.unexpected_guard_events()
            self.assertEqual(events, 0, f"the divergence guard caught {events} time(s) on {watcher.subscriber.name}")

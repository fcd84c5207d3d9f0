#!/usr/bin/python3
"""The clients of the README's second terminal beside the demo (demo_clients.test), each run as a user
types it: `rostopic echo -n1` of ~state, `rosservice call` of ~grasp and ~release, and
`rosrun soft_body_sim grasp_example.py`. Each loads the package's generated Python messages or services,
which the node itself does not need: on a build of the node alone they fail ("Cannot load message class
for [soft_body_sim/SimState]", "Unable to load type [soft_body_sim/Grasp]"). This test imports none of
them itself, so that it reports what the clients print."""
import subprocess
import time
import unittest

import rospy
import rostest
import tf2_ros
import yaml
from geometry_msgs.msg import TransformStamped

NODE = "/soft_body_sim"
# The command-line grasp's tf frame, broadcast by this test, stands at the string's anchored middle node
# (config/scenes/demo.yaml: node 39 at (-4.0, 0.0, 2.5)): its free neighbours, 5 cm away along the
# string, stay within the grasp's 0.1 m however the string swings. grasp_example.py grasps with its own
# frame, `hand`.
FRAME = "terminal_hand"
PIN = (-4.0, 0.0, 2.5)


def run(command, timeout):
    """Runs a command line in a shell, as typed in a terminal; returns its stdout, or fails when it exits
    non-zero or has not finished after `timeout` seconds, with its error in the first line (scripts/test's
    summary shows that line: the ROS tools' "ERROR: ..." line, else the last, a traceback's exception)
    and then all it printed."""
    try:
        result = subprocess.run(command, shell=True, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired as e:
        raise AssertionError(f"`{command}` had not finished after {timeout} s; it printed:\n{e.stderr}\n{e.stdout}") from None
    if result.returncode != 0:
        lines = result.stderr.strip().splitlines() or [""]
        error = next((line for line in lines if line.startswith("ERROR")), lines[-1])
        raise AssertionError(f"`{command}` exited {result.returncode}: {error}\n{result.stderr}\n{result.stdout[-2000:]}")
    return result.stdout


class DemoClientsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_demo_clients")
        frame = TransformStamped()
        frame.header.stamp = rospy.Time.now()
        frame.header.frame_id = "world"
        frame.child_frame_id = FRAME
        frame.transform.translation.x, frame.transform.translation.y, frame.transform.translation.z = PIN
        frame.transform.rotation.w = 1.0
        cls.frame_broadcaster = tf2_ros.StaticTransformBroadcaster()
        cls.frame_broadcaster.sendTransform(frame)
        # The node loads the demo's scene before it offers its services and publishes its first state.
        rospy.wait_for_service(NODE + "/grasp", 30.0)

    def test_rostopic_echo_prints_a_state(self):
        out = run(f"rostopic echo -n1 {NODE}/state", timeout=30)
        for field in ("header:", "bodies:", 'name: "string"', "positions:", "real_time_factor:"):
            self.assertIn(field, out, out[:2000])

    def test_rosservice_grasps_the_string_and_releases_it(self):
        # The node hears of the frame from /tf_static a moment after this test broadcasts it: until then
        # it refuses the grasp, naming the frame.
        grasp = f'rosservice call {NODE}/grasp "{{frame: {FRAME}, body: string, radius: 0.1, max_force: 0.0}}"'
        deadline = time.monotonic() + 10.0
        out = run(grasp, timeout=30)
        while "success: True" not in out and time.monotonic() < deadline:
            time.sleep(0.5)
            out = run(grasp, timeout=30)
        response = yaml.safe_load(out)
        self.assertTrue(response["success"], out)
        # The anchored node is not free; its neighbours on either side are held.
        self.assertTrue({38, 40} <= set(response["nodes"]), out)
        out = run(f'rosservice call {NODE}/release "{{frame: {FRAME}}}"', timeout=30)
        self.assertTrue(yaml.safe_load(out)["success"], out)

    def test_grasp_example_lifts_the_string_and_lets_go(self):
        # Its five seconds of motion and three of holding, as the README runs it.
        out = run("rosrun soft_body_sim grasp_example.py", timeout=60)
        self.assertIn("holds", out)
        self.assertIn("|F| =", out)
        self.assertIn("released its grasp", out)


if __name__ == "__main__":
    rostest.rosrun("soft_body_sim", "demo_clients", DemoClientsTest)

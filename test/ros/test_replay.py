#!/usr/bin/python3
"""Determinism through rosbag (launched by replay.test, which starts only the master):

1. record: record.launch, then a node on replay_test_scene.yaml in wall-clock time, whose rope end the
   test drives along a path with poses stamped 0.1 s ahead (as send_targets.py does);
2. replay: a fresh node under /use_sim_time, told the recorded start time (~start_time, from the bag's
   ~start_time topic), fed only the bag's input topic by `rosbag play --clock`;
3. every state published by both at the same simulated instant must be bit-identical: same inputs at
   the same steps, same build, same arithmetic."""
import glob
import math
import os
import shutil
import signal
import subprocess
import tempfile
import time
import unittest

import rosbag
import rospy
import rostest
from geometry_msgs.msg import PoseStamped

from node_client import StateWatcher, wait_for

SCENE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "replay_test_scene.yaml")
INPUT = "/soft_body_sim/rope/end/pose"


def start(*command):
    return subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)


def stop(process):
    """SIGINT (rosbag closes its bag), then waits."""
    if process.poll() is None:
        os.killpg(process.pid, signal.SIGINT)
    process.wait(timeout=30)


def key(state):
    return state.header.stamp.to_nsec()


def values(state):
    """Every number of the state's bodies, exactly as sent."""
    return [(p.x, p.y, p.z, v.x, v.y, v.z) for body in state.bodies for p, v in zip(body.positions, body.velocities)]


class ReplayTest(unittest.TestCase):
    def setUp(self):
        self.folder = tempfile.mkdtemp(prefix="soft_body_sim_replay_")
        self.processes = []

    def tearDown(self):
        for process in self.processes:
            stop(process)
        shutil.rmtree(self.folder, ignore_errors=True)

    def launch(self, *command):
        process = start(*command)
        self.processes.append(process)
        return process

    def test_a_replayed_bag_of_inputs_reproduces_the_recorded_state_bit_for_bit(self):
        rospy.init_node("test_replay")
        watcher = StateWatcher()

        # --- 1. record a live run
        recorder = self.launch("roslaunch", "soft_body_sim", "record.launch", f"bag:={self.folder}/run")
        self.assertTrue(wait_for(lambda: "/record_soft_body_sim" in subprocess.run(
            ["rosnode", "list"], capture_output=True, text=True).stdout, 20.0))
        time.sleep(1.0)  # the recorder subscribes once the node's topics appear
        recorded_node = self.launch("rosrun", "soft_body_sim", "soft_body_sim_node", "__name:=soft_body_sim",
                                    f"_scene:={SCENE}")
        watcher.next(1, 20.0)
        publisher = rospy.Publisher(INPUT, PoseStamped, queue_size=10)
        self.assertTrue(wait_for(lambda: publisher.get_num_connections() >= 2, 10.0))  # node and recorder
        ticker = rospy.Rate(25)
        begin = time.monotonic()
        while time.monotonic() - begin < 3.0:
            pose = PoseStamped()
            pose.header.frame_id = "world"
            pose.header.stamp = rospy.Time.now() + rospy.Duration(0.1)
            phase = 2.0 * (time.monotonic() - begin)
            pose.pose.position.x = 0.4 + 0.2 * math.sin(phase)
            pose.pose.position.z = 1.0 + 0.2 * (1.0 - math.cos(phase))
            pose.pose.orientation.w = 1.0
            publisher.publish(pose)
            ticker.sleep()
        time.sleep(0.5)
        stop(recorded_node)
        stop(recorder)
        bags = glob.glob(os.path.join(self.folder, "run_*.bag"))
        self.assertEqual(len(bags), 1, os.listdir(self.folder))
        recorded, start_time, inputs, topics = {}, None, 0, set()
        with rosbag.Bag(bags[0]) as bag:
            for topic, message, _ in bag.read_messages():
                topics.add(topic)
                if topic == "/soft_body_sim/state":
                    recorded[key(message)] = values(message)
                elif topic == "/soft_body_sim/start_time":
                    start_time = message.data
                elif topic == INPUT:
                    inputs += 1
        # record.launch took inputs, markers, state and the start time.
        self.assertTrue({INPUT, "/soft_body_sim/markers", "/soft_body_sim/state", "/soft_body_sim/start_time"} <= topics,
                        topics)
        self.assertGreater(inputs, 50)
        self.assertIsNotNone(start_time)
        self.assertEqual(start_time.nsecs % 1000000, 0)  # a whole millisecond: exact as a double parameter
        end_x = [state[4][0] for state in recorded.values()]
        self.assertGreater(max(end_x) - min(end_x), 0.2)  # the inputs moved the rope

        # --- 2. replay the inputs into a fresh node under simulated time
        watcher.states.clear()
        rospy.set_param("/use_sim_time", True)
        self.launch("rosrun", "soft_body_sim", "soft_body_sim_node", "__name:=soft_body_sim", f"_scene:={SCENE}",
                    "_start_time:=%d.%03d" % (start_time.secs, start_time.nsecs // 1000000))
        time.sleep(2.0)  # the node is up before the clock starts
        player = self.launch("rosbag", "play", "--clock", "-q", bags[0], "--topics", INPUT)
        player.wait(timeout=60)
        time.sleep(0.5)

        # --- 3. the same instants hold the same numbers
        replayed = {key(state): values(state) for state in watcher.states}
        common = sorted(set(recorded) & set(replayed))
        self.assertGreater(len(common), 40, f"{len(recorded)} recorded, {len(replayed)} replayed states")
        mismatches = [stamp for stamp in common if recorded[stamp] != replayed[stamp]]
        print(f"replay: {len(common)} common instants of {len(recorded)} recorded, {len(replayed)} replayed states; "
              f"{len(mismatches)} differ", flush=True)
        self.assertEqual(mismatches, [], f"{len(mismatches)} of {len(common)} states differ")


if __name__ == "__main__":
    rostest.rosrun("soft_body_sim", "replay", ReplayTest)

#!/usr/bin/python3
"""Determinism through rosbag (launched by replay.test, which starts only the master):

1. record: record.launch, then sim.launch on replay_test_scene.yaml in wall-clock time, whose rope end
   the test drives along a path with poses stamped ahead (as send_targets.py does);
2. replay: a fresh sim.launch under /use_sim_time, told the recorded start time (start_time:=, from the
   bag's ~start_time topic), fed only the bag's input topic by `rosbag play --clock`;
3. every state published by both at the same simulated instant must be bit-identical: same inputs at
   the same steps, same build, same arithmetic.

Every step waits for what the next one needs (a node registered, a topic subscribed, a state past an
instant) rather than for a fixed time, within STARTUP seconds: on a loaded machine roslaunch alone can
take several seconds. The nodes are started with roslaunch, not rosrun: rosrun leaves out every path
under <package>/build/, so it cannot find the node of a devel space built inside the package (build/)."""
import glob
import math
import os
import shutil
import signal
import subprocess
import tempfile
import time

import rosbag
import rosgraph
import rospy
import rostest
from geometry_msgs.msg import PoseStamped

from node_client import NodeTestCase, StateWatcher, wait_for

SCENE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "replay_test_scene.yaml")
NODE = "/soft_body_sim"
INPUT = NODE + "/rope/end/pose"
STATE = NODE + "/state"
START_TIME = NODE + "/start_time"
RECORDER = "/record_soft_body_sim"
STARTUP = 60.0  # [s] bound on any one wait for a process to come up, subscribe or catch up
# [s] how far ahead the poses are stamped: an input must reach the node (and, for the replay, the
# recorder) before its step, whatever the load; send_targets.py's 0.1 s is meant for an idle machine.
LEAD = 0.5


def start(log, *command):
    return subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT, start_new_session=True)


def stop(process):
    """SIGINT to its process group (roslaunch stops its nodes, rosbag closes its bag), then waits."""
    if process.poll() is None:
        os.killpg(process.pid, signal.SIGINT)
    process.wait(timeout=STARTUP)


def subscriptions(node):
    """The topics `node` subscribes to, as the master knows them."""
    _, subscribers, _ = rosgraph.Master(rospy.get_name()).getSystemState()
    return {topic for topic, nodes in subscribers if node in nodes}


def registered(node):
    try:
        rosgraph.Master(rospy.get_name()).lookupNode(node)
        return True
    except rosgraph.MasterError:
        return False


def key(state):
    return state.header.stamp.to_nsec()


def values(state):
    """Every number of the state's bodies, exactly as sent."""
    return [(p.x, p.y, p.z, v.x, v.y, v.z) for body in state.bodies for p, v in zip(body.positions, body.velocities)]


class ReplayTest(NodeTestCase):
    def setUp(self):
        self.folder = tempfile.mkdtemp(prefix="soft_body_sim_replay_")
        self.processes = {}  # name -> a process still wanted
        self.logs = []  # the name of every process started

    def tearDown(self):
        for process in self.processes.values():
            stop(process)
        shutil.rmtree(self.folder, ignore_errors=True)

    def launch(self, name, *command):
        """Starts `command` with its output in <folder>/<name>.log, shown if the test fails."""
        with open(os.path.join(self.folder, name + ".log"), "w") as log:
            process = start(log, *command)
        self.processes[name] = process
        self.logs.append(name)
        return process

    def finish(self, name):
        """Stops process `name` (see stop())."""
        stop(self.processes.pop(name))

    def wait(self, condition, what):
        """Waits up to STARTUP seconds for condition(); fails at once, naming it, if a process exits first."""
        def holds_or_a_process_exited():
            return condition() or any(process.poll() is not None for process in self.processes.values())
        wait_for(holds_or_a_process_exited, STARTUP, 0.05)
        exited = [f"{name} (status {process.returncode})" for name, process in self.processes.items()
                  if process.poll() is not None]
        self.assertFalse(exited, f"exited while waiting for {what}")
        self.assertTrue(condition(), f"no {what} within {STARTUP} s")

    def print_logs(self):
        for name in self.logs:
            with open(os.path.join(self.folder, name + ".log"), errors="replace") as log:
                lines = log.readlines()[-30:]
            print(f"--- {name} (last {len(lines)} lines)\n{''.join(lines)}", flush=True)

    def test_a_replayed_bag_of_inputs_reproduces_the_recorded_state_bit_for_bit(self):
        rospy.init_node("test_replay")
        try:
            self.record_and_replay()
        except BaseException:
            self.print_logs()
            raise

    def record_and_replay(self):
        watcher = StateWatcher()

        # --- 1. record a live run
        self.launch("recorder", "roslaunch", "soft_body_sim", "record.launch", f"bag:={self.folder}/run")
        self.wait(lambda: registered(RECORDER), "recorder")
        self.launch("recorded_node", "roslaunch", "soft_body_sim", "sim.launch", f"scene:={SCENE}")
        self.wait(lambda: watcher.latest is not None, "state of the recorded node")
        # rosbag record subscribes to each matching topic once it sees it at the master: the inputs may
        # go out once it and the node listen to them, and it has the state and the start time.
        self.wait(lambda: {INPUT, STATE, START_TIME} <= subscriptions(RECORDER) and INPUT in subscriptions(NODE),
                  "subscription of the recorder and the node to the inputs")
        publisher = rospy.Publisher(INPUT, PoseStamped, queue_size=100)
        self.wait(lambda: publisher.get_num_connections() >= 2, "connection of the node and the recorder")
        ticker = rospy.Rate(25)
        begin = time.monotonic()
        last_stamp = None
        while time.monotonic() - begin < 3.0:
            pose = PoseStamped()
            pose.header.frame_id = "world"
            pose.header.stamp = last_stamp = rospy.Time.now() + rospy.Duration(LEAD)
            phase = 2.0 * (time.monotonic() - begin)
            pose.pose.position.x = 0.4 + 0.2 * math.sin(phase)
            pose.pose.position.z = 1.0 + 0.2 * (1.0 - math.cos(phase))
            pose.pose.orientation.w = 1.0
            publisher.publish(pose)
            ticker.sleep()
        # Every input has taken effect once the node has simulated past the last one's stamp.
        self.wait(lambda: watcher.latest.header.stamp > last_stamp + rospy.Duration(0.1), "state past the last input")
        self.finish("recorded_node")
        self.finish("recorder")
        bags = glob.glob(os.path.join(self.folder, "run_*.bag"))
        self.assertEqual(len(bags), 1, os.listdir(self.folder))
        recorded, start_times, inputs, late, topics, last_input_time = {}, set(), 0, 0, set(), None
        with rosbag.Bag(bags[0]) as bag:
            for topic, message, received in bag.read_messages():
                topics.add(topic)
                if topic == STATE:
                    recorded[key(message)] = values(message)
                elif topic == START_TIME:
                    start_times.add(message.data)
                elif topic == INPUT:
                    inputs += 1
                    late += message.header.stamp <= received
                    last_input_time = received
        # record.launch took inputs, markers, state and the start time.
        self.assertTrue({INPUT, NODE + "/markers", STATE, START_TIME} <= topics, topics)
        self.assertGreater(inputs, 50)
        self.assertEqual(len(start_times), 1, "the recorded node fell behind real time (its start time moved): such "
                         f"a recording is not replayable exactly; start times {sorted(start_times)}")
        start_time = start_times.pop()
        self.assertEqual(start_time.nsecs % 1000000, 0)  # a whole millisecond: exact as a double parameter
        # An input played back after its stamp would reach the replaying node late, at another step.
        self.assertEqual(late, 0, f"{late} of {inputs} inputs reached the recorder after their stamp")
        end_x = [state[4][0] for state in recorded.values()]
        self.assertGreater(max(end_x) - min(end_x), 0.2)  # the inputs moved the rope

        # --- 2. replay the inputs into a fresh node under simulated time
        watcher.states.clear()
        rospy.set_param("/use_sim_time", True)
        self.launch("replay_node", "roslaunch", "soft_body_sim", "sim.launch", f"scene:={SCENE}",
                    "start_time:=%d.%03d" % (start_time.secs, start_time.nsecs // 1000000))
        # Its time stands at 0 until the first /clock: it must hear the clock and the inputs from the start.
        self.wait(lambda: {INPUT, "/clock"} <= subscriptions(NODE), "subscription of the replaying node")
        player = self.launch("player", "rosbag", "play", "--clock", "--wait-for-subscribers", "-q", bags[0],
                             "--topics", INPUT)
        self.assertEqual(player.wait(timeout=STARTUP + 10.0), 0)
        self.processes.pop("player")
        # The clock stops at the last input: the node's last tick is at most a tick and a step before it.
        self.wait(lambda: watcher.latest is not None and watcher.latest.header.stamp > last_input_time - rospy.Duration(0.1),
                  "replayed state up to the last input")

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

#!/usr/bin/python3
"""Determinism through rosbag, on the demo as docs/node.md tells it (launched by replay.test, which starts
only the master):

1. record: demo.launch rviz:=false record:=<folder>/run: send_targets.py streams the rope's right end,
   the codeling's target and the gripper's tf frame once the simulator and the recorder listen. Under a
   /clock that the test runs at half speed, not wall-clock time: on a shared machine the demo, at a
   real-time factor near 1, may fall behind real time now and then, and such a bag is not replayable
   (bag_start_time.py says so); a clock it always keeps up with records what a fast machine records;
2. replay: a fresh sim.launch on the demo scene under /use_sim_time, told the recorded start time (from
   the bag's ~start_time), fed only the bag's input topics and /tf by `rosbag play --clock`;
3. every state published by both at the same simulated instant must be bit-identical in every body:
   same inputs at the same steps, same build, same arithmetic.

Every step waits for what the next one needs (a topic subscribed, a state past an
instant) rather than for a fixed time, within STARTUP seconds: on a loaded machine roslaunch alone can
take several seconds."""
import glob
import os
import shutil
import signal
import subprocess
import tempfile
import threading
import time

import rosbag
import rosgraph
import rospy
import rostest
from geometry_msgs.msg import PoseStamped
from rosgraph_msgs.msg import Clock

from node_client import NodeTestCase, StateWatcher, wait_for

NODE = "/soft_body_sim"
INPUTS = [NODE + "/rope/right/pose", NODE + "/codeling/target"]
STATE = NODE + "/state"
START_TIME = NODE + "/start_time"
BAG_START_TIME = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts", "bag_start_time.py")
STARTUP = 60.0  # [s] bound on any one wait for a process to come up, subscribe or catch up
RUN = 8.0  # [s] of the recorded demo from its first input: the gripper's fingers reach the rope by then
DT = 0.005  # [s] the demo scene's physics.dt
RATE = 0.5  # of the recording's clock and rosbag play's: ROS seconds per wall second


class HalfSpeedClock:
    """Publishes /clock from a plausible ROS time on, RATE times as fast as wall time, every 2 ms."""

    def __init__(self):
        self.publisher = rospy.Publisher("/clock", Clock, queue_size=10)
        self.running = True
        self.thread = threading.Thread(target=self.run, daemon=True)
        self.thread.start()

    def run(self):
        origin, begin = time.time(), time.monotonic()
        while self.running:
            self.publisher.publish(Clock(rospy.Time.from_sec(origin + RATE * (time.monotonic() - begin))))
            time.sleep(0.002)

    def stop(self):
        self.running = False
        self.thread.join()
        self.publisher.unregister()


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


def key(state):
    return state.header.stamp.to_nsec()


def values(state):
    """Every number of each body (by name), exactly as sent."""
    return {body.name: [(p.x, p.y, p.z, v.x, v.y, v.z) for p, v in zip(body.positions, body.velocities)]
            for body in state.bodies}


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
        first_input = []
        rospy.Subscriber(INPUTS[0], PoseStamped, lambda pose: first_input or first_input.append(pose.header.stamp))

        # --- 1. record the demo, from its first input
        rospy.set_param("/use_sim_time", True)  # for the nodes to come; this test's node keeps wall time
        clock = HalfSpeedClock()
        self.launch("demo", "roslaunch", "soft_body_sim", "demo.launch", "rviz:=false", f"record:={self.folder}/run")
        self.wait(lambda: first_input, "the first input of send_targets.py")
        self.wait(lambda: watcher.latest is not None and watcher.latest.header.stamp > first_input[0] + rospy.Duration(RUN),
                  f"state {RUN} s past the first input")
        self.finish("demo")
        clock.stop()
        bags = glob.glob(os.path.join(self.folder, "run_*.bag"))
        self.assertEqual(len(bags), 1, os.listdir(self.folder))
        # The start time to replay from, as docs/node.md has the user find it (the last one: it may move while
        # the demo starts up, not after the first input).
        found = subprocess.run([BAG_START_TIME, bags[0]], capture_output=True, text=True)
        self.assertEqual(found.returncode, 0, found.stderr)
        start_time = rospy.Time(*map(int, found.stdout.strip().split(".")))
        start_time.nsecs *= 1000000
        recorded, inputs, late, topics, last_input_time, first_recorded = {}, 0, 0, set(), None, {}
        with rosbag.Bag(bags[0]) as bag:
            for topic, message, received in bag.read_messages():
                topics.add(topic)
                if topic == STATE:
                    recorded[key(message)] = values(message)
                elif topic == START_TIME:
                    recorded.clear()  # the states before it are stamped from an earlier start time
                elif topic in INPUTS or topic == "/tf":
                    stamps = [message.header.stamp] if topic in INPUTS else [t.header.stamp for t in message.transforms]
                    first_recorded.setdefault(topic, min(stamps))
                    inputs += 1
                    late += sum(stamp <= received for stamp in stamps)
                    last_input_time = received
        self.assertTrue(set(INPUTS) | {"/tf", NODE + "/markers", STATE, START_TIME} <= topics, topics)
        # The bag holds every input from the first one the simulator heard (the test may have heard later).
        self.assertLessEqual(first_recorded[INPUTS[0]], first_input[0])
        self.assertGreater(inputs, 3 * 20 * RUN * 0.9)  # three streams at 20 Hz
        # An input played back after its stamp would reach the replaying node late, at another step.
        self.assertEqual(late, 0, f"{late} inputs reached the recorder after their stamp")

        # --- 2. replay the inputs into a fresh node under simulated time
        watcher.states.clear()
        # It publishes after every step (~rate = 1 / dt), so that each recorded state has its replayed twin.
        rospy.set_param(NODE + "/rate", 1.0 / DT)
        self.launch("replay_node", "roslaunch", "soft_body_sim", "sim.launch",
                    "start_time:=%d.%03d" % (start_time.secs, start_time.nsecs // 1000000))
        # Its time stands at 0 until the first /clock: it must hear the clock and the inputs from the start.
        self.wait(lambda: set(INPUTS) | {"/clock", "/tf"} <= subscriptions(NODE), "subscription of the replaying node")
        player = self.launch("player", "rosbag", "play", "--clock", "--hz", "1000", "--wait-for-subscribers", "-q",
                             "-r", str(RATE),
                             bags[0], "--topics", *INPUTS, "/tf")
        self.assertEqual(player.wait(timeout=STARTUP + RUN / RATE), 0)
        self.processes.pop("player")
        # The clock stops at the last input: the node's last tick is at most a tick and a step before it.
        self.wait(lambda: watcher.latest is not None and watcher.latest.header.stamp > last_input_time - rospy.Duration(0.1),
                  "replayed state up to the last input")

        # --- 3. the same instants hold the same numbers, in every body
        replayed = {key(state): values(state) for state in watcher.states}
        span = [stamp for stamp in recorded if stamp <= max(replayed)]  # the replay ends at the bag's last input
        common = sorted(set(span) & set(replayed))
        self.assertGreater(len(span), 0.5 * 60 * RUN)  # ~rate 60 Hz
        mismatches = [stamp for stamp in common if recorded[stamp] != replayed[stamp]]
        print(f"replay: {len(common)} common instants of {len(recorded)} recorded, {len(replayed)} replayed states; "
              f"{len(mismatches)} differ", flush=True)
        # Most instants are common: both publish after most steps (one tick in a loaded moment takes two).
        self.assertGreater(len(common), 0.5 * len(span), f"{len(span)} recorded, {len(replayed)} replayed states")
        if mismatches:
            first = mismatches[0]
            bodies = [name for name in recorded[first] if recorded[first][name] != replayed[first].get(name)]
            self.fail(f"{len(mismatches)} of {len(common)} states differ, the first at "
                      f"{first * 1e-9 - start_time.to_sec():.3f} s in {', '.join(bodies)}")


if __name__ == "__main__":
    rostest.rosrun("soft_body_sim", "replay", ReplayTest)

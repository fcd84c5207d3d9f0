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

Between 1 and 2, the recording as play.launch shows it: the bag holds no markers, is LZ4-compressed and
at most MAX_BYTES_PER_SECOND of simulated time; the state viewer, fed the bag's states, draws markers
equal to those the simulator published live at the same instants (to 1e-12 m: a collider's orientation
is made unit again).

Every step waits for what the next one needs (a topic subscribed, a state past an
instant) rather than for a fixed time, within STARTUP seconds: on a loaded machine roslaunch alone can
take several seconds."""
import glob
import math
import os
import shutil
import signal
import struct
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
from visualization_msgs.msg import MarkerArray

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
MARKERS = NODE + "/markers"
FORCE_MARKERS = NODE + "/force_markers"
VIEWED = "/viewer_test/markers"  # the state viewer's markers, apart from the simulator's
VIEWED_FORCES = "/viewer_test/force_markers"
MAX_BYTES_PER_SECOND = 1.5e6  # of the bag, per second of simulated time (issue 34)
STATE_RATE = 30.0  # [Hz] demo.launch's ~state_rate


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


class RawMarkers:
    """Keeps every MarkerArray of `topic` as sent, by the stamp of its first marker, to be read later
    (reading each as it comes would slow the test's process on a busy machine)."""

    def __init__(self, topic):
        self.by_stamp = {}
        self.subscriber = rospy.Subscriber(topic, rospy.AnyMsg, self._on_markers, queue_size=1000)

    def _on_markers(self, message):
        buffer = message._buff
        # uint32 marker count, then the first marker's header: uint32 seq, uint32 secs, uint32 nsecs
        if len(buffer) >= 16 and struct.unpack_from("<I", buffer, 0)[0] > 0:
            secs, nsecs = struct.unpack_from("<II", buffer, 8)
            self.by_stamp[secs * 10**9 + nsecs] = buffer

    def read(self, stamp):
        return MarkerArray().deserialize(self.by_stamp[stamp])

    def stop(self):
        self.subscriber.unregister()


def numbers(marker):
    """A marker's numbers in order: pose, scale, colour, then its points and their colours."""
    p, o = marker.pose.position, marker.pose.orientation
    values = [p.x, p.y, p.z, o.x, o.y, o.z, o.w, marker.scale.x, marker.scale.y, marker.scale.z,
              marker.color.r, marker.color.g, marker.color.b, marker.color.a]
    for point in marker.points:
        values += [point.x, point.y, point.z]
    for color in marker.colors:
        values += [color.r, color.g, color.b, color.a]
    return values


def drawn(markers):
    """Each marker by (namespace, id): its kind and frame, and its numbers."""
    return {(m.ns, m.id): ((m.type, m.action, m.header.frame_id, m.mesh_resource, len(m.points)), numbers(m))
            for m in markers.markers}


def arrows(markers):
    """The force arrows, each as its numbers, sorted: the simulator numbers them anchors first, then
    grasps, the viewer body by body."""
    return sorted(numbers(m) for m in markers.markers if m.type == m.ARROW and m.action == m.ADD)


def differences(live, viewed):
    """Where two marker arrays differ: markers on one side only, another kind, or a number off by 1e-12."""
    a, b = drawn(live), drawn(viewed)
    found = [f"{key} only live" for key in a.keys() - b.keys()] + [f"{key} only viewed" for key in b.keys() - a.keys()]
    for key in a.keys() & b.keys():
        if a[key][0] != b[key][0]:
            found.append(f"{key}: {a[key][0]} live, {b[key][0]} viewed")
        elif not all(math.isclose(x, y, rel_tol=0.0, abs_tol=1e-12) for x, y in zip(a[key][1], b[key][1])):
            found.append(f"{key}: numbers differ")
    return found


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
        live_markers = RawMarkers(MARKERS)
        live_forces = RawMarkers(FORCE_MARKERS)
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
        live_markers.stop()
        live_forces.stop()
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
        self.assertTrue(set(INPUTS) | {"/tf", STATE, START_TIME} <= topics, topics)
        # The bag holds every input from the first one the simulator heard (the test may have heard later).
        self.assertLessEqual(first_recorded[INPUTS[0]], first_input[0])
        self.assertGreater(inputs, 3 * 20 * RUN * 0.9)  # three streams at 20 Hz
        # An input played back after its stamp would reach the replaying node late, at another step.
        self.assertEqual(late, 0, f"{late} inputs reached the recorder after their stamp")

        self.check_recording(bags[0], live_markers, live_forces)

        # --- 2. replay the inputs into a fresh node under simulated time
        rospy.set_param("/use_sim_time", True)
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
        self.assertGreater(len(span), 0.5 * STATE_RATE * RUN)
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

    def check_recording(self, bag_path, live_markers, live_forces):
        """The bag's size and content, and its states drawn by the state viewer as they were live."""
        with rosbag.Bag(bag_path) as bag:
            info = bag.get_type_and_topic_info()
            span = bag.get_end_time() - bag.get_start_time()  # [s] of the recording's (simulated) clock
            states = [message for _, message, _ in bag.read_messages(topics=[STATE])]
        size = os.path.getsize(bag_path)
        print(f"recording: {size / 1e6:.2f} MB over {span:.2f} s of simulated time, {size / span / 1e6:.2f} MB/s; "
              f"{len(states)} states; topics {sorted(info.topics)}", flush=True)
        self.assertNotIn(MARKERS, info.topics)
        compression = subprocess.run(["rosbag", "info", "--yaml", "--key=compression", bag_path],
                                     capture_output=True, text=True)
        self.assertEqual(compression.stdout.strip(), "lz4", compression.stderr)
        self.assertLessEqual(size / span, MAX_BYTES_PER_SECOND)

        # The recorded states, played into the state viewer (no clock: it only draws).
        rospy.set_param("/use_sim_time", False)
        viewed, viewed_forces = RawMarkers(VIEWED), RawMarkers(VIEWED_FORCES)
        self.launch("viewer", "rosrun", "soft_body_sim", "state_viewer",
                    f"_scene:={os.path.join(os.path.dirname(BAG_START_TIME), '..', 'config', 'scenes', 'demo.yaml')}",
                    f"state:={STATE}", f"markers:={VIEWED}", f"force_markers:={VIEWED_FORCES}")
        self.wait(lambda: STATE in subscriptions("/soft_body_sim_viewer"), "the state viewer's subscription")
        player = self.launch("viewer_player", "rosbag", "play", "-q", "-r", "2", "--wait-for-subscribers", bag_path,
                             "--topics", STATE)
        self.assertEqual(player.wait(timeout=STARTUP + RUN), 0)
        self.processes.pop("viewer_player")
        last = max(key(state) for state in states)
        self.wait(lambda: last in viewed.by_stamp, "the state viewer's markers of the last state")
        self.finish("viewer")
        viewed.stop()
        viewed_forces.stop()
        common = sorted(set(viewed.by_stamp) & set(live_markers.by_stamp))
        print(f"viewer: {len(viewed.by_stamp)} marker arrays drawn from {len(states)} states, {len(common)} at "
              f"instants with live markers", flush=True)
        self.assertGreater(len(common), 0.5 * len(states))
        for stamp in common[::max(1, len(common) // 40)]:  # 40 of them, across the run
            found = differences(live_markers.read(stamp), viewed.read(stamp))
            self.assertFalse(found, f"at {stamp * 1e-9:.3f} s: {found[:5]}")
        common = sorted(set(viewed_forces.by_stamp) & set(live_forces.by_stamp))
        self.assertGreater(len(common), 0.5 * len(states))
        for stamp in common[::max(1, len(common) // 40)]:
            live, viewed_arrows = arrows(live_forces.read(stamp)), arrows(viewed_forces.read(stamp))
            self.assertGreater(len(live), 0)  # the demo's anchors
            self.assertEqual(len(live), len(viewed_arrows), f"at {stamp * 1e-9:.3f} s")
            for a, b in zip(live, viewed_arrows):
                self.assertTrue(all(math.isclose(x, y, rel_tol=0.0, abs_tol=1e-12) for x, y in zip(a, b)),
                                f"at {stamp * 1e-9:.3f} s: a force arrow differs")


if __name__ == "__main__":
    rostest.rosrun("soft_body_sim", "replay", ReplayTest)

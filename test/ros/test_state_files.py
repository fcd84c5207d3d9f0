#!/usr/bin/python3
"""~save_state and ~load_state the ROS way (launched by state_files.test on state_file_scene.yaml): the
states published after ~load_state are, at every simulated instant both have, those published after the
~save_state of that moment, bit for bit (every node's position and velocity); simulated time goes back to
the moment and ~start_time moves so that stamps go on from now; files that are missing, no snapshot, a
directory or unwritable are refused with their reason, and the node runs on unchanged."""
import os
import tempfile

import rospy
import rostest
from std_msgs.msg import Time

from node_client import NodeTestCase, StateWatcher, wait_for
from soft_body_sim.srv import StateFile

NODE = "/soft_body_sim"
WINDOW = 1.5  # [s] of simulated time compared after the moment


def simulated_time(state, start):
    """The state's simulated time [s] (its stamp is ~start_time + t), in steps of 1/60 s, as a whole step count."""
    return round((state.header.stamp - start).to_sec() * 60.0)


def nodes(state):
    """Every node's position and velocity, as exact floats."""
    return [(p.x, p.y, p.z, v.x, v.y, v.z) for b in state.bodies for p, v in zip(b.positions, b.velocities)]


class StateFilesTest(NodeTestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_state_files")
        cls.state = StateWatcher()
        cls.starts = []
        rospy.Subscriber(NODE + "/start_time", Time, lambda m: cls.starts.append(m.data), queue_size=10)
        rospy.wait_for_service(NODE + "/save_state", 20.0)
        cls.save = rospy.ServiceProxy(NODE + "/save_state", StateFile)
        cls.load = rospy.ServiceProxy(NODE + "/load_state", StateFile)
        cls.state.next(1, 20.0)
        cls.folder = tempfile.mkdtemp(prefix="soft_body_sim_state_")

    def record(self, start, after, until):
        """{step count: nodes} of the states from now on with after < step count <= until."""
        first = self.state.count()
        if not wait_for(lambda: self.state.latest is not None and simulated_time(self.state.latest, start) > until, 30.0):
            raise AssertionError("the simulation did not reach the end of the window")
        return {simulated_time(s, start): nodes(s) for s in self.state.states[first:]
                if after < simulated_time(s, start) <= until}

    def test_a_loaded_moment_goes_on_as_it_did_after_the_save(self):
        wait_for(lambda: len(self.starts) > 0, 10.0)
        start = self.starts[-1]
        wait_for(lambda: simulated_time(self.state.latest, start) >= 20, 10.0)
        path = os.path.join(self.folder, "moment.snapshot")
        saved = self.save(path)
        self.assertTrue(saved.success, saved.message)
        moment = round(saved.time * 60.0)
        after_save = self.record(start, moment, moment + round(WINDOW * 60))
        starts_before = len(self.starts)
        loaded = self.load(path)
        self.assertTrue(loaded.success, loaded.message)
        self.assertEqual(loaded.time, saved.time)
        self.assertTrue(wait_for(lambda: len(self.starts) > starts_before, 5.0), "~start_time did not move")
        new_start = self.starts[-1]
        self.assertGreater(new_start, start)  # the moment is now: stamps go on from the ROS time of the load
        after_load = self.record(new_start, moment, moment + round(WINDOW * 60))
        both = sorted(set(after_save) & set(after_load))
        # One step per tick: nearly every instant is in both (a late tick steps twice and publishes once).
        self.assertGreater(len(both), 0.5 * WINDOW * 60, f"instants after the save {sorted(after_save)}, after the load {sorted(after_load)}")
        for step in both:
            self.assertEqual(after_load[step], after_save[step], f"at step {step}")
        # The moment mattered: the rope moved over the window.
        self.assertNotEqual(after_save[both[0]], after_save[both[-1]])

    def test_bad_files_are_refused_and_the_node_runs_on(self):
        garbage = os.path.join(self.folder, "garbage.snapshot")
        with open(garbage, "wb") as f:
            f.write(b"this is no snapshot" * 10)
        for path, reason in [(os.path.join(self.folder, "missing.snapshot"), "No such file"),
                             (garbage, "not a soft_body_sim snapshot"),
                             (self.folder, "not a regular file")]:
            before = self.state.next(1)
            answer = self.load(path)
            self.assertFalse(answer.success, path)
            self.assertIn(reason, answer.message)
            after = self.state.next(2)
            self.assertGreater(after.header.stamp, before.header.stamp)  # still running, time never went back
        answer = self.save(os.path.join(self.folder, "no", "such", "folder", "x.snapshot"))
        self.assertFalse(answer.success)
        self.assertIn("cannot write", answer.message)


if __name__ == "__main__":
    rostest.rosrun("soft_body_sim", "state_files", StateFilesTest)

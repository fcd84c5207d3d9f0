#!/usr/bin/python3
"""Starting the simulator carelessly (launched by node_start.test, which starts only the master): a scene
that cannot load stops a launch of the nodelet as it stops the node; `rosrun` runs the node built into
build/ inside the package; a node parameter of the wrong type stops the node with one line naming it."""
import os
import signal
import subprocess
import unittest

import roslib.packages
import rostest

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "node_test_scene.yaml")
MISSING_SCENE = "/nonexistent/careless_scene.yaml"
TIMEOUT = 60.0  # [s] for a process that should stop by itself; it is killed after that


def run(command):
    """Runs `command` to its end, or kills its process group after TIMEOUT: (exit code or None, output)."""
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                               start_new_session=True)
    try:
        output, _ = process.communicate(timeout=TIMEOUT)
        return process.returncode, output
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGINT)
        try:
            output, _ = process.communicate(timeout=30.0)
        except subprocess.TimeoutExpired:
            os.killpg(process.pid, signal.SIGKILL)
            output, _ = process.communicate()
        return None, output


class NodeStartTest(unittest.TestCase):
    def test_a_scene_that_cannot_load_stops_the_nodelet_launch_naming_it(self):
        code, output = run(["roslaunch", os.path.join(HERE, "nodelet_manager.launch"), f"scene:={MISSING_SCENE}"])
        self.assertIsNotNone(code, f"still running after {TIMEOUT} s:\n{output[-3000:]}")
        self.assertIn("REQUIRED process [soft_body_sim-", output)  # the `nodelet load` of sim.launch
        self.assertIn(MISSING_SCENE, output)  # the manager's error line (roslaunch's summary shortens it)

    def test_rosrun_runs_the_node_built_inside_the_package(self):
        code, output = run(["rosrun", "soft_body_sim", "soft_body_sim_node", "__name:=rosrun_check",
                            f"_scene:={MISSING_SCENE}"])
        self.assertNotIn("[rosrun]", output)
        self.assertEqual(code, 1, output)
        self.assertIn(MISSING_SCENE, output)

    def test_a_node_parameter_of_a_wrong_type_stops_the_node_naming_it(self):
        node = roslib.packages.find_node("soft_body_sim", "soft_body_sim_node")[0]
        cases = [  # (parameter, value, what the node says)
            ("scene", "5", "scene: must be the path of a scene file, not 5"),
            ("rate", "abc", "rate: must be a finite number > 0 [Hz], not 'abc'"),
            ("status_period", "true", "status_period: must be a finite number >= 0 [s], not true"),
            ("status_period", "-1", "status_period: must be a finite number >= 0 [s], not -1"),
            ("force_scale", "abc", "force_scale: must be a finite number > 0 [m/N], not 'abc'"),
            ("start_time", "soon", "start_time: must be a ROS time in seconds (> 0), or 0, not 'soon'"),
            ("max_held_inputs", "many", "max_held_inputs: must be an integer >= 1, not 'many'"),
        ]
        for k, (parameter, value, message) in enumerate(cases):
            name = f"wrong_type_{k}"  # its own private namespace: no parameter left from the last
            scene = [] if parameter == "scene" else [f"_scene:={SCENE}"]
            code, output = run([node, f"__name:={name}", *scene, f"_{parameter}:={value}"])
            self.assertEqual(code, 1, f"_{parameter}:={value}: {output[-2000:]}")
            self.assertIn(f"/{name}/{message}", output)


if __name__ == "__main__":
    rostest.rosrun("soft_body_sim", "node_start", NodeStartTest)

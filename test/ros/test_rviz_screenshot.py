#!/usr/bin/python3
"""The demo in a real rviz under Xvfb (rviz_screenshot.test). Each body is drawn in its own colour,
a golden-angle hue per body index (bodyColor in src/ros/marker_conversion.cpp); the demo's bodies stand
left to right along x in the order of the scene file, seen from -y. The test takes a screenshot of
the virtual screen and checks that every body's colour is there, in enough pixels, in that order from
left to right. SOFT_BODY_SIM_SCREENSHOT=FILE keeps the screenshot (the README's docs/demo.png)."""
import colorsys
import os
import shutil
import signal
import subprocess
import tempfile
import time
import unittest

import rostest
from PIL import Image, ImageGrab

# The demo scene's bodies in file order (= body index = colour) and so from left to right.
BODIES = ["rope", "string", "jelly", "cloth", "codeling", "figure"]
HUE_TOLERANCE = 8.0   # [deg] lighting changes value and saturation of the flat colours, hardly the hue
MIN_PIXELS = 40       # a body covers at least this many pixels of its colour in the 1920 x 620 view


def body_hue(index):
    """The hue [deg] of bodyColor(index): golden-angle steps of 137.508 deg."""
    return (index * 137.508) % 360.0


def free_display():
    for number in range(99, 200):
        if not os.path.exists(f"/tmp/.X11-unix/X{number}") and not os.path.exists(f"/tmp/.X{number}-lock"):
            return f":{number}"
    raise RuntimeError("no free X display number")


BACKGROUND = (48, 48, 48)  # config/rviz/demo.rviz: Background Color


def colour_columns(image):
    """Per body, the x coordinates of the pixels of its colour inside the 3D view (the box around the
    background colour, so that rviz's coloured icons do not count)."""
    rgb = image.convert("RGB")
    mask = Image.new("L", rgb.size)
    mask.putdata([255 if p == BACKGROUND else 0 for p in rgb.getdata()])
    box = mask.getbbox()
    columns = {name: [] for name in BODIES}
    if box is None:
        return columns
    pixels = rgb.load()
    hues = [body_hue(k) for k in range(len(BODIES))]
    for y in range(box[1], box[3]):
        for x in range(box[0], box[2]):
            r, g, b = pixels[x, y]
            h, s, v = colorsys.rgb_to_hsv(r / 255.0, g / 255.0, b / 255.0)
            if s < 0.35 or v < 0.25:
                continue  # background, grid, handles: grey
            for name, hue in zip(BODIES, hues):
                if abs((h * 360.0 - hue + 180.0) % 360.0 - 180.0) <= HUE_TOLERANCE:
                    columns[name].append(x)
    return columns


def median(values):
    return sorted(values)[len(values) // 2]


class RvizScreenshotTest(unittest.TestCase):
    def setUp(self):
        self.processes = []
        self.folder = tempfile.mkdtemp(prefix="soft_body_sim_rviz_")

    def tearDown(self):
        for process in reversed(self.processes):
            if process.poll() is None:
                os.killpg(process.pid, signal.SIGINT)
                try:
                    process.wait(timeout=20)
                except subprocess.TimeoutExpired:
                    os.killpg(process.pid, signal.SIGKILL)
        shutil.rmtree(self.folder, ignore_errors=True)

    def start(self, command, env=None):
        log = open(os.path.join(self.folder, os.path.basename(command[0]) + ".log"), "w")
        process = subprocess.Popen(command, env=env, stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
        self.processes.append(process)
        return process

    def test_every_body_is_visible_in_its_colour_and_place(self):
        display = free_display()
        self.start(["Xvfb", display, "-screen", "0", "1920x620x24", "-nolisten", "tcp"])
        env = dict(os.environ, DISPLAY=display, LIBGL_ALWAYS_SOFTWARE="1")
        deadline = time.monotonic() + 20.0
        while not os.path.exists(f"/tmp/.X11-unix/X{display[1:]}") and time.monotonic() < deadline:
            time.sleep(0.1)
        # As shipped, with send_targets.py: the gripper's fingers appear once their tf frame does.
        demo = self.start(["roslaunch", "soft_body_sim", "demo.launch"], env=env)

        # rviz takes a while to start on software GL; look every few seconds until all bodies show.
        columns, image = {}, None
        deadline = time.monotonic() + 90.0
        while time.monotonic() < deadline:
            time.sleep(3.0)
            self.assertIsNone(demo.poll(), "the demo stopped")
            image = ImageGrab.grab(xdisplay=display)
            columns = colour_columns(image)
            if all(len(columns[name]) >= MIN_PIXELS for name in BODIES):
                break
        keep = os.environ.get("SOFT_BODY_SIM_SCREENSHOT")
        if keep and image is not None:
            image.save(keep)
        counts = {name: len(columns.get(name, [])) for name in BODIES}
        for name in BODIES:
            self.assertGreaterEqual(counts[name], MIN_PIXELS, f"{name} not visible: pixels per body {counts}")
        # Left to right as in the scene: x of the rope < string < jelly < cloth < codeling < figure.
        medians = [median(columns[name]) for name in BODIES]
        self.assertEqual(medians, sorted(medians), f"median columns {dict(zip(BODIES, medians))}")


if __name__ == "__main__":
    rostest.rosrun("soft_body_sim", "rviz_screenshot", RvizScreenshotTest)

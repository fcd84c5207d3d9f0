#!/usr/bin/python3
"""The node's simulated RGB-D camera (camera.test on camera_test_scene.yaml): a camera at (0, 0, 1) looking
along +x, 64 x 48 px over 60 degrees, at a wall whose face is 1.9 m away, with a red rope of radius 2 cm
across its view 1 m away. Every topic of a frame carries the same stamp; the CameraInfo is the pinhole
model; the wall's depth is 1.9 m at every pixel off the rope (z of a plane facing the camera); the rope
owns its rows with its own depth; the cloud is the depth back-projected; tf places the optical frame."""
import math
import struct
import threading

import rospy
import rostest
import tf2_ros
from sensor_msgs.msg import CameraInfo, Image, PointCloud2
from sensor_msgs import point_cloud2

from node_client import NodeTestCase, wait_for

NODE = "/soft_body_sim/camera"
WIDTH, HEIGHT = 64, 48
FX = 32.0 / math.tan(math.radians(30.0))
CX, CY = 31.5, 23.5
TOPICS = {
    "color": ("/color/image_raw", Image),
    "color_info": ("/color/camera_info", CameraInfo),
    "aligned": ("/aligned_depth_to_color/image_raw", Image),
    "aligned_info": ("/aligned_depth_to_color/camera_info", CameraInfo),
    "depth": ("/depth/image_rect", Image),
    "points": ("/depth/points", PointCloud2),
    "mask": ("/mask", Image),
}


class CameraTest(NodeTestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_camera")
        cls.lock = threading.Lock()
        cls.frames = {}  # stamp -> {kind: message}
        for kind, (topic, message_type) in TOPICS.items():
            rospy.Subscriber(NODE + topic, message_type, cls.keep(kind), queue_size=20)
        cls.tf = tf2_ros.Buffer()
        cls.listener = tf2_ros.TransformListener(cls.tf)

    @classmethod
    def keep(cls, kind):
        def keep_message(message):
            with cls.lock:
                cls.frames.setdefault(message.header.stamp.to_nsec(), {})[kind] = message
        return keep_message

    def complete_frames(self, count):
        def complete():
            with self.lock:
                return [f for _, f in sorted(self.frames.items()) if len(f) == len(TOPICS)]
        self.assertTrue(wait_for(lambda: len(complete()) >= count, 30.0), "frames: %d" % len(complete()))
        return complete()

    def test_every_topic_of_a_frame_has_its_stamp_and_the_frames_come_at_the_cameras_rate(self):
        frames = self.complete_frames(4)
        stamps = [f["color"].header.stamp.to_sec() for f in frames]
        gaps = [later - earlier for earlier, later in zip(stamps, stamps[1:])]
        for gap in gaps:  # frame n at n / rate of simulated time, 0.1 s apart (a busy frame may skip one)
            self.assertGreaterEqual(round(gap / 0.1), 1, gaps)
            self.assertAlmostEqual(gap, 0.1 * round(gap / 0.1), delta=1e-3, msg=gaps)
        self.assertIn(1, [round(gap / 0.1) for gap in gaps])
        for frame in frames:
            self.assertEqual({m.header.frame_id for m in frame.values()}, {"camera_color_optical_frame"})

    def test_the_camera_info_is_the_pinhole_model(self):
        frame = self.complete_frames(1)[0]
        for info in (frame["color_info"], frame["aligned_info"]):
            self.assertEqual((info.width, info.height), (WIDTH, HEIGHT))
            self.assertAlmostEqual(info.K[0], FX, places=9)
            self.assertAlmostEqual(info.K[4], FX, places=9)
            self.assertEqual((info.K[2], info.K[5]), (CX, CY))
            self.assertEqual(list(info.D), [0.0] * 5)

    def test_depth_colour_mask_and_cloud_show_the_wall_and_the_rope(self):
        frame = self.complete_frames(1)[0]
        depth = struct.unpack("<%df" % (WIDTH * HEIGHT), bytes(frame["depth"].data))
        aligned = struct.unpack("<%dH" % (WIDTH * HEIGHT), bytes(frame["aligned"].data))
        mask = struct.unpack("<%dH" % (WIDTH * HEIGHT), bytes(frame["mask"].data))
        color = bytes(frame["color"].data)
        self.assertEqual((frame["depth"].encoding, frame["aligned"].encoding, frame["mask"].encoding,
                          frame["color"].encoding), ("32FC1", "16UC1", "16UC1", "rgb8"))
        # The rope: 2 cm at 1 m is 1.1 px either side of its axis, which lies between rows 23 and 24.
        rope_rows = (23, 24)
        rope_span = int(FX * 0.4 / 1.0) - 2  # its ends, 0.4 m from the centre
        for v in range(HEIGHT):
            for u in range(WIDTH):
                k = v * WIDTH + u
                on_rope = v in rope_rows and abs(u - CX) < rope_span
                if on_rope:
                    self.assertEqual(mask[k], 1, (u, v))  # 1 + the rope's index
                    self.assertTrue(0.975 < depth[k] < 0.985, (u, v, depth[k]))  # its front, 0.98 m
                    self.assertGreater(color[3 * k], color[3 * k + 2])  # red
                elif v not in (21, 22, 23, 24, 25, 26):
                    self.assertEqual(mask[k], 1000, (u, v))  # the wall, collider 0
                    self.assertAlmostEqual(depth[k], 1.9, delta=1e-4)
                    self.assertEqual(aligned[k], 1900)
                    self.assertGreater(color[3 * k + 2], color[3 * k])  # blue
        points = list(point_cloud2.read_points(frame["points"], field_names=("x", "y", "z")))
        self.assertEqual((frame["points"].height, frame["points"].width), (HEIGHT, WIDTH))
        for v in range(0, HEIGHT, 7):
            for u in range(0, WIDTH, 5):
                x, y, z = points[v * WIDTH + u]
                d = depth[v * WIDTH + u]
                self.assertAlmostEqual(z, d, places=5)
                self.assertAlmostEqual(x, (u - CX) / FX * d, places=5)
                self.assertAlmostEqual(y, (v - CY) / FX * d, places=5)

    def test_tf_places_the_link_and_its_optical_frame(self):
        self.assertTrue(wait_for(lambda: self.tf.can_transform("world", "camera_color_optical_frame", rospy.Time(0)), 10.0))
        t = self.tf.lookup_transform("world", "camera_color_optical_frame", rospy.Time(0)).transform
        self.assertEqual((t.translation.x, t.translation.y, t.translation.z), (0.0, 0.0, 1.0))
        # The optical z (forward) is the world's x, its x (right) the world's -y, its y (down) the world's -z.
        q = (t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w)
        for axis, expected in (((0, 0, 1), (1, 0, 0)), ((1, 0, 0), (0, -1, 0)), ((0, 1, 0), (0, 0, -1))):
            for got, want in zip(rotate(q, axis), expected):
                self.assertAlmostEqual(got, want, places=9)


def rotate(q, v):
    """v turned by the unit quaternion q = (x, y, z, w): v + 2 w (u x v) + 2 u x (u x v), u = (x, y, z)."""
    u, w = q[:3], q[3]
    cross = lambda a, b: (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
    uv = cross(u, v)
    uuv = cross(u, uv)
    return tuple(v[i] + 2.0 * (w * uv[i] + uuv[i]) for i in range(3))


if __name__ == "__main__":
    rostest.rosrun("soft_body_sim", "camera", CameraTest)

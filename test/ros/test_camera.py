#!/usr/bin/python3
"""The node's simulated RGB-D camera (camera.test on camera_test_scene.yaml): a camera at (0, 0, 1) looking
along +x, 64 x 48 px over 60 degrees, at a wall whose face is 1.9 m away, with a red rope of radius 2 cm
across its view 1 m away. Every topic of a frame carries the same stamp; the CameraInfo is the pinhole
model; the wall's depth is 1.9 m at every pixel off the rope (z of a plane facing the camera); the rope
owns its rows with its own depth; the cloud is the depth back-projected; tf places the optical frame.
A second camera, 30 cm above the tf frame `wrist`, which this test moves to and fro along x (stamped ahead,
so that tf knows it at every instant): each of its frames sees the wall from the frame's pose at the frame's
stamp. depth_image_proc's point_cloud_xyzrgb nodelet, fed with that camera's colour image, registered
depth (16UC1) and CameraInfo through an exact-time synchroniser, makes from every frame the cloud we
publish, within 1 mm (the millimetres' rounding)."""
import math
import struct
import threading

import rospy
import rostest
import tf2_ros
from sensor_msgs.msg import CameraInfo, Image, PointCloud2
from sensor_msgs import point_cloud2

from node_client import FrameBroadcaster, NodeTestCase, wait_for

NODE = "/soft_body_sim/camera"
WRIST = "/soft_body_sim/wrist"
CONSUMER = "/point_cloud_xyzrgb/points"  # depth_image_proc's cloud of the wrist camera (camera.test)
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
        # The wrist frame: 1 m up, to and fro along x between 0.1 and 0.5 m, a period of 12.6 s.
        cls.start = rospy.Time.now().to_sec()
        cls.wrist = FrameBroadcaster(period=0.01, lead=0.2)
        cls.wrist.set("wrist", lambda t: ((cls.wrist_x(t), 0.0, 1.0), (0.0, 0.0, 0.0, 1.0)))
        cls.wrist_depths = {}  # stamp -> Image (32FC1)
        cls.clouds = {"ours": {}, "consumer": {}}  # stamp -> PointCloud2
        rospy.Subscriber(WRIST + "/depth/image_rect", Image, cls.keep_in(cls.wrist_depths), queue_size=20)
        rospy.Subscriber(WRIST + "/depth/points", PointCloud2, cls.keep_in(cls.clouds["ours"]), queue_size=20)
        rospy.Subscriber(CONSUMER, PointCloud2, cls.keep_in(cls.clouds["consumer"]), queue_size=20)

    @classmethod
    def wrist_x(cls, t):
        return 0.3 + 0.2 * math.sin(0.5 * (t - cls.start))

    @classmethod
    def keep_in(cls, messages):
        def keep_message(message):
            with cls.lock:
                messages[message.header.stamp.to_nsec()] = message
        return keep_message

    def count(self, messages):
        with self.lock:
            return len(messages)

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

    def test_a_camera_on_a_moving_frame_sees_from_the_frames_pose_at_each_frames_stamp(self):
        # The wall's face is 1.9 m along x; the camera looks along x from x(stamp): every pixel of its upper
        # rows (the wall, above the rope's 30 cm lower line of sight) has depth 1.9 - x(stamp).
        self.assertTrue(wait_for(lambda: self.count(self.wrist_depths) >= 25, 30.0))
        with self.lock:
            frames = sorted(self.wrist_depths.items())
        expected = [1.9 - self.wrist_x(stamp * 1e-9) for stamp, _ in frames]
        self.assertGreater(max(expected) - min(expected), 0.1)  # it moved between the frames
        for (stamp, image), want in zip(frames, expected):
            depth = struct.unpack("<%df" % (WIDTH * HEIGHT), bytes(image.data))
            self.assertEqual(image.header.frame_id, "wrist_color_optical_frame")
            for k in range(12 * WIDTH):  # rows 0 to 11
                self.assertAlmostEqual(depth[k], want, delta=1e-4, msg=(stamp, k))

    def test_depth_image_procs_cloud_of_each_frame_equals_ours(self):
        # From the first cloud both we and the consumer have (it subscribes to the camera when we subscribe to
        # it), the consumer's clouds have our clouds' stamps, every one: its exact-time synchroniser matched
        # each frame's colour, depth and CameraInfo.
        self.assertTrue(wait_for(lambda: self.count(self.clouds["consumer"]) >= 1, 30.0), "no consumer cloud")
        self.assertTrue(wait_for(lambda: self.count(self.clouds["ours"]) >= 1, 30.0), "no cloud")
        with self.lock:
            first = max(min(self.clouds["consumer"]), min(self.clouds["ours"]))
        self.assertTrue(wait_for(lambda: len([s for s in self.clouds["ours"] if s >= first]) >= 20, 30.0))
        with self.lock:
            ours = {s: c for s, c in self.clouds["ours"].items() if s >= first}
        last = max(ours)
        self.assertTrue(wait_for(lambda: last in self.clouds["consumer"], 5.0), "the last frame's cloud")
        with self.lock:
            consumer = dict(self.clouds["consumer"])
        self.assertEqual(sorted(ours), sorted(s for s in consumer if first <= s <= last))
        fields = ("x", "y", "z", "rgb")
        for stamp in sorted(ours):
            theirs = consumer[stamp]
            self.assertEqual((theirs.height, theirs.width), (HEIGHT, WIDTH))
            self.assertEqual(theirs.header.frame_id, "wrist_color_optical_frame")
            mine = list(point_cloud2.read_points(ours[stamp], field_names=fields))
            for k, point in enumerate(point_cloud2.read_points(theirs, field_names=fields)):
                for axis in range(3):
                    a, b = mine[k][axis], point[axis]
                    if math.isnan(a) or math.isnan(b):
                        self.assertTrue(math.isnan(a) and math.isnan(b), (stamp, k, axis, a, b))
                    else:
                        self.assertAlmostEqual(a, b, delta=1e-3, msg=(stamp, k, axis))
                self.assertEqual(struct.pack("<f", mine[k][3])[:3], struct.pack("<f", point[3])[:3], (stamp, k))


def rotate(q, v):
    """v turned by the unit quaternion q = (x, y, z, w): v + 2 w (u x v) + 2 u x (u x v), u = (x, y, z)."""
    u, w = q[:3], q[3]
    cross = lambda a, b: (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
    uv = cross(u, v)
    uuv = cross(u, uv)
    return tuple(v[i] + 2.0 * (w * uv[i] + uuv[i]) for i in range(3))


if __name__ == "__main__":
    rostest.rosrun("soft_body_sim", "camera", CameraTest)

#!/usr/bin/python3
"""Example client of soft_body_sim: drives a creature's target along a figure eight, an anchor around
a circle and a gripper's tf frame up and down, stamping each pose with the ROS time it is meant for, as
a planner would.

  rosrun soft_body_sim send_targets.py                 # the demo's codeling and the rope's right end
  rosrun soft_body_sim send_targets.py _target_topic:=/soft_body_sim/figure/target _anchor_topic:=''

Parameters (private, all optional):
  ~target_topic   PoseStamped topic of a target (default /soft_body_sim/codeling/target; '' = none)
  ~target_center  [m] centre of the figure eight [x, y, z] (default [3.6, 0.0, 1.2])
  ~target_size    [m] half width along x; half that along y (default 0.5)
  ~target_period  [s] one figure eight (default 12)
  ~anchor_topic   PoseStamped topic of an anchor (default /soft_body_sim/rope/right/pose; '' = none)
  ~anchor_center  [m] centre of the circle, in the x-z plane (default [-6.75, 0.0, 1.5])
  ~anchor_radius  [m] (default 0.25)
  ~anchor_period  [s] one turn (default 4)
  ~gripper_frame  tf frame broadcast as a child of ~frame_id, moving up and down (default gripper;
                  '' = none): the demo's two fingers follow it
  ~gripper_center [m] centre of its motion (default [-7.25, 0.0, 1.25])
  ~gripper_height [m] it rises this far above the centre and as far below (default 0.35)
  ~gripper_period [s] one up and down (default 6)
  ~gripper_phase  [s] it moves as if started this far into its period (default 0: at its lowest point;
                  half the period starts it at its highest, as launch/soft_box.launch's press does)
  ~frame_id       frame of every path (default world)
  ~rate           [Hz] poses per second on each topic (default 20)
  ~lead           [s] each pose is stamped this far ahead of now, so that it reaches the simulator
                  before its step and a replay of the recording is exact (default 0.1)
  ~wait_for       node names (e.g. [/soft_body_sim, /record_soft_body_sim]) that must be connected to
                  every topic above before the first pose goes out (default []): what a recorder
                  missed while it subscribed would be missing from its bag, and a replay would differ
"""
import math

import rospy
import tf2_ros
from geometry_msgs.msg import PoseStamped, TransformStamped


def pose(frame_id, stamp, x, y, z):
    message = PoseStamped()
    message.header.frame_id = frame_id
    message.header.stamp = stamp
    message.pose.position.x, message.pose.position.y, message.pose.position.z = x, y, z
    message.pose.orientation.w = 1.0
    return message


def figure_eight(center, size, period, t):
    """A Lissajous figure eight: x = a sin(w t), y = a/2 sin(2 w t) about the centre."""
    w = 2.0 * math.pi / period
    return center[0] + size * math.sin(w * t), center[1] + 0.5 * size * math.sin(2.0 * w * t), center[2]


def circle(center, radius, period, t):
    """A circle in the x-z plane (the demo is seen from -y), starting at its rightmost point."""
    w = 2.0 * math.pi / period
    return center[0] + radius * math.cos(w * t), center[1], center[2] + radius * math.sin(w * t)


def up_and_down(center, height, period, t):
    """A vertical oscillation about the centre, starting at its lowest point."""
    w = 2.0 * math.pi / period
    return center[0], center[1], center[2] - height * math.cos(w * t)


def transform(frame_id, child, stamp, x, y, z):
    message = TransformStamped()
    message.header.frame_id = frame_id
    message.header.stamp = stamp
    message.child_frame_id = child
    message.transform.translation.x, message.transform.translation.y, message.transform.translation.z = x, y, z
    message.transform.rotation.w = 1.0
    return message


def wait_for_connections(publishers, nodes):
    """Returns once each of `nodes` (names) is connected to each of `publishers`; says whom it waits for."""
    def missing():
        return sorted({node for node in nodes for p in publishers if not p.impl.has_connection(node)})
    if missing():
        rospy.loginfo("send_targets: waiting for %s to subscribe", ", ".join(missing()))
    while missing() and not rospy.is_shutdown():
        rospy.sleep(0.01)


def main():
    rospy.init_node("send_targets")
    frame_id = rospy.get_param("~frame_id", "world")
    rate = rospy.get_param("~rate", 20.0)
    lead = rospy.Duration(rospy.get_param("~lead", 0.1))
    target_topic = rospy.get_param("~target_topic", "/soft_body_sim/codeling/target")
    target_center = rospy.get_param("~target_center", [3.6, 0.0, 1.2])
    target_size = rospy.get_param("~target_size", 0.5)
    target_period = rospy.get_param("~target_period", 12.0)
    anchor_topic = rospy.get_param("~anchor_topic", "/soft_body_sim/rope/right/pose")
    anchor_center = rospy.get_param("~anchor_center", [-6.75, 0.0, 1.5])
    anchor_radius = rospy.get_param("~anchor_radius", 0.25)
    anchor_period = rospy.get_param("~anchor_period", 4.0)
    gripper_frame = rospy.get_param("~gripper_frame", "gripper")
    gripper_center = rospy.get_param("~gripper_center", [-7.25, 0.0, 1.25])
    gripper_height = rospy.get_param("~gripper_height", 0.35)
    gripper_period = rospy.get_param("~gripper_period", 6.0)
    gripper_phase = rospy.get_param("~gripper_phase", 0.0)

    target_pub = rospy.Publisher(target_topic, PoseStamped, queue_size=10) if target_topic else None
    anchor_pub = rospy.Publisher(anchor_topic, PoseStamped, queue_size=10) if anchor_topic else None
    broadcaster = tf2_ros.TransformBroadcaster() if gripper_frame else None
    while rospy.Time.now().is_zero() and not rospy.is_shutdown():  # /use_sim_time: wait for /clock
        rospy.sleep(0.01)
    publishers = [p for p in (target_pub, anchor_pub, broadcaster.pub_tf if broadcaster else None) if p]
    wait_for_connections(publishers, rospy.get_param("~wait_for", []))
    start = rospy.Time.now()
    ticker = rospy.Rate(rate)
    while not rospy.is_shutdown():
        stamp = rospy.Time.now() + lead
        t = (stamp - start).to_sec()
        if target_pub:
            target_pub.publish(pose(frame_id, stamp, *figure_eight(target_center, target_size, target_period, t)))
        if anchor_pub:
            anchor_pub.publish(pose(frame_id, stamp, *circle(anchor_center, anchor_radius, anchor_period, t)))
        if broadcaster:
            broadcaster.sendTransform(transform(frame_id, gripper_frame, stamp,
                                                *up_and_down(gripper_center, gripper_height, gripper_period,
                                                            t + gripper_phase)))
        try:
            ticker.sleep()
        except rospy.ROSInterruptException:
            break


if __name__ == "__main__":
    main()

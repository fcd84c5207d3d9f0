#!/usr/bin/python3
"""Example client of soft_body_sim: drives a creature's target along a figure eight and an anchor
around a circle, stamping each pose with the ROS time it is meant for, as a planner would.

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
  ~frame_id       frame of both paths (default world)
  ~rate           [Hz] poses per second on each topic (default 20)
  ~lead           [s] each pose is stamped this far ahead of now, so that it reaches the simulator
                  before its step and a replay of the recording is exact (default 0.1)
"""
import math

import rospy
from geometry_msgs.msg import PoseStamped


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

    target_pub = rospy.Publisher(target_topic, PoseStamped, queue_size=10) if target_topic else None
    anchor_pub = rospy.Publisher(anchor_topic, PoseStamped, queue_size=10) if anchor_topic else None
    while rospy.Time.now().is_zero() and not rospy.is_shutdown():  # /use_sim_time: wait for /clock
        rospy.sleep(0.01)
    start = rospy.Time.now()
    ticker = rospy.Rate(rate)
    while not rospy.is_shutdown():
        stamp = rospy.Time.now() + lead
        t = (stamp - start).to_sec()
        if target_pub:
            target_pub.publish(pose(frame_id, stamp, *figure_eight(target_center, target_size, target_period, t)))
        if anchor_pub:
            anchor_pub.publish(pose(frame_id, stamp, *circle(anchor_center, anchor_radius, anchor_period, t)))
        try:
            ticker.sleep()
        except rospy.ROSInterruptException:
            break


if __name__ == "__main__":
    main()

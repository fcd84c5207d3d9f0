#!/usr/bin/python3
"""Example client of soft_body_sim: a gripper (a tf frame that this client broadcasts) closes on a body
with ~grasp, lifts and turns the grasped part, prints the force that the body exerts on it once a
second (from ~<body>/<frame>/wrench), and lets go with ~release.

  rosrun soft_body_sim grasp_example.py          # on the demo: lifts the string's free end

It exits 1 when the simulator has no such body or refuses the grasp.

Parameters (private, all optional):
  ~simulator  namespace of the simulator's topics and services (default /soft_body_sim)
  ~frame      tf frame of the gripper, a child of ~frame_id; it names the grasp (default hand)
  ~frame_id   the simulation's fixed frame (default world)
  ~body       body to grasp (default string)
  ~node       the gripper starts at this node of the body, as ~state has it (default 0)
  ~radius     [m] the grasp holds every free node this close to the gripper (default 0.1)
  ~max_force  [N] above it the grasp slips; 0 = no limit (default 0)
  ~lift       [m] the gripper moves by this much [x, y, z] while turning a quarter turn about y
              (default [0.5, 0.0, 1.0])
  ~duration   [s] the motion takes this long (default 5)
  ~hold       [s] then it holds still this long before it lets go (default 3)
  ~rate       [Hz] tf broadcasts per second (default 50)
"""
import math
import sys

import rospy
import tf2_ros
from geometry_msgs.msg import TransformStamped, WrenchStamped

from soft_body_sim.msg import SimState
from soft_body_sim.srv import Detach, Grasp


def gripper_transform(frame_id, child, stamp, position, angle):
    """The gripper at `position`, turned by `angle` [rad] about y."""
    message = TransformStamped()
    message.header.frame_id = frame_id
    message.header.stamp = stamp
    message.child_frame_id = child
    t = message.transform
    t.translation.x, t.translation.y, t.translation.z = position
    t.rotation.y, t.rotation.w = math.sin(angle / 2.0), math.cos(angle / 2.0)
    return message


def main():
    rospy.init_node("grasp_example")
    simulator = rospy.get_param("~simulator", "/soft_body_sim")
    frame = rospy.get_param("~frame", "hand")
    frame_id = rospy.get_param("~frame_id", "world")
    body = rospy.get_param("~body", "string")
    node = rospy.get_param("~node", 0)
    radius = rospy.get_param("~radius", 0.1)
    max_force = rospy.get_param("~max_force", 0.0)
    lift = rospy.get_param("~lift", [0.5, 0.0, 1.0])
    duration = rospy.get_param("~duration", 5.0)
    hold = rospy.get_param("~hold", 3.0)
    rate = rospy.get_param("~rate", 50.0)

    rospy.wait_for_service(simulator + "/grasp", 30.0)
    grasp = rospy.ServiceProxy(simulator + "/grasp", Grasp)
    release = rospy.ServiceProxy(simulator + "/release", Detach)
    latest_state = []

    def on_state(message):
        latest_state[:] = [message]

    rospy.Subscriber(simulator + "/state", SimState, on_state, queue_size=1)
    ticker = rospy.Rate(rate)
    while not latest_state and not rospy.is_shutdown():
        ticker.sleep()
    bodies = {b.name: b for b in latest_state[0].bodies}
    if body not in bodies:
        rospy.logfatal("grasp_example: the simulator has no body '%s' (it has %s)", body, ", ".join(bodies))
        return 1

    def node_position():
        p = next(b for b in latest_state[0].bodies if b.name == body).positions[node]
        return (p.x, p.y, p.z)

    broadcaster = tf2_ros.TransformBroadcaster()
    # The gripper follows the node for half a second (the simulator looks the frame up when it grasps),
    # then closes on it; a body still swinging may have moved out of reach in between: try again.
    response = None
    start_position = None  # where the gripper closed
    for _attempt in range(10):
        for _ in range(int(rate / 2)):
            start_position = node_position()
            broadcaster.sendTransform(gripper_transform(frame_id, frame, rospy.Time.now(), start_position, 0.0))
            ticker.sleep()
        response = grasp(frame=frame, body=body, radius=radius, max_force=max_force)
        if response.success or "no free node" not in response.message:
            break
    if not response.success:
        rospy.logfatal("grasp_example: grasp refused: %s", response.message)
        return 1
    start = rospy.Time.now()

    def broadcast(stamp):
        s = min(1.0, max(0.0, (stamp - start).to_sec() / duration))
        position = tuple(a + s * d for a, d in zip(start_position, lift))
        broadcaster.sendTransform(gripper_transform(frame_id, frame, stamp, position, s * math.pi / 2.0))

    rospy.loginfo("grasp_example: %s (nodes %s)", response.message, list(response.nodes))
    latest = []  # the last wrench message

    def on_wrench(message):
        latest[:] = [message]

    rospy.Subscriber(f"{simulator}/{body}/{frame}/wrench", WrenchStamped, on_wrench)
    last_print = start
    end = start + rospy.Duration(duration + hold)
    while not rospy.is_shutdown() and rospy.Time.now() < end:
        now = rospy.Time.now()
        broadcast(now)
        if latest and (now - last_print).to_sec() >= 1.0:
            last_print = now
            f = latest[0].wrench.force
            rospy.loginfo("grasp_example: t = %.1f s: the %s pulls '%s' with (%.3f, %.3f, %.3f) N, |F| = %.3f N",
                          (now - start).to_sec(), body, frame, f.x, f.y, f.z, math.sqrt(f.x ** 2 + f.y ** 2 + f.z ** 2))
        ticker.sleep()
    rospy.loginfo("grasp_example: %s", release(frame=frame).message)
    return 0


if __name__ == "__main__":
    sys.exit(main())

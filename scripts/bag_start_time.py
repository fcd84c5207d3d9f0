#!/usr/bin/python3
"""Prints the ~start_time to replay a bag recorded with record.launch: the ROS time of simulated time 0,
in seconds to the millisecond, as sim.launch's start_time:= takes it (docs/node.md, "Record and replay").

  rosrun soft_body_sim bag_start_time.py /tmp/run_2026-11-26-19-00-00.bag [--node /soft_body_sim]

The simulator publishes a new start time whenever it pauses, resets or falls behind real time. Moves
before the first input (a pose, a target or a tf transform) change nothing a replay reproduces, so the last start time is the one to give;
a move after the first input makes the bag not replayable exactly: the script then says when and exits 1.
"""
import argparse
import sys

import rosbag


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("bag")
    parser.add_argument("--node", default="/soft_body_sim", help="the simulator's name (default /soft_body_sim)")
    args = parser.parse_args()
    node = args.node.rstrip("/")
    start_times, first_input = [], None
    with rosbag.Bag(args.bag) as bag:
        for topic, message, received in bag.read_messages():
            if topic == node + "/start_time":
                start_times.append((received, message.data))
            elif first_input is None and (topic == "/tf" or topic.startswith(node + "/") and
                                          topic.endswith(("/pose", "/target"))):
                first_input = received  # a pose, a target or a transform that an anchor or collider may follow
    if not start_times:
        sys.exit(f"{args.bag}: no {node}/start_time in the bag (record with record.launch, ns as the simulator's)")
    moved = [received for received, _ in start_times[1:] if first_input is not None and received >= first_input]
    if moved:
        sys.exit(f"{args.bag}: {node}'s start time moved {len(moved)} times after the first input (first at "
                 f"{moved[0].to_sec():.3f}: it paused, reset or fell behind real time); no replay reproduces it")
    start_time = start_times[-1][1]
    print("%d.%03d" % (start_time.secs, start_time.nsecs // 1000000))


if __name__ == "__main__":
    main()

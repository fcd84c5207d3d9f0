"""sim.rollouts equals the same goals stepped one rollout at a time through the World API, to the bit, for any
number of threads, and leaves its world as it was. The loop below is the documented interpolation (docs/python.md):
within a goal's steps the holder goes from the previous goal (at first, from where it is) to this one in equal
parts, position (1 - f) a + f b, orientation normalized linear interpolation the shorter way."""
import math

import numpy as np
import pytest

from conftest import SCENES, same_bits
from soft_body_sim import sim


def normalized(q):
    x, y, z, w = (float(v) for v in q)
    norm = math.sqrt(x * x + y * y + z * z + w * w)
    return np.array([x / norm, y / norm, z / norm, w / norm])


def between(a, b, f):
    """The pose f of the way from pose a to pose b (7 numbers each)."""
    g = 1.0 - f
    dot = a[3] * b[3] + a[4] * b[4] + a[5] * b[5] + a[6] * b[6]
    s = -f if dot < 0.0 else f
    return np.concatenate([g * a[:3] + f * b[:3], normalized(g * a[3:] + s * b[3:])])


def move(w, holder, pose, turn):
    if "/" in holder:
        body, anchor = holder.split("/")
        w.move_anchor(body, anchor, pose[:3], orientation=pose[3:] if turn else None)
    else:
        w.move_grasp(holder, pose[:3], pose[3:])


def one_at_a_time(w, holder, goals, steps_per_goal):
    start = w.pose(holder)
    turn = goals.shape[2] == 7
    out = np.empty((goals.shape[0], goals.shape[1]) + w.positions().shape)
    for b in range(goals.shape[0]):
        c = w.clone()
        previous = start
        for t in range(goals.shape[1]):
            goal = np.concatenate([goals[b, t, :3], normalized(goals[b, t, 3:]) if turn else start[3:]])
            for step in range(1, steps_per_goal + 1):
                pose = between(previous, goal, step / steps_per_goal)
                move(c, holder, pose if turn else np.concatenate([pose[:3], start[3:]]), turn)
                c.step(1)
            out[b, t] = c.positions()
            previous = goal
    return out


def random_walks(rng, start, rollouts, count, scale):
    return start + np.cumsum(rng.normal(scale=scale, size=(rollouts, count, 3)), axis=1)


def turning_poses(rng, start, rollouts, count):
    """Positions near `start` and orientations turning about x by up to about 0.4 rad a goal, of norm 3."""
    angles = np.cumsum(rng.uniform(-0.4, 0.4, size=(rollouts, count)), axis=1)
    quaternions = 3.0 * np.stack([np.sin(angles / 2), 0 * angles, 0 * angles, np.cos(angles / 2)], axis=2)
    return np.concatenate([random_walks(rng, start[:3], rollouts, count, 0.005), quaternions], axis=2)


def check(w, holder, goals, steps_per_goal):
    before = w.clone()
    expected = one_at_a_time(w, holder, goals, steps_per_goal)
    for threads in (1, 2, 0, 8):
        got = sim.rollouts(w, holder=holder, goals=goals, steps_per_goal=steps_per_goal, threads=threads)
        assert same_bits(got, expected), f"threads={threads}"
    # w as it was: it steps on as the clone taken before does.
    assert w.step_count == before.step_count
    w.step(5)
    before.step(5)
    assert same_bits(w.positions(), before.positions()) and same_bits(w.velocities(), before.velocities())


def test_anchor_positions():
    w = sim.World(str(SCENES / "rope.yaml"))
    w.step(20)
    check(w, "rope/right", random_walks(np.random.default_rng(1), w.pose("rope/right")[:3], 5, 4, 0.01), 3)


def test_anchor_poses_turn_a_rod():
    w = sim.World(str(SCENES / "cable.yaml"))  # implicit Euler; the rod's anchored tip holds its orientation
    w.step(5)
    goals = turning_poses(np.random.default_rng(2), w.pose("cable/tip"), 3, 3)
    check(w, "cable/tip", goals, 4)
    # The rollouts turned the tip: its rod's nodes went elsewhere than those of rollouts with positions only.
    moved = sim.rollouts(w, holder="cable/tip", goals=goals[:, :, :3], steps_per_goal=4)
    turned = sim.rollouts(w, holder="cable/tip", goals=goals, steps_per_goal=4)
    assert not np.array_equal(moved, turned)


@pytest.mark.parametrize("width", [3, 7])
def test_grasp_frames(width):
    w = sim.World(str(SCENES / "rope.yaml"))
    w.grasp("hand", "rope", w.positions("rope")[8], radius=0.03, orientation=[0.0, 0.0, 0.2, 1.0])
    w.step(3)
    goals = turning_poses(np.random.default_rng(3), w.pose("hand"), 4, 3)[:, :, :width]
    check(w, "hand", goals, 2)


def test_one_step_per_goal_lands_on_each_goal():
    w = sim.World(str(SCENES / "rope.yaml"))
    goals = random_walks(np.random.default_rng(4), w.pose("rope/right")[:3], 2, 5, 0.02)
    check(w, "rope/right", goals, 1)
    X = sim.rollouts(w, holder="rope/right", goals=goals)
    assert same_bits(X[:, :, w.node_slice("rope").stop - 1], goals)  # an anchor lands exactly on its goal


def test_empty_batches():
    w = sim.World(str(SCENES / "rope.yaml"))
    assert sim.rollouts(w, holder="rope/left", goals=np.zeros((0, 3, 3))).shape == (0, 3, 21, 3)
    assert sim.rollouts(w, holder="rope/left", goals=np.zeros((2, 0, 3))).shape == (2, 0, 21, 3)

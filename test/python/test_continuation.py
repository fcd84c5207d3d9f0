"""A clone, and a world restored to a snapshot (its own or another world's of the same scene, or one that went
through bytes or pickle), given the same inputs, step on to the same bits as the world that went on
uninterrupted."""
import copy
import math
import pickle

import numpy as np

from conftest import SCENES, same_bits
from soft_body_sim import sim

STEPS = 40


def drive(w, steps):
    """Steps `w` with inputs of every kind: an anchor on a circle, a grasp carried along a line, the gripper's
    fingers moved up through the rope, the creature sent off; returns every node's positions and velocities."""
    right = w.pose("rope/right")[:3]
    cloth = w.positions("cloth")[-1]
    w.grasp("hand", "cloth", cloth, radius=0.05)
    for n in range(steps):
        angle = 0.2 * n
        w.move_anchor("rope", "right", right + 0.05 * np.array([math.cos(angle) - 1.0, 0.0, math.sin(angle)]))
        w.move_grasp("hand", cloth + [0.0, 0.005 * n, 0.01 * n], [0.0, 0.0, math.sin(0.01 * n), math.cos(0.01 * n)])
        for finger, dz in (("lower_finger", -0.05), ("upper_finger", 0.05)):
            w.move_collider(finger, [-7.0, 0.0, 1.2 + dz + 0.01 * n], [0, 0.7071067811865476, 0, 0.7071067811865476])
        if n == 10:
            w.set_target("codeling", [1.0, 0.5, 0.5])
        w.step(1)
    return w.positions(), w.velocities(), w.time


def test_clone_and_restored_snapshots_continue_to_the_same_bits():
    w = sim.World(str(SCENES / "demo.yaml"))  # xpbd, every body type, a table and the gripper's fingers
    w.step(30)
    clone = w.clone()
    moment = w.snapshot()
    other = sim.World(str(SCENES / "demo.yaml"))
    other.step(7)  # elsewhere in its own run: restore replaces all of it

    pickled = pickle.dumps(w)  # its scene file's path and the moment's bytes
    copied = copy.deepcopy(w)
    data = moment.to_bytes()

    expected = drive(w, STEPS)
    assert moment.time == 30 * w.dt and moment.step_count == 30
    other.restore(moment)
    from_bytes = sim.World(SCENES / "demo.yaml")
    from_bytes.restore(sim.Snapshot.from_bytes(bytearray(data)))
    from_pickle = sim.World(SCENES / "demo.yaml")
    from_pickle.restore(pickle.loads(pickle.dumps(moment)))
    w.restore(moment)
    for continued in (clone, copied, other, from_bytes, from_pickle, pickle.loads(pickled), w):
        got = drive(continued, STEPS)
        assert all(same_bits(a, b) for a, b in zip(got[:2], expected[:2])) and got[2] == expected[2]


def test_a_clone_is_independent_of_its_original():
    w = sim.World(str(SCENES / "rope.yaml"))
    clone = w.clone()
    w.move_anchor("rope", "right", [0.3, 0.0, 1.2])
    w.step(10)
    assert w.step_count == 10 and clone.step_count == 0
    assert same_bits(clone.positions(), sim.World(str(SCENES / "rope.yaml")).positions())

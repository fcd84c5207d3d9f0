"""Bad input is a Python exception that says what is wrong, never a crash: an unknown name a KeyError naming
the known ones, a malformed or non-finite array a ValueError, a scene the loader refuses sim.SceneError (a
ValueError) with the loader's line, another scene's snapshot a ValueError naming both scenes."""
import pickle

import numpy as np
import pytest

from conftest import SCENES
from soft_body_sim import sim


@pytest.fixture
def rope():
    return sim.World(str(SCENES / "rope.yaml"))


def test_scenes_the_loader_refuses(tmp_path):
    with pytest.raises(sim.SceneError, match="nowhere.yaml"):
        sim.World(str(tmp_path / "nowhere.yaml"))
    bad = tmp_path / "bad.yaml"
    bad.write_text("bodies:\n  - {name: r, type: rope, nodes: 1, from: [0, 0, 0], to: [1, 0, 0], mass: 1, stiffness: 1}\n")
    with pytest.raises(sim.SceneError, match=r"bad.yaml:2: bodies\[0\]\.nodes"):
        sim.World(bad)  # a pathlib.Path does too
    assert issubclass(sim.SceneError, ValueError)


@pytest.mark.parametrize("call", [
    lambda w: w.positions("nope"),
    lambda w: w.velocities("nope"),
    lambda w: w.anchors("nope"),
    lambda w: w.node_slice("nope"),
    lambda w: w.tensions("nope"),
    lambda w: w.set_target("nope", [0, 0, 0]),
    lambda w: w.grasp("hand", "nope", [0, 0, 1.5], radius=0.1),
    lambda w: w.move_anchor("nope", "left", [0, 0, 0]),
])
def test_unknown_bodies_are_key_errors_naming_the_bodies(rope, call):
    with pytest.raises(KeyError, match="unknown body 'nope'; the scene's bodies: 'rope'"):
        call(rope)


def test_unknown_anchors_grasps_and_colliders_are_key_errors_naming_the_known(rope):
    for call in (lambda: rope.move_anchor("rope", "end", [0, 0, 1]), lambda: rope.wrench("rope", "end")):
        with pytest.raises(KeyError, match="body 'rope' has no anchor 'end'; its anchors: 'left', 'right'"):
            call()
    rope.grasp("hand", "rope", rope.positions("rope")[10], radius=0.03)
    for call in (lambda: rope.move_grasp("paw", [0, 0, 1]), lambda: rope.release("paw"),
                 lambda: rope.grasp_wrench("paw"), lambda: rope.pose("paw")):
        with pytest.raises(KeyError, match="paw.*'hand'"):
            call()
    with pytest.raises(KeyError, match="no anchor or grasp 'rope/end'; .*'rope/left', 'rope/right'.*'hand'"):
        sim.rollouts(rope, holder="rope/end", goals=np.zeros((1, 1, 3)))
    demo = sim.World(SCENES / "demo.yaml")
    with pytest.raises(KeyError, match="no collider 'finger' that moves; the scene's: 'lower_finger', 'upper_finger', 'table'"):
        demo.move_collider("finger", [0, 0, 1])


@pytest.mark.parametrize("value, reason", [
    ([1.0, 2.0], r"position: expected 3 numbers, got an array of shape \(2,\)"),
    ([[1.0, 2.0, 3.0]], r"position: expected 3 numbers, got an array of shape \(1, 3\)"),
    ([0.0, float("nan"), 1.0], "position: not finite"),
    ([0.0, float("inf"), 1.0], "position: not finite"),
    ("abc", "position: expected numbers"),
    ([0.0, None, 1.0], "position: not finite"),
])
def test_malformed_positions_are_value_errors(rope, value, reason):
    with pytest.raises(ValueError, match=reason):
        rope.move_anchor("rope", "left", value)


def test_malformed_orientations_and_other_values_are_value_errors(rope):
    with pytest.raises(ValueError, match="orientation: expected 4 numbers"):
        rope.move_anchor("rope", "left", [0, 0, 1], orientation=[0, 0, 1])
    with pytest.raises(ValueError, match="orientation: no orientation"):
        rope.move_anchor("rope", "left", [0, 0, 1], orientation=[0, 0, 0, 0])
    with pytest.raises(ValueError, match="orientation: no orientation"):
        rope.move_anchor("rope", "left", [0, 0, 1], orientation=[1e200, 0, 0, 0])
    with pytest.raises(ValueError, match="steps: must be >= 0"):
        rope.step(-1)
    with pytest.raises(ValueError, match="takes no target; those that do: none"):
        rope.set_target("rope", [0, 0, 0])
    # What the core refuses, in its words.
    with pytest.raises(ValueError, match="no free node"):
        rope.grasp("hand", "rope", [5.0, 0.0, 0.0], radius=0.03)
    with pytest.raises(ValueError, match="radius"):
        rope.grasp("hand", "rope", [0.0, 0.0, 1.5], radius=-1.0)
    rope.grasp("hand", "rope", rope.positions("rope")[10], radius=0.03)
    with pytest.raises(ValueError, match="hand"):
        rope.grasp("hand", "rope", rope.positions("rope")[5], radius=0.03)


@pytest.mark.parametrize("goals, steps_per_goal, threads, reason", [
    (np.zeros((2, 3, 4)), 1, 0, r"goals: expected shape \(B, T, 3\) positions or \(B, T, 7\) poses.*got \(2, 3, 4\)"),
    (np.zeros((2, 3)), 1, 0, r"got \(2, 3\)"),
    ("abc", 1, 0, "goals: expected numbers"),
    (np.full((2, 3, 3), 0.5), 0, 0, "steps_per_goal: must be >= 1, got 0"),
    (np.full((2, 3, 3), 0.5), 1, -1, "threads: must be >= 0"),
])
def test_malformed_rollouts_are_value_errors(rope, goals, steps_per_goal, threads, reason):
    with pytest.raises(ValueError, match=reason):
        sim.rollouts(rope, holder="rope/right", goals=goals, steps_per_goal=steps_per_goal, threads=threads)


def test_goals_that_are_not_finite_or_no_orientation_are_named(rope):
    goals = np.full((3, 4, 7), 0.5)
    goals[2, 1, 0] = np.nan
    with pytest.raises(ValueError, match=r"goals\[2, 1\] is not finite"):
        sim.rollouts(rope, holder="rope/right", goals=goals)
    goals[2, 1, 0] = 0.5
    goals[1, 3, 3:] = 0.0
    with pytest.raises(ValueError, match=r"goals\[1, 3\]: no orientation"):
        sim.rollouts(rope, holder="rope/right", goals=goals)


def test_a_snapshot_of_another_scene_is_refused_naming_both(rope):
    cloth = sim.World(str(SCENES / "cloth.yaml"))
    before = rope.positions()
    for snapshot in (cloth.snapshot(), sim.Snapshot.from_bytes(cloth.snapshot().to_bytes())):
        with pytest.raises(ValueError, match=r"cloth \(225 nodes\).*rope \(21 nodes\)"):
            rope.restore(snapshot)
    assert np.array_equal(rope.positions(), before)


def test_bytes_that_are_no_snapshot_are_refused(rope):
    data = rope.snapshot().to_bytes()
    damaged = data[:-8] + bytes([data[-8] ^ 1]) + data[-7:]  # a bit of the values, which the checksum covers
    for bad in (b"", b"not a snapshot at all", data[:-1], damaged):
        with pytest.raises(ValueError):
            sim.Snapshot.from_bytes(bad)
    with pytest.raises(TypeError):
        sim.Snapshot.from_bytes("a str is no bytes")


def test_a_pickled_world_whose_scene_file_changed_is_refused(tmp_path):
    scene = tmp_path / "rope.yaml"
    rope = "bodies: [{name: rope, type: rope, nodes: %d, from: [0, 0, 1], to: [1, 0, 1], mass: 0.1, stiffness: 100}]\n"
    scene.write_text(rope % 11)
    data = pickle.dumps(sim.World(scene))
    scene.write_text(rope % 12)
    with pytest.raises(ValueError, match=r"rope \(11 nodes\).*rope \(12 nodes\)"):
        pickle.loads(data)

"""A Python World of a scene steps to the same bits as the headless `simulate` of the same scene: the same
loader (package:// meshes, `dt: auto`), the same world. simulate writes 17 significant digits, which read back
as the very doubles it printed."""
import csv
import subprocess

import pytest

from conftest import SCENES, same_bits
from soft_body_sim import sim

# A rope falling onto the example mesh, named by package://, at the step `dt: auto` chooses.
AUTO_DT_MESH_SCENE = """
physics: {integrator: semi_implicit_euler, dt: auto}
colliders:
  - {name: part, shape: mesh, mesh: package://soft_body_sim/config/meshes/part.stl, position: [0.5, 0.0, 0.85]}
bodies:
  - {name: rope, type: rope, nodes: 15, from: [0.0, 0.0, 1.0], to: [1.0, 0.0, 1.0], mass: 0.1, stiffness: 500.0,
     damping: 0.01, radius: 0.01, pinned: [0], anchors: [{name: end, node: 0}]}
"""


def last_rows(path, columns):
    """The rows of a simulate CSV at its last time, by their leading key columns (strings) after t."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))[1:]
    last = max(float(row[0]) for row in rows)
    return float(rows[-1][0]), {tuple(row[1:columns]): [float(x) for x in row[columns:]]
                                for row in rows if float(row[0]) == last}


@pytest.mark.parametrize("name", ["rope.yaml", "cloth.yaml", "auto_dt_mesh.yaml"])
def test_positions_tensions_and_wrenches_equal_simulate_to_the_bit(name, simulate, tmp_path):
    scene = str(SCENES / name)
    if name == "auto_dt_mesh.yaml":
        scene = str(tmp_path / name)
        with open(scene, "w") as f:
            f.write(AUTO_DT_MESH_SCENE)
    duration = 0.5
    out = {name: str(tmp_path / (name + ".csv")) for name in ("csv", "tensions", "forces")}
    subprocess.run([simulate, "--scene", scene, "--duration", str(duration)] +
                   [arg for name, path in out.items() for arg in ("--" + name, path)], check=True)

    w = sim.World(scene)
    w.step(round(duration / w.dt))

    t, positions = last_rows(out["csv"], 3)
    assert t == w.time
    for body in w.bodies:
        expected = [positions[(body, str(k))] for k in range(w.positions(body).shape[0])]
        assert same_bits(w.positions(body), expected), body
    _, tensions = last_rows(out["tensions"], 6)
    for body in w.bodies:
        # simulate's rows per body: its springs, then its constraints, each in order, as tensions() lists them.
        expected = [tension for (name, kind, index, a, b), [tension] in tensions.items() if name == body]
        assert same_bits(w.tensions(body), expected), body
    _, forces = last_rows(out["forces"], 3)
    for body in w.bodies:
        for anchor in w.anchors(body):
            force, torque = w.wrench(body, anchor)
            assert same_bits(force, forces[(body, anchor)][:3]) and same_bits(torque, forces[(body, anchor)][3:])


def test_divergence_events_are_those_simulate_warns_of(simulate, tmp_path):
    """A rope far too stiff for explicit Euler at its step: the guard catches it once and switches it to
    implicit_euler. Python's events of the step() call are simulate's warnings, word for word."""
    scene = tmp_path / "diverging.yaml"
    scene.write_text("physics: {integrator: explicit_euler, dt: 0.01}\n"
                     "bodies: [{name: rope, type: rope, nodes: 10, from: [0, 0, 1], to: [1, 0, 1], mass: 0.1,\n"
                     "          stiffness: 100000.0, pinned: [0]}]\n")
    run = subprocess.run([simulate, "--scene", str(scene), "--duration", "0.1", "--csv", str(tmp_path / "x.csv")],
                         check=True, capture_output=True, text=True)
    warned = [line.split("simulate: warning: ", 1)[1] for line in run.stderr.splitlines() if "diverged" in line]

    w = sim.World(scene)
    start = w.snapshot()
    w.step(10)
    assert len(warned) == 1 and [str(event) for event in w.divergence_events] == warned
    [event] = w.divergence_events
    assert event.body == "rope" and "implicit_euler" in event.action and 0.0 < event.time <= w.time
    assert w.divergence_count == 1
    w.step(10)
    assert w.divergence_events == [] and w.divergence_count == 1  # the last call's catches; all since made
    w.restore(start)
    assert w.divergence_events == [] and w.divergence_count == 0

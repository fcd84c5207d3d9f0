"""python3 -m soft_body_sim.sweep (docs/sweeps.md): a sweep on a local cluster, and on a real scheduler with
two workers of which one is killed half-way, gives each run once, with the bits of the same run done in this
process and of `simulate` of the run's scene; a stopped sweep resumes with only what is missing; a bad sweep
file stops before any run with one line naming the key."""
import csv
import datetime
import json
import os
import re
import shlex
import signal
import socket
import subprocess
import sys
import time

import distributed
import h5py
import pytest

from conftest import ROOT, SCENES, same_bits
from soft_body_sim import sweep, sweep_run
from soft_body_sim.sweep_file import read_sweep

# rope.yaml (21 nodes between two anchors), its guard set to give up at once: a body it catches is frozen,
# which is a run the sweep must report as diverged.
BASE_SCENE = (SCENES / "rope.yaml").read_text().replace(
    "  drag: 0.5 ", "  guard: {policy: freeze}\n  drag: 0.5 ")

# 4 x 2 grid runs and 4 random ones: 12. A stiffness of -5 N/m is refused by the loader (2 failed runs); 10^5
# N/m is far beyond semi-implicit Euler's limit at this step (omega dt ~ 13 > 2: the guard freezes the rope,
# diverged) and fine for implicit Euler.
SWEEP = """\
scene: rope.yaml
duration: {duration}
record_every: {record_every}
grid:
  bodies.rope.stiffness: [150, 300.0, 1e5, -5]
  physics.integrator: [semi_implicit_euler, implicit_euler]
random:
  count: 4
  seed: 7
  keys:
    bodies.rope.mass: {{uniform: [0.05, 0.3]}}
"""


def write_sweep(folder, duration=0.5, record_every=0.1, text=SWEEP):
    (folder / "rope.yaml").write_text(BASE_SCENE)
    path = folder / "sweep.yaml"
    path.write_text(text.format(duration=duration, record_every=record_every))
    return path


def serial_results(path):
    """The sweep's runs done one after the other in this process, by id."""
    s = read_sweep(path)
    return {spec.id: sweep_run.run(spec) for spec in sweep.specs_of(s, s.runs)}


def read_csv(out):
    with open(out / "runs.csv", newline="") as f:
        return list(csv.DictReader(f))


def assert_output_is(out, expected):
    """Each run of `expected` exactly once in runs.csv and runs.h5, with its bits."""
    rows = read_csv(out)
    assert sorted(row["id"] for row in rows) == sorted(expected)
    with h5py.File(out / "runs.h5", "r") as h5:
        assert sorted(h5["runs"]) == sorted(expected)
        for run_id, truth in expected.items():
            group = h5["runs"][run_id]
            assert group.attrs["status"] == truth["status"] and group.attrs["message"] == truth["message"]
            assert json.loads(group.attrs["values"]) == truth["values"]
            for name in ("time", "positions", "tensions", "wrenches"):
                assert (name in group) == (name in truth), (run_id, name)
                if name in truth:
                    assert same_bits(group[name][()], truth[name]), (run_id, name)
    return rows


def test_a_local_cluster_gives_the_bits_of_the_runs_done_in_process_and_records_the_failures(tmp_path, capsys):
    path = write_sweep(tmp_path)
    assert sweep.main([str(path), "--out", str(tmp_path / "results"), "--workers", "2"]) == 0
    truth = serial_results(path)
    rows = assert_output_is(tmp_path / "results", truth)

    assert len(rows) == 12
    by_status = {}
    for row in rows:
        by_status.setdefault(row["status"], []).append(row)
    assert len(by_status["failed"]) == 2 and len(by_status["diverged"]) == 1 and len(by_status["ok"]) == 9
    for row in by_status["failed"]:
        assert row["bodies.rope.stiffness"] == "-5"
        assert "rope.yaml:29: bodies[0].stiffness: rope 'rope': stiffness must be > 0, got -5" in row["message"]
    [diverged] = by_status["diverged"]
    assert diverged["physics.integrator"] == "semi_implicit_euler" and diverged["bodies.rope.stiffness"] == "100000.0"
    assert "body 'rope' diverged" in diverged["message"] and int(diverged["divergence_events"]) >= 1
    # The random runs leave the grid's columns empty: those keys are as in the base scene.
    assert sum(row["bodies.rope.mass"] != "" for row in rows) == 4
    assert "sweep: 12 runs, 0 already in" in capsys.readouterr().err


def test_tasks_of_several_runs_give_the_same_bits_and_share_the_names(tmp_path, monkeypatch):
    # One worker, no tail, tasks of up to 16 runs: a one-run task first, then the other 11 runs in one task.
    monkeypatch.setattr(sweep, "TAIL_TASKS_PER_THREAD", 1)
    monkeypatch.setattr(sweep, "TASK_SECONDS", 100.0)
    sizes = []
    submit = sweep.Tasks.submit
    monkeypatch.setattr(sweep.Tasks, "submit", lambda tasks, count: (sizes.append(count), submit(tasks, count)))
    path = write_sweep(tmp_path)
    assert sweep.main([str(path), "--out", str(tmp_path / "results"), "--workers", "1"]) == 0
    assert sizes == [1, 11]
    truth = serial_results(path)
    assert_output_is(tmp_path / "results", truth)
    with h5py.File(tmp_path / "results" / "runs.h5", "r") as h5:
        stepped = [run for run in h5["runs"].values() if "time" in run]
        names = [run[name] for run in stepped for name in ("node_names", "tension_bodies", "anchor_names")]
        # The 21-node rope in every run: one dataset of each list, which every run's link reads.
        assert len(h5["names"]) == 3
        assert {tuple(n.asstr()[()]) for n in names} == {tuple(h5["names"][key].asstr()[()]) for key in h5["names"]}
        assert [n.asstr()[()].tolist() for n in names[:3]] == [truth[stepped[0].name.split("/")[-1]][name] for name
                                                               in ("node_names", "tension_bodies", "anchor_names")]
        assert len({n.id for n in names[0::3]}) == 1  # one HDF5 object, not copies


def test_a_run_has_the_bits_of_simulate_of_its_scene(tmp_path, simulate):
    path = write_sweep(tmp_path)
    s = read_sweep(path)
    run = next(r for r in s.runs if r.values.get("physics.integrator") == "implicit_euler"
               and r.values.get("bodies.rope.stiffness") == 300.0)
    [result] = [sweep_run.run(spec) for spec in sweep.specs_of(s, [run])]
    # The scene as --scene-of prints it, beside the base scene (where its relative meshes would be found).
    scene = tmp_path / f"run-{run.id}.yaml"
    assert subprocess.run([sys.executable, "-m", "soft_body_sim.sweep", str(path), "--scene-of", run.id],
                          stdout=open(scene, "w"), check=True).returncode == 0
    out = {name: tmp_path / f"{name}.csv" for name in ("csv", "tensions", "forces")}
    every = round(0.1 / 0.002)  # record_every / the scene's dt, in steps
    subprocess.run([simulate, "--scene", str(scene), "--duration", "0.5", "--every", str(every)]
                   + [arg for name, p in out.items() for arg in ("--" + name, str(p))], check=True,
                   capture_output=True)
    rows = {name: list(csv.reader(open(p)))[1:] for name, p in out.items()}
    times = sorted({float(row[0]) for row in rows["csv"]})
    assert same_bits(result["time"], times)
    positions = [[[float(x) for x in row[3:]] for row in rows["csv"] if float(row[0]) == t] for t in times]
    assert same_bits(result["positions"], positions)
    tensions = [[float(row[6]) for row in rows["tensions"] if float(row[0]) == t] for t in times]
    assert same_bits(result["tensions"], tensions)
    wrenches = [[[float(x) for x in row[3:]] for row in rows["forces"] if float(row[0]) == t and row[1]]
                for t in times]
    assert same_bits(result["wrenches"], wrenches)
    assert list(result["anchor_names"]) == ["rope/left", "rope/right"]


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture
def cluster(tmp_path):
    """A `dask scheduler` and two `dask worker` processes on 127.0.0.1 (one thread each, no nanny, so that
    a killed worker stays dead); stopped after the test, whatever happened."""
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    log = open(tmp_path / "dask.log", "w")
    quiet = dict(stdout=log, stderr=log, start_new_session=True)
    processes = [subprocess.Popen(["dask", "scheduler", "--host", "127.0.0.1", "--port", str(port),
                                   "--no-dashboard"], **quiet)]
    try:
        for name in ("w1", "w2"):
            processes.append(subprocess.Popen(["dask", "worker", address, "--name", name, "--nthreads", "1",
                                               "--no-nanny", "--no-dashboard", "--host", "127.0.0.1"], **quiet))
        with distributed.Client(address, timeout=20) as client:
            client.wait_for_workers(2, timeout=20)
            workers = {info["name"]: worker for worker, info in client.scheduler_info()["workers"].items()}
        yield address, processes, workers
    finally:
        for process in processes:
            if process.poll() is None:
                os.killpg(process.pid, signal.SIGTERM)
        for process in processes:
            try:
                process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                os.killpg(process.pid, signal.SIGKILL)
                process.wait()
        log.close()


def test_a_worker_killed_half_way_loses_no_run_and_doubles_none(tmp_path, cluster):
    address, processes, workers = cluster
    # Runs of 0.05 to 0.2 s, so that the killed worker is in the middle of one.
    path = write_sweep(tmp_path, duration=300.0, record_every=10.0)
    out = tmp_path / "results"
    client = subprocess.Popen([sys.executable, "-m", "soft_body_sim.sweep", str(path), "--out", str(out),
                               "--scheduler", address], stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 60
        with distributed.Client(address, timeout=20) as observer:
            # Half-way: a third of the runs written, and w1 holding runs that it has not finished.
            while not ((out / "runs.csv").exists() and len(read_csv(out)) >= 4
                       and observer.processing(workers=[workers["w1"]])[workers["w1"]]):
                assert client.poll() is None and time.monotonic() < deadline, "the sweep ended before half-way"
                time.sleep(0.01)
            processes[1].kill()  # w1
        # A result w1 sent just before it died may still be written a moment later; after 0.1 s only w2's.
        time.sleep(0.1)
        killed = datetime.datetime.now(datetime.timezone.utc).isoformat()
        _, err = client.communicate(timeout=60)
    finally:
        if client.poll() is None:
            client.kill()
    assert client.returncode == 0, err
    assert_output_is(out, serial_results(path))
    with h5py.File(out / "runs.h5", "r") as h5:
        after = [run.attrs["worker"] for run in h5["runs"].values() if run.attrs["finished"] > killed]
    assert after and set(after) == {workers["w2"]}  # the rest, w1's run in flight among them, went to w2


def test_a_resumed_sweep_runs_only_what_is_missing(tmp_path, capsys):
    out = tmp_path / "results"
    first = SWEEP.replace("[150, 300.0, 1e5, -5]", "[150, 300.0]").split("random:")[0]
    path = write_sweep(tmp_path, text=first)
    assert sweep.main([str(path), "--out", str(out), "--workers", "1"]) == 0
    with h5py.File(out / "runs.h5", "r") as h5:
        finished = {run_id: h5["runs"][run_id].attrs["finished"] for run_id in h5["runs"]}
    assert len(finished) == 4

    # The whole sweep into the same folder: its first four runs are there, by their ids.
    path = write_sweep(tmp_path)
    capsys.readouterr()
    assert sweep.main([str(path), "--out", str(out), "--workers", "1"]) == 0
    assert "sweep: 12 runs, 4 already in" in capsys.readouterr().err
    assert_output_is(out, serial_results(path))
    with h5py.File(out / "runs.h5", "r") as h5:
        assert all(h5["runs"][run_id].attrs["finished"] == when for run_id, when in finished.items())

    # Once more: nothing to run, no cluster started.
    assert sweep.main([str(path), "--out", str(out)]) == 0
    assert "12 runs, 12 already in" in capsys.readouterr().err
    assert len(read_csv(out)) == 12


BAD = [
    ("grid:\n  bodies.rop.stiffness: [1]\n", "4: grid.bodies.rop.stiffness: no element 'rop' in bodies (names: rope)"),
    ("grid:\n  bodies.rope.stifness: [1]\n", "4: grid.bodies.rope.stifness: unknown key 'stifness'; allowed keys:"),
    ("grid:\n  physics.gravity.z: [1]\n", "4: grid.physics.gravity.z: no element 'z' in physics.gravity"),
    ("grid: {}\n", "3: grid: empty: give at least one key with its values"),
    ("grid:\n  bodies.rope.stiffness: []\n", "4: grid.bodies.rope.stiffness: empty: give at least one value"),
    ("grid:\n  bodies.rope.stiffness: [100, stiff]\n",
     "4: grid.bodies.rope.stiffness: expected a number as the scene's bodies.rope.stiffness is, got 'stiff'"),
    ("grid:\n  physics.integrator: [xpbd, 2]\n",
     "4: grid.physics.integrator: expected a string as the scene's physics.integrator is, got '2'"),
    ("random: {count: 2, seed: 1, keys: {bodies.rope.mass: {gauss: [1, 2]}}}\n",
     "3: random.keys.bodies.rope.mass: expected one distribution of uniform, log_uniform, got gauss"),
    ("random: {count: 2, seed: 1, keys: {bodies.rope.mass: {log_uniform: [0, 2]}}}\n",
     "3: random.keys.bodies.rope.mass.log_uniform: expected low > 0"),
    ("grids:\n  physics.dt: [0.001]\n", "3: grids: unknown key; allowed keys: scene, duration, record_every, grid"),
]


@pytest.mark.parametrize("tail, message", BAD, ids=[m.split(": ")[1] for _, m in BAD])
def test_a_bad_sweep_file_stops_before_any_run_with_one_line(tmp_path, capsys, tail, message):
    literal = tail.replace("{", "{{").replace("}", "}}")  # write_sweep formats the text
    path = write_sweep(tmp_path, text="scene: rope.yaml\nduration: 1.0\n" + literal)
    assert sweep.main([str(path), "--out", str(tmp_path / "results")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"{path}:{message}"), err
    assert not (tmp_path / "results").exists()


def test_the_readmes_example_finds_the_recorded_stiffness_back(tmp_path):
    """The README's "Sweeps" commands as written, from the repository root, the output folder in tmp_path."""
    readme = (ROOT / "README.md").read_text()
    section = readme.split("\n## Sweeps\n", 1)[1].split("\n## ", 1)[0]
    [block] = re.findall(r"```sh\n(.*?)```", section, re.S)
    for line in block.strip().splitlines():
        args = shlex.split(line.replace("/tmp/stiffness", str(tmp_path / "stiffness")))
        # This test's python3 (Debian's) for `python3 -m` and for the script, whatever is first on PATH.
        args = [sys.executable] + (args[1:] if args[0] == "python3" else args)
        run = subprocess.run(args, cwd=ROOT, check=True, capture_output=True, text=True)
    estimate = float(re.match(r"stiffness (\d+) N/m", run.stdout).group(1))
    # The recording's 2 mm of noise per coordinate make the estimate's standard deviation 2.0 N/m (2 mm over
    # the root sum of squares of the nodes' sensitivity, up to 0.32 mm per N/m at the middle): 8 N/m is 4 of them.
    assert abs(estimate - 237.0) <= 8.0
    assert (tmp_path / "stiffness" / "fit.png").stat().st_size > 0

#!/usr/bin/python3
"""A sweep's cost on Dask (RESULTS.md, "Sweeps"): 200 runs of bench/rope_51.yaml (51 nodes, implicit Euler at
1/60 s) over a grid of 20 stiffnesses x 10 dampings, on a local cluster of one worker, then of two.

- the run itself: the steps of a run, timed in this process (World.step, nothing else), averaged over runs;
- overhead per run: one worker's wall time for the sweep, cluster start excluded, over the runs, less the run
  itself: what loading the scene, sampling, shipping the result, scheduling and writing runs.h5 add;
- speed-up: one worker's wall time over two workers', for each of `--pairs` pairs, and their median.

  source build/devel/setup.bash && /usr/bin/python3 bench/bench_sweep.py [--duration S] [--runs-timed N] [--pairs K]
"""
import argparse
import io
import os
import pathlib
import resource
import shutil
import tempfile
import time

import numpy as np

from soft_body_sim import sim, sweep
from soft_body_sim.sweep_file import read_sweep
from soft_body_sim.sweep_run import steps_of

ROOT = pathlib.Path(__file__).resolve().parents[1]

SWEEP = """\
scene: rope_51.yaml
duration: {duration}
record_every: {record_every}
grid:
  bodies.rope.stiffness: [{stiffness}]
  bodies.rope.damping: [{damping}]
"""


def write_sweep(folder, duration, record_every):
    shutil.copy(ROOT / "bench" / "rope_51.yaml", folder / "rope_51.yaml")
    stiffness = ", ".join(repr(float(k)) for k in np.linspace(500.0, 2400.0, 20))
    damping = ", ".join(repr(float(c)) for c in np.linspace(0.01, 0.1, 10))
    path = folder / "sweep.yaml"
    path.write_text(SWEEP.format(duration=duration, record_every=record_every, stiffness=stiffness,
                                 damping=damping))
    return path


def step_seconds(s, count):
    """The mean wall time [s] of a run's steps alone, over the first `count` runs, in this process."""
    seconds = []
    for run in s.runs[:count]:
        world = sim.World.from_yaml(s.run_scene(run), s.scene_path)
        steps = steps_of(s.duration, world.dt)
        start = time.perf_counter()
        world.step(steps)
        seconds.append(time.perf_counter() - start)
    return float(np.mean(seconds))


def busy_seconds():
    """CPU seconds the whole machine has spent busy (every process, /proc/stat), and this process's with its
    reaped children's (the cluster's workers, once it is closed)."""
    with open("/proc/stat") as f:
        user, nice, system, idle, iowait, irq, softirq, steal = (int(x) for x in f.readline().split()[1:9])
    machine = (user + nice + system + irq + softirq + steal) / os.sysconf("SC_CLK_TCK")
    own = sum(resource.getrusage(who).ru_utime + resource.getrusage(who).ru_stime
              for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN))
    return machine, own


def sweep_seconds(s, out, workers):
    """The wall time [s] of the whole sweep on a local cluster of `workers` as the command makes it (the
    cluster already started), the cores [1] that other processes kept busy meanwhile (the machine is shared:
    RESULTS.md, "The machine"), from start to close of the cluster, and the CPU seconds of this process (the
    client, and the local cluster's scheduler, which runs in it) during the sweep."""
    machine, own = busy_seconds()
    started = time.perf_counter()
    client, cluster = sweep.make_client(None, workers)
    with cluster, client:
        client.wait_for_workers(workers)
        start, client_cpu = time.perf_counter(), time.process_time()
        lost = sweep.run_sweep(s, out, client=client, stream=io.StringIO())
        seconds, client_cpu = time.perf_counter() - start, time.process_time() - client_cpu
    assert lost == 0
    machine_after, own_after = busy_seconds()
    others = ((machine_after - machine) - (own_after - own)) / (time.perf_counter() - started)
    return seconds, others, client_cpu


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--duration", type=float, default=300.0, help="[s] simulated per run (default 300)")
    parser.add_argument("--record-every", type=float, default=10.0, help="[s] between samples (default 10)")
    parser.add_argument("--runs-timed", type=int, default=20, help="runs timed alone for the run itself")
    parser.add_argument("--pairs", type=int, default=3, help="sweeps on 1 worker then 2, this many times")
    args = parser.parse_args()
    ratios = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = pathlib.Path(tmp)
        s = read_sweep(write_sweep(folder, args.duration, args.record_every))
        n = len(s.runs)
        alone = step_seconds(s, args.runs_timed)
        print(f"{n} runs of {args.duration:g} s of a 51-node rope ({steps_of(args.duration, 1 / 60)} steps), "
              f"sampled every {args.record_every:g} s")
        print(f"the run itself (its steps, in-process, mean of {args.runs_timed}): {1000 * alone:.1f} ms")
        for k in range(args.pairs):
            one, others_one, client_one = sweep_seconds(s, folder / f"one{k}", 1)
            two, others_two, client_two = sweep_seconds(s, folder / f"two{k}", 2)
            ratios.append(one / two)
            print(f"1 worker: {one:.2f} s, {1000 * one / n:.1f} ms a run: overhead {1000 * (one / n - alone):.1f} ms "
                  f"a run (client and scheduler {1000 * client_one / n:.1f} ms CPU a run; other processes kept "
                  f"{others_one:.2f} cores busy)")
            print(f"2 workers: {two:.2f} s, {1000 * two / n:.1f} ms a run: {one / two:.2f} times 1 worker (client and "
                  f"scheduler {1000 * client_two / n:.1f} ms CPU a run; other processes kept {others_two:.2f} cores "
                  "busy)")
    print(f"2 workers over 1, median of {args.pairs} pairs: {float(np.median(ratios)):.2f} "
          f"(from {min(ratios):.2f} to {max(ratios):.2f})")


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""The Python module's speed (docs/RESULTS.md, "From Python"), by hand after `source build/devel/setup.bash`:

    python3 bench/bench_python.py [--rounds N]

- sim.rollouts on bench/rope_51.yaml (bench_step's BM_Snapshot rope: 51 nodes, implicit Euler at 1/60 s) 60
  steps in, 50 rollouts x 60 goals x 4 steps, with 1 and with 2 threads: rope steps per second per core, and
  the speed-up of 2 threads over 1;
- World.step(1000) from Python, per step, against bench_step's C++ loop on the same rope: bench/rope_100.yaml
  against BM_RopeStepEngine/implicit_euler/100 (both step on from the start), and bench/rope_51.yaml 60 steps
  in against BM_Snapshot/rope_51/step (which times each step from that moment, pausing its timer for a
  restore in between). Python and C++ run in turn, round after round.
Medians over the rounds. Another load on the machine shows in the numbers: run it on an idle one."""
import argparse
import json
import pathlib
import statistics
import subprocess
import time

import numpy as np
from catkin.find_in_workspaces import find_in_workspaces

from soft_body_sim import sim

BENCH = pathlib.Path(__file__).resolve().parent
ROLLOUTS, GOALS, STEPS_PER_GOAL = 50, 60, 4


def rope_51_60_steps_in():
    w = sim.World(str(BENCH / "rope_51.yaml"))
    w.step(60)
    return w


def rollouts_seconds(w, goals, threads):
    start = time.perf_counter()
    sim.rollouts(w, holder="rope/end", goals=goals, steps_per_goal=STEPS_PER_GOAL, threads=threads)
    return time.perf_counter() - start


def python_step_seconds(w, steps=1000, seconds=0.5):
    """Per step [s]: the mean over w.step(steps) calls for about `seconds`, as Google Benchmark's over its
    iterations."""
    calls, spent = 0, 0.0
    while spent < seconds:
        start = time.perf_counter()
        w.step(steps)
        spent += time.perf_counter() - start
        calls += 1
    return spent / (calls * steps)


def cpp_step_seconds(bench_step, benchmark):
    out = subprocess.run([bench_step, f"--benchmark_filter={benchmark}$", "--benchmark_format=json"],
                         check=True, capture_output=True, text=True).stdout
    [run] = json.loads(out)["benchmarks"]
    return run["real_time"] * {"us": 1e-6, "ns": 1e-9, "ms": 1e-3}[run["time_unit"]]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=7)
    rounds = parser.parse_args().rounds
    [bench_step] = find_in_workspaces(search_dirs=["libexec"], project="soft_body_sim", path="bench_step",
                                      first_match_only=True)

    w = rope_51_60_steps_in()
    # Random walks of 1 cm steps from the anchor's place: the rope is swung about, as a planner's samples.
    rng = np.random.default_rng(0)
    goals = w.pose("rope/end")[:3] + np.cumsum(rng.normal(scale=0.01, size=(ROLLOUTS, GOALS, 3)), axis=1)
    steps = ROLLOUTS * GOALS * STEPS_PER_GOAL
    times = {1: [], 2: []}
    for _ in range(rounds):
        for threads in times:
            times[threads].append(rollouts_seconds(w, goals, threads))
    one, two = statistics.median(times[1]), statistics.median(times[2])
    print(f"sim.rollouts, {ROLLOUTS} x {GOALS} goals x {STEPS_PER_GOAL} steps = {steps} rope steps "
          f"(median of {rounds}):")
    print(f"  1 thread:  {one * 1e3:.1f} ms, {steps / one:,.0f} rope steps/s per core")
    print(f"  2 threads: {two * 1e3:.1f} ms, {steps / two / 2:,.0f} rope steps/s per core, {one / two:.2f} x 1 thread")

    comparisons = [("rope_100.yaml", lambda: sim.World(str(BENCH / "rope_100.yaml")),
                    "BM_RopeStepEngine/implicit_euler/100"),
                   ("rope_51.yaml", rope_51_60_steps_in, "BM_Snapshot/rope_51/step")]
    for scene, world, benchmark in comparisons:
        python, cpp = [], []
        for _ in range(rounds):
            cpp.append(cpp_step_seconds(bench_step, benchmark))
            python.append(python_step_seconds(world()))
        py_step, cpp_step = statistics.median(python), statistics.median(cpp)
        print(f"one step of {scene} (median of {rounds} rounds, in turn): World.step(1000) from Python "
              f"{py_step * 1e6:.3f} us, bench_step {benchmark} {cpp_step * 1e6:.3f} us: "
              f"Python / C++ {py_step / cpp_step:.3f}")


if __name__ == "__main__":
    main()

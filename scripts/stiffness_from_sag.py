#!/usr/bin/python3
"""The README's worked example of a sweep (docs/sweeps.md): a rope's stiffness found from its recorded sag.

  scripts/stiffness_from_sag.py record config/sweeps/recorded_sag.csv
      The "recording": config/scenes/rope.yaml at rest with a stiffness of 237 N/m, every node's position
      with 2 mm of Gaussian noise (seed 1), as a camera might see it. Made once; the file is in the repository.
  python3 -m soft_body_sim.sweep config/sweeps/rope_stiffness.yaml --out /tmp/stiffness
      The same rope at rest for 31 stiffnesses from 100 to 400 N/m.
  scripts/stiffness_from_sag.py fit /tmp/stiffness config/sweeps/recorded_sag.csv [--plot docs/sweep_stiffness.png]
      Each run's resting rope against the recording: the RMS distance over the nodes, its minimum refined by a
      parabola through the best run and its neighbours; prints the stiffness, plots the curve and the shapes.
"""
import argparse
import json
import pathlib
import sys

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
KEY = "bodies.rope.stiffness"
TRUE_STIFFNESS = 237.0  # [N/m] the recording's, between the sweep's values (they step by 10)
NOISE = 0.002           # [m] standard deviation of the recording's noise, per coordinate
SETTLE = 40.0           # [s] as the sweep's duration: the drag of 0.5 1/s leaves < 0.01 mm of swing


def record(path):
    from soft_body_sim import sim
    from soft_body_sim.scene_edit import Scene
    from soft_body_sim.sweep_run import steps_of

    scene_path = ROOT / "config" / "scenes" / "rope.yaml"
    scene = Scene(scene_path.read_text(), str(scene_path))
    world = sim.World.from_yaml(scene.with_values({KEY: TRUE_STIFFNESS}), str(scene_path))
    world.step(steps_of(SETTLE, world.dt))
    resting = world.positions("rope")
    seen = resting + np.random.default_rng(1).normal(scale=NOISE, size=resting.shape)
    with open(path, "w") as f:
        f.write(f"# config/scenes/rope.yaml at rest after {SETTLE:g} s with stiffness {TRUE_STIFFNESS:g} N/m, "
                f"each coordinate with Gaussian noise of {NOISE * 1000:g} mm (seed 1): "
                "scripts/stiffness_from_sag.py record\n")
        f.write("node,x,y,z\n")
        for k, (x, y, z) in enumerate(seen):
            f.write(f"{k},{x!r},{y!r},{z!r}\n")


def read_recording(path):
    return np.loadtxt(path, delimiter=",", comments="#", skiprows=2)[:, 1:]


def fit(results, recording_path, plot):
    import h5py

    recorded = read_recording(recording_path)
    stiffness, rms, shapes = [], [], []
    with h5py.File(pathlib.Path(results) / "runs.h5", "r") as h5:
        for group in h5["runs"].values():
            if group.attrs["status"] != "ok":
                continue
            final = group["positions"][-1]
            stiffness.append(float(json.loads(group.attrs["values"])[KEY]))
            rms.append(float(np.sqrt(np.mean(np.sum((final - recorded) ** 2, axis=1)))))
            shapes.append(final)
    order = np.argsort(stiffness)
    stiffness, rms, shapes = np.array(stiffness)[order], np.array(rms)[order], [shapes[i] for i in order]
    best = int(np.argmin(rms))
    estimate = stiffness[best]
    if 0 < best < len(stiffness) - 1:
        # The vertex of the parabola through the best run and its two neighbours.
        a, b, c = np.polyfit(stiffness[best - 1:best + 2], rms[best - 1:best + 2], 2)
        estimate = -b / (2 * a)
    print(f"stiffness {estimate:.0f} N/m (best run {stiffness[best]:g} N/m, RMS {1000 * rms[best]:.1f} mm "
          f"over {len(recorded)} nodes; the recording's noise is {1000 * NOISE:g} mm per coordinate)")
    if plot:
        plot_fit(stiffness, rms, shapes, best, estimate, recorded, plot)
    return estimate


def plot_fit(stiffness, rms, shapes, best, estimate, recorded, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
    left.plot(stiffness, 1000 * rms, "o-", color="tab:blue", markersize=4, label="sweep runs")
    left.axvline(estimate, color="tab:red", label=f"estimate {estimate:.0f} N/m")
    left.axvline(TRUE_STIFFNESS, color="k", linestyle=":", label=f"recording made with {TRUE_STIFFNESS:g} N/m")
    left.set_xlabel("segment stiffness [N/m]")
    left.set_ylabel("RMS distance to the recording [mm]")
    left.set_title("Misfit of each run's resting rope")
    left.legend(loc="upper center")
    for k, color in ((0, "tab:gray"), (best, "tab:red"), (len(shapes) - 1, "tab:olive")):
        right.plot(shapes[k][:, 0], shapes[k][:, 2], "-", color=color, label=f"run, {stiffness[k]:g} N/m")
    right.plot(recorded[:, 0], recorded[:, 2], "k.", label="recording (2 mm noise)")
    right.set_xlabel("x [m]")
    right.set_ylabel("z [m]")
    right.set_title("Resting rope: recording and runs")
    right.set_aspect("equal")
    right.set_ylim(top=recorded[:, 2].max() + 0.15)  # room for the legend above the ropes
    right.legend(loc="upper center", fontsize=8)
    fig.savefig(path, dpi=100)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    record_parser = sub.add_parser("record", help="make the recording")
    record_parser.add_argument("csv")
    fit_parser = sub.add_parser("fit", help="the stiffness of the sweep's run nearest the recording")
    fit_parser.add_argument("results", help="the sweep's output folder")
    fit_parser.add_argument("csv", help="the recording")
    fit_parser.add_argument("--plot", help="a PNG of the misfit and the shapes")
    args = parser.parse_args()
    if args.command == "record":
        record(args.csv)
    else:
        fit(args.results, args.csv, args.plot)
    return 0


if __name__ == "__main__":
    sys.exit(main())

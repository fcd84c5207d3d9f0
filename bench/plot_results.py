#!/usr/bin/env python3
"""Plots and tables of the work-precision report (scripts/bench OUT runs it after the measurements).

Reads from OUT: work_precision.csv, best_cost.csv, ratios.csv, demo.csv (work_precision),
bench_step.json (Google Benchmark), memory.csv (memory_footprint). Writes into OUT:
  work_precision.png         error against cost, log-log, one panel per problem (its first error kind)
  work_precision_more.png    the same for the second error kind (strain, energy drift, penetration), and
                             the problems of one error kind that show all node counts in one panel (rod)
  scaling.png                step cost against node count, with the fitted log-log slope
  summary.md                 the tables docs/RESULTS.md shows
"""
import csv
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ENGINES = ["explicit_euler", "semi_implicit_euler", "verlet", "velocity_verlet", "rk4", "implicit_euler", "xpbd",
           "bullet"]
STYLE = {
    "explicit_euler": ("tab:gray", "v"),
    "semi_implicit_euler": ("tab:blue", "o"),
    "verlet": ("tab:cyan", "s"),
    "velocity_verlet": ("tab:purple", "D"),
    "rk4": ("tab:olive", "^"),
    "implicit_euler": ("tab:green", "P"),
    "xpbd": ("tab:red", "*"),
    "bullet": ("black", "x"),
}
# (problem, n_nodes): panel title; the order of the panels.
PANELS = [
    ("harmonic_oscillator", 2, "1. harmonic oscillator"),
    ("hanging_chain_stiff", 51, "2. hanging chain, stiff, 51 nodes"),
    ("hanging_chain_inextensible", 51, "2. hanging chain, inextensible, 51"),
    ("hanging_chain_stiff", 201, "2. hanging chain, stiff, 201 nodes"),
    ("hanging_chain_inextensible", 201, "2. hanging chain, inextensible, 201"),
    ("swinging_rope_stiff", 51, "3. swinging rope, stiff, 51 nodes"),
    ("swinging_rope_inextensible", 51, "3. swinging rope, inextensible, 51"),
    ("cloth", 1024, "4. cloth 32 x 32"),
    ("jelly", 49, "5. jelly dropped on the floor"),
]
# Problems of one error kind swept over node counts: one panel in work_precision_more.png with every node
# count (each engine's front across them, its points labelled by node count), one table per problem.
ALL_NODES_PANELS = [
    ("rod_cantilever", "6. rod cantilever (elastica)"),
]
UNITS = {
    "final_position": "m", "max_node_distance": "m", "end_point_distance": "m", "penetration": "m",
    "max_strain": "-", "energy_drift": "of M g L", "cell_area": "of the area",
}


def read_csv(path):
    if not os.path.exists(path):
        return []
    with open(path) as f:
        return list(csv.DictReader(f))


def pareto(points):
    """The points (cost, error, ...) no other point beats in both cost and error, by rising cost."""
    front = []
    for point in sorted(points):
        if not front or point[1] < front[-1][1]:
            front.append(point)
    return front


def plot_work_precision(rows, kind_index, path, all_nodes_panels=()):
    """One panel per PANELS entry with an error kind number kind_index, then one per all_nodes_panels entry
    (its first error kind, every node count; nodes None)."""
    kinds = {}
    for row in rows:
        for key in ((row["problem"], int(row["n_nodes"])), (row["problem"], None)):
            kinds.setdefault(key, [])
            if row["error_kind"] not in kinds[key]:
                kinds[key].append(row["error_kind"])
    panels = [(p[0], p[1], p[2], kind_index) for p in PANELS if len(kinds.get((p[0], p[1]), [])) > kind_index]
    for problem, title in all_nodes_panels:
        counts = sorted({int(r["n_nodes"]) for r in rows if r["problem"] == problem})
        if counts:
            panels.append((problem, None, "%s, %d to %d nodes" % (title, counts[0], counts[-1]), 0))
    if not panels:
        return
    columns = 3
    lines = math.ceil(len(panels) / columns)
    figure, axes = plt.subplots(lines, columns, figsize=(5.2 * columns, 4.2 * lines), squeeze=False)
    for axis in axes.flat[len(panels):]:
        axis.set_visible(False)
    for axis, (problem, nodes, title, index) in zip(axes.flat, panels):
        kind = kinds[(problem, nodes)][index]
        for engine in ENGINES:
            points = [(float(r["cpu_s_per_sim_s"]), float(r["error"]), int(r["n_nodes"])) for r in rows
                      if r["problem"] == problem and (nodes is None or int(r["n_nodes"]) == nodes)
                      and r["integrator"] == engine and r["error_kind"] == kind and r["error"] not in ("inf", "nan")
                      and r["cpu_s_per_sim_s"] != "nan" and float(r["error"]) > 0]
            if not points:
                continue
            color, marker = STYLE[engine]
            axis.scatter([p[0] for p in points], [p[1] for p in points], s=14, color=color, marker=marker, alpha=0.45)
            front = pareto(points)
            axis.plot([p[0] for p in front], [p[1] for p in front], color=color, marker=marker, markersize=5,
                      linewidth=1.6 if engine in ("xpbd", "bullet", "implicit_euler") else 1.0,
                      label="Bullet (btSoftBody)" if engine == "bullet" else engine)
            if nodes is None:
                for cost, error, n in front:
                    axis.annotate(str(n), (cost, error), textcoords="offset points", xytext=(3, 3), fontsize=6,
                                  color=color)
        if problem.startswith("hanging_chain") and kind == "max_node_distance":
            axis.axhline(1e-3, color="gray", linestyle="--", linewidth=0.8)
        axis.set_xscale("log")
        axis.set_yscale("log")
        axis.set_title(title, fontsize=10)
        axis.set_xlabel("cost [CPU s per simulated s]", fontsize=8)
        axis.set_ylabel("%s [%s]" % (kind.replace("_", " "), UNITS.get(kind, "")), fontsize=8)
        axis.grid(True, which="major", linewidth=0.3)
        axis.tick_params(labelsize=7)
    handles, labels = [], []
    for axis in axes.flat:
        for handle, label in zip(*axis.get_legend_handles_labels()):
            if label not in labels:
                handles.append(handle)
                labels.append(label)
    figure.legend(handles, labels, loc="lower center", ncol=len(labels), fontsize=9)
    figure.suptitle("Error against cost (lines: each engine's cheapest configuration for its error)", fontsize=11)
    figure.tight_layout(rect=(0, 0.04, 1, 0.97))
    figure.savefig(path, dpi=90)
    plt.close(figure)


def fit_slope(xs, ys):
    lx = [math.log10(x) for x in xs]
    ly = [math.log10(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sum((a - mx) ** 2 for a in lx)


def node_range(nodes):
    return "%s to %s nodes" % ("{:,}".format(int(round(min(nodes), -2))), "{:,}".format(int(round(max(nodes), -2))))


def scaling(out):
    path = os.path.join(out, "bench_step.json")
    if not os.path.exists(path):
        return {}, {}
    with open(path) as f:
        benchmarks = json.load(f)["benchmarks"]
    series, per_spring, rope, cloth_60hz = {}, {}, [], []
    for b in benchmarks:
        name = b["name"]
        if name.startswith("BM_ClothStep/"):
            _, integrator, _ = name.split("/")
            cpu_ns = b["cpu_time"] * {"ns": 1, "us": 1e3, "ms": 1e6, "s": 1e9}[b["time_unit"]]
            series.setdefault(integrator, []).append((b["nodes"], cpu_ns, b["springs"]))
        if name.startswith("BM_ClothSpringForces/"):
            per_spring["spring force kernel (accumulateSpringForces)"] = 1e9 / b["items_per_second"]
        if name.startswith("BM_StiffRopeImplicitEuler/"):
            cpu_ns = b["cpu_time"] * {"ns": 1, "us": 1e3, "ms": 1e6, "s": 1e9}[b["time_unit"]]
            rope.append((int(name.split("/")[1]), cpu_ns))
        if name.startswith("BM_ClothLinearSolveAt60Hz/cheaper/"):
            cpu_ns = b["cpu_time"] * {"ns": 1, "us": 1e3, "ms": 1e6, "s": 1e9}[b["time_unit"]]
            cloth_60hz.append((b["nodes"], cpu_ns))
    slopes = {}
    figure, axis = plt.subplots(figsize=(6.4, 4.6))
    for integrator, points in sorted(series.items()):
        points.sort()
        nodes = [p[0] for p in points]
        cost = [p[1] * 1e-9 for p in points]
        slope = fit_slope(nodes, cost)
        slopes["%s, %s" % (integrator, node_range(nodes))] = slope
        for p in points:
            if p[0] == 10000:
                per_spring["%s step, per spring" % integrator] = p[1] / p[2]
        color, marker = STYLE.get(integrator, ("black", "o"))
        axis.plot(nodes, cost, color=color, marker=marker, label="%s: slope %.3f" % (integrator, slope))
    # implicit_euler on the stiff rope (1e6 N/m, one Newton iteration; block tridiagonal) and on the cloths
    # (sparse LDL^T or CG, whichever the rule picks), both at dt = 1/60 s.
    for label, points, marker, linestyle in (("stiff rope", rope, "s", "--"), ("cloth", cloth_60hz, "^", ":")):
        if not points:
            continue
        points.sort()
        nodes = [p[0] for p in points]
        cost = [p[1] * 1e-9 for p in points]
        slope = fit_slope(nodes, cost)
        slopes["implicit_euler, %s at 1/60 s, %s" % (label, node_range(nodes))] = slope
        color, _ = STYLE.get("implicit_euler", ("black", "o"))
        axis.plot(nodes, cost, color=color, marker=marker, linestyle=linestyle,
                  label="implicit_euler, %s at 1/60 s: slope %.3f" % (label, slope))
    axis.set_xscale("log")
    axis.set_yscale("log")
    axis.set_xlabel("nodes")
    axis.set_ylabel("CPU s per step")
    axis.set_title("Step cost against node count\n(cloths at dt = 0.2 ms; dashed, dotted: at 1/60 s)")
    axis.grid(True, which="major", linewidth=0.3)
    axis.legend(fontsize=9)
    figure.tight_layout()
    figure.savefig(os.path.join(out, "scaling.png"), dpi=90)
    plt.close(figure)
    return slopes, per_spring


def fmt(value, digits=3):
    try:
        v = float(value)
    except (TypeError, ValueError):
        return str(value)
    if math.isnan(v):
        return "–"
    return ("%." + str(digits) + "g") % v


def summary(out, slopes, per_spring):
    lines = []
    best = read_csv(os.path.join(out, "best_cost.csv"))
    rows = read_csv(os.path.join(out, "work_precision.csv"))
    levels = ["0.1", "0.01", "0.001", "0.0001", "1e-05", "1e-06"]
    lines.append("### Best cost at each error level [CPU s per simulated s]\n")
    lines.append("The cheapest configuration of each engine whose error is at most the level "
                 "(– = none reaches it; configuration as dt [s] / sub-steps / iterations, and for Bullet's "
                 "bending links their kLST).\n")
    tables = list(PANELS)
    for problem, title in ALL_NODES_PANELS:
        for n in sorted({int(r["n_nodes"]) for r in rows if r["problem"] == problem}):
            tables.append((problem, n, "%s, %d nodes" % (title, n)))
    for problem, nodes, title in tables:
        kinds = []
        for r in rows:
            if r["problem"] == problem and int(r["n_nodes"]) == nodes and r["error_kind"] not in kinds:
                kinds.append(r["error_kind"])
        if not kinds:
            continue
        kind = kinds[0]
        lines.append("**%s** (%s [%s])\n" % (title, kind.replace("_", " "), UNITS.get(kind, "")))
        lines.append("| engine | " + " | ".join("≤ " + fmt(level) for level in levels) + " |")
        lines.append("|---" * (len(levels) + 1) + "|")
        for engine in ENGINES:
            cells, seen = [], False
            for level in levels:
                match = [b for b in best if b["problem"] == problem and int(b["n_nodes"]) == nodes
                         and b["error_kind"] == kind and b["engine"] == engine and float(b["error_level"]) == float(level)]
                if match:
                    b = match[0]
                    seen = True
                    stiffness = ", kLST %s" % fmt(b["bending_kLST"]) if b.get("bending_kLST") else ""
                    cells.append("%s (%s/%s/%s%s)" % (fmt(b["cpu_s_per_sim_s"]), fmt(b["dt"]), b["substeps"],
                                                      b["iterations"], stiffness))
                else:
                    cells.append("–")
            if seen or any(r["integrator"] == engine and r["problem"] == problem for r in rows):
                lines.append("| %s | %s |" % ("Bullet" if engine == "bullet" else engine, " | ".join(cells)))
        lines.append("")
    ratios = read_csv(os.path.join(out, "ratios.csv"))
    if ratios:
        lines.append("### Hanging chain at max node error ≤ 1 mm: this package against Bullet\n")
        lines.append("| chain | nodes | ours: cost (engine, dt/sub-steps/iterations) | Bullet: cost (dt, piterations) "
                     "| ratio | ratio, both interpolated to 1 mm |")
        lines.append("|---|---|---|---|---|---|")
        for r in ratios:
            lines.append("| %s | %s | %s (%s, %s/%s/%s) | %s (%s, %s) | %s | %s |" % (
                r["problem"].replace("hanging_chain_", ""), r["n_nodes"], fmt(r["package_cost"]), r["package_engine"],
                fmt(r["package_dt"]), r["package_substeps"], r["package_iterations"], fmt(r["bullet_cost"]),
                fmt(r["bullet_dt"]), r["bullet_iterations"], fmt(r["ratio"]), fmt(r["ratio_interpolated"])))
        lines.append("")
    if per_spring or slopes:
        lines.append("### Cost per spring update and scaling (Google Benchmark, cloth)\n")
        lines.append("| measure | value |")
        lines.append("|---|---|")
        for name, ns in per_spring.items():
            lines.append("| %s, 10,000-node cloth | %.2f ns |" % (name, ns))
        for integrator, slope in slopes.items():
            lines.append("| log-log slope of step cost, %s | %.3f |" % (integrator, slope))
        lines.append("")
    memory = read_csv(os.path.join(out, "memory.csv"))
    if memory:
        lines.append("### Memory, cloth of 100,000 nodes\n")
        lines.append("| integrator | nodes | springs | heap bytes per node | resident now [MB] | peak resident [MB] |")
        lines.append("|---|---|---|---|---|---|")
        for m in memory:
            lines.append("| %s | %s | %s | %s | %s | %s |" % (m["integrator"], m["n_nodes"], m["n_springs"],
                                                          fmt(m["heap_bytes_per_node"], 4), m["rss_mb"], m["peak_rss_mb"]))
        lines.append("")
    demo = read_csv(os.path.join(out, "demo.csv"))
    if demo:
        d = demo[0]
        lines.append("### Demo scene\n")
        lines.append("%s nodes, %s, dt %s s x %s sub-steps: physics costs %s CPU s per simulated s (%.1f %% of one core)\n"
                     % (d["n_nodes"], d["integrator"], d["dt"], d["substeps"], fmt(d["cpu_s_per_sim_s"]),
                        100 * float(d["cpu_s_per_sim_s"])))
    with open(os.path.join(out, "summary.md"), "w") as f:
        f.write("\n".join(lines) + "\n")


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: plot_results.py OUT")
    out = sys.argv[1]
    rows = read_csv(os.path.join(out, "work_precision.csv"))
    plot_work_precision(rows, 0, os.path.join(out, "work_precision.png"))
    plot_work_precision(rows, 1, os.path.join(out, "work_precision_more.png"), ALL_NODES_PANELS)
    slopes, per_spring = scaling(out)
    summary(out, slopes, per_spring)
    print("plots and summary.md written to %s" % out)


if __name__ == "__main__":
    main()

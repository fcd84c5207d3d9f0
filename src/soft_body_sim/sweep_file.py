"""A sweep file read and checked, and the runs it asks for (docs/sweeps.md).

Every mistake is found before any run starts and reported as one line, `FILE:LINE: KEY: REASON`, as the
scene loader reports its own: an unknown key, a key path that does not lead into the scene, an empty grid
or an empty list of values, a value of another kind than the scene's, an unknown distribution.
"""
import dataclasses
import hashlib
import itertools
import json
import math
import os

import numpy as np
import yaml

from soft_body_sim import sim
from soft_body_sim.scene_edit import KeyPathError, Scene, kind, node_kind

TOP_KEYS = ("scene", "duration", "record_every", "grid", "random")
RANDOM_KEYS = ("count", "seed", "keys")
DISTRIBUTIONS = ("uniform", "log_uniform")


class SweepError(ValueError):
    """A sweep file that cannot be run: str() is one line, `FILE:LINE: KEY: REASON`."""


@dataclasses.dataclass(frozen=True)
class Run:
    """One run: its id (a hash of everything its result depends on) and its values by dotted key."""
    id: str
    values: dict


@dataclasses.dataclass
class Sweep:
    path: str           # the sweep file
    scene_path: str     # the base scene, absolute
    scene: Scene        # its text and node tree
    duration: float     # [s] simulated per run
    record_every: float  # [s] between samples; 0: the final state only
    keys: list          # the varied keys, grid's then random's, each once, in the file's order
    runs: list          # [Run], the grid's combinations then the random draws

    def run_scene(self, run):
        """The YAML text of a run's scene: the base scene's text with the run's values written in."""
        return self.scene.with_values(run.values)


def read_sweep(path):
    """The sweep of the file at `path`; SweepError, one line, for anything wrong with it."""
    path = os.fspath(path)
    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except OSError as e:
        raise SweepError(f"{path}: cannot open sweep file: {e.strerror}") from None
    try:
        root = yaml.compose(text)
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None)
        where = f"{path}:{mark.line + 1}" if mark else path
        raise SweepError(f"{where}: invalid YAML: {getattr(e, 'problem', e)}") from None
    return _Reader(path, root).sweep()


class _Reader:
    def __init__(self, path, root):
        self.path = path
        self.root = root

    def fail(self, node, key, reason):
        line = node.start_mark.line + 1 if node is not None else 1
        raise SweepError(f"{self.path}:{line}: {key}: {reason}")

    def mapping(self, node, key, allowed=None):
        if not isinstance(node, yaml.MappingNode):
            self.fail(node, key or "the sweep file", "expected a mapping of keys")
        items = {}
        for key_node, value_node in node.value:
            name = key_node.value
            dotted = f"{key}.{name}" if key else name
            if allowed is not None and name not in allowed:
                self.fail(key_node, dotted, f"unknown key; allowed keys: {', '.join(allowed)}")
            if name in items:
                self.fail(key_node, dotted, "given twice")
            items[name] = (key_node, value_node)
        return items

    def number(self, items, key, minimum, strict, default=None):
        if key not in items:
            if default is None:
                self.fail(self.root, key, "missing")
            return default
        node = items[key][1]
        if node_kind(node) != "number" or not math.isfinite(float(node.value)):
            self.fail(node, key, f"expected a number, got {node.value!r}")
        value = float(node.value)
        if value < minimum or (strict and value == minimum):
            self.fail(node, key, f"must be {'>' if strict else '>='} {minimum:g}, got {node.value}")
        return value

    def sweep(self):
        items = self.mapping(self.root, "", TOP_KEYS)
        if "scene" not in items:
            self.fail(self.root, "scene", "missing: the base scene file, relative to this file")
        scene_node = items["scene"][1]
        if node_kind(scene_node) != "string" or not scene_node.value:
            self.fail(scene_node, "scene", "expected a file name")
        scene_path = os.path.abspath(os.path.join(os.path.dirname(self.path), scene_node.value))
        try:
            with open(scene_path, encoding="utf-8") as f:
                scene_text = f.read()
            scene = Scene(scene_text, scene_path)
        except OSError as e:
            self.fail(scene_node, "scene", f"cannot open {scene_path}: {e.strerror}")
        except (yaml.YAMLError, KeyPathError) as e:
            self.fail(scene_node, "scene", f"{scene_path} is no scene file: {str(e).splitlines()[0]}")
        duration = self.number(items, "duration", 0.0, strict=True)
        record_every = self.number(items, "record_every", 0.0, strict=False, default=0.0)
        if "grid" not in items and "random" not in items:
            self.fail(self.root, "grid", "missing: a sweep needs a grid, random runs or both")

        keys, grid = [], {}
        if "grid" in items:
            grid_items = self.mapping(items["grid"][1], "grid")
            if not grid_items:
                self.fail(items["grid"][1], "grid", "empty: give at least one key with its values")
            for key, (key_node, values_node) in grid_items.items():
                grid[key] = self.grid_values(scene, f"grid.{key}", key, key_node, values_node)
                keys.append(key)
            try:  # keys that are each fine may still overlap: bodies.rope.from and bodies.rope.from.2
                scene.with_values({key: values[0] for key, values in grid.items()})
            except KeyPathError as e:
                self.fail(items["grid"][0], "grid", str(e))

        draws = []
        if "random" in items:
            draws = self.random_draws(scene, items["random"][1])
            keys += [key for key in (draws[0] if draws else {}) if key not in keys]

        values = [dict(zip(grid, combination)) for combination in itertools.product(*grid.values())] if grid else []
        identity = {"scene": scene_text, "duration": duration, "record_every": record_every}
        runs, seen = [], set()
        for run_values in values + draws:
            run = Run(run_id(identity, run_values), run_values)
            if run.id not in seen:  # a random draw that equals another run is that run
                seen.add(run.id)
                runs.append(run)
        return Sweep(self.path, scene_path, scene, duration, record_every, keys, runs)

    def check_key(self, scene, dotted, key, key_node, value):
        """The key's node in the base scene, or None if the scene leaves it at its default; fails naming the
        key if it does not lead into the scene, or if the loader does not know it (tried with `value`)."""
        try:
            target = scene.find(key)[2]
            text = scene.with_values({key: value})
        except (KeyPathError, ValueError) as e:
            self.fail(key_node, dotted, str(e))
        if target is None:
            # Only the loader knows which keys a mapping may have; any other complaint of its is about the
            # value, which makes that run fail and the others go on.
            try:
                sim.World.from_yaml(text, scene.source)
            except ValueError as e:
                if ": unknown key " in str(e):
                    self.fail(key_node, dotted, "unknown key " + str(e).split(": unknown key ", 1)[1])
        return target

    def grid_values(self, scene, dotted, key, key_node, values_node):
        if not isinstance(values_node, yaml.SequenceNode):
            self.fail(values_node, dotted, "expected a list of values")
        if not values_node.value:
            self.fail(values_node, dotted, "empty: give at least one value")
        target = self.check_key(scene, dotted, key, key_node, _python_value(values_node.value[0]))
        expected = node_kind(target) if target is not None else None
        values = []
        for node in values_node.value:
            value = _python_value(node)
            # The base scene says what kind a key holds; a key it leaves at its default, the first value.
            expected = expected or kind(value)
            if kind(value) != expected:
                self.fail(node, dotted, f"expected a {expected} as the scene's {key} is, got {node.value!r}")
            if value in values:
                self.fail(node, dotted, f"{node.value} given twice")
            values.append(value)
        return values

    def random_draws(self, scene, node):
        items = self.mapping(node, "random", RANDOM_KEYS)
        for required in RANDOM_KEYS:
            if required not in items:
                self.fail(node, f"random.{required}", "missing")
        count_node, seed_node = items["count"][1], items["seed"][1]
        for name, n in (("count", count_node), ("seed", seed_node)):
            if node_kind(n) != "number" or not _is_integer(n.value) or int(n.value) < 0:
                self.fail(n, f"random.{name}", f"expected an integer >= 0, got {n.value!r}")
        keys_items = self.mapping(items["keys"][1], "random.keys")
        if not keys_items:
            self.fail(items["keys"][1], "random.keys", "empty: give at least one key and its distribution")
        distributions = {}
        for key, (key_node, spec_node) in keys_items.items():
            dotted = f"random.keys.{key}"
            target = self.check_key(scene, dotted, key, key_node, 1.0)
            if target is not None and node_kind(target) != "number":
                self.fail(key_node, dotted, f"the scene's {key} is a {node_kind(target)}; only numbers are drawn")
            spec = self.mapping(spec_node, dotted)
            if len(spec) != 1 or next(iter(spec)) not in DISTRIBUTIONS:
                name_node = next(iter(spec.values()))[0] if spec else spec_node
                self.fail(name_node, dotted, f"expected one distribution of {', '.join(DISTRIBUTIONS)}, "
                          f"got {', '.join(spec) or 'none'}")
            (name, (_, bounds_node)), = spec.items()
            bounds = _python_value(bounds_node)
            if (kind(bounds) != "list" or len(bounds) != 2 or any(kind(b) != "number" for b in bounds)
                    or not all(math.isfinite(b) for b in bounds) or not bounds[0] < bounds[1]):
                self.fail(bounds_node, f"{dotted}.{name}", "expected [low, high], two finite numbers, low < high")
            if name == "log_uniform" and not bounds[0] > 0:
                self.fail(bounds_node, f"{dotted}.{name}", "expected low > 0 (it draws log(value) uniformly)")
            distributions[key] = (name, float(bounds[0]), float(bounds[1]))
        # One generator for the sweep, keys drawn in the file's order run after run: the same file draws the
        # same values on any machine (numpy's PCG64 is fixed across versions for a seed).
        rng = np.random.default_rng(int(seed_node.value))
        draws = []
        for _ in range(int(count_node.value)):
            draw = {}
            for key, (name, low, high) in distributions.items():
                if name == "uniform":
                    draw[key] = float(rng.uniform(low, high))
                else:
                    draw[key] = float(math.exp(rng.uniform(math.log(low), math.log(high))))
            draws.append(draw)
        return draws


def run_id(identity, values):
    """16 hex digits of a SHA-256 of all a run's result depends on: the base scene's text, duration,
    record_every and the run's values. A changed scene or sweep makes new ids; the same values the same."""
    text = json.dumps({**identity, "values": values}, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _is_integer(text):
    return text.lstrip("+-").isdigit()


def _python_value(node):
    """A sweep file's value as the scene loader would read it: numbers by YAML 1.2 (`1e3` is 1000.0)."""
    if isinstance(node, yaml.SequenceNode):
        return [_python_value(item) for item in node.value]
    if isinstance(node, yaml.MappingNode):
        return {key.value: _python_value(value) for key, value in node.value}
    k = node_kind(node)
    if k == "number":
        return int(node.value) if _is_integer(node.value) else float(node.value)
    if k == "boolean":
        return node.value.lower() == "true"
    if k == "null":
        return None
    return node.value

"""A sweep's output folder: runs.h5, every finished run's values, status and samples, and runs.csv, a row a
run (docs/sweeps.md). Only the client writes them, the runs of a task as it arrives, and flushes them after
each task: a sweep stopped at any point holds every run it had received, and a run is written once whatever
Dask retried. runs.csv is made again from runs.h5 when a sweep starts and ends, so the two always agree.
"""
import csv
import datetime
import hashlib
import json
import os

import h5py
import numpy as np

FIXED_COLUMNS_BEFORE = ["id"]
FIXED_COLUMNS_AFTER = ["status", "divergence_events", "cpu_seconds", "worker", "message"]


SCALAR = h5py.h5s.create(h5py.h5s.SCALAR)


def write_attrs(obj, attrs):
    """Sets `attrs` (str, int, float or bool values) on the new h5py group or dataset `obj`, as its .attrs[name]
    = value would, through h5py's low-level calls: a third of the cost (the high-level call checks and
    converts each value in Python), and a run has a dozen attributes."""
    for name, value in attrs.items():
        data = np.array(value, dtype=h5py.string_dtype() if isinstance(value, str) else None)
        h5py.h5a.create(obj.id, name.encode(), h5py.h5t.py_create(data.dtype, logical=True), SCALAR).write(data)


class Store:
    def __init__(self, folder, sweep):
        os.makedirs(folder, exist_ok=True)
        self.h5_path = os.path.join(folder, "runs.h5")
        self.csv_path = os.path.join(folder, "runs.csv")
        self.sweep = sweep
        try:
            self.h5 = h5py.File(self.h5_path, "a")
        except OSError as e:
            raise OSError(f"{self.h5_path}: cannot open for writing ({e}); a sweep still running into it, or "
                          "a file cut short by a crash (delete it to start again)") from None
        self.runs = self.h5.require_group("runs")
        self.names = self.h5.require_group("names")
        self.names_by_key = {}
        self.h5.attrs["sweep"] = os.path.abspath(sweep.path)
        self.h5.attrs["scene"] = sweep.scene_path
        self.h5.attrs["duration"] = sweep.duration
        self.h5.attrs["record_every"] = sweep.record_every
        self.columns = FIXED_COLUMNS_BEFORE + sweep.keys + FIXED_COLUMNS_AFTER
        self.write_csv()
        self.csv_file = open(self.csv_path, "a", newline="")
        self.csv = csv.writer(self.csv_file)

    def done(self):
        """The ids of the runs already written (of this sweep file or an earlier one)."""
        return set(self.runs.keys())

    def add(self, result):
        """Writes one run's result; a run already written (Dask ran it twice) is left as it is."""
        if result["id"] in self.runs:
            return False
        group = self.runs.create_group(result["id"])
        attrs = {"values": json.dumps(result["values"])}
        for key, value in result["values"].items():
            attrs[key] = value if isinstance(value, (int, float, str)) else json.dumps(value)
        for name in ("status", "message", "divergence_events", "cpu_seconds", "worker"):
            attrs[name] = result[name]
        attrs["finished"] = datetime.datetime.now(datetime.timezone.utc).isoformat()
        write_attrs(group, attrs)
        if "time" in result:
            for name, unit in (("time", "s"), ("positions", "m"), ("tensions", "N"),
                               ("wrenches", "N (force x, y, z), N m (torque x, y, z, about the anchor's node)")):
                write_attrs(group.create_dataset(name, data=result[name]), {"unit": unit})
            for name in ("node_names", "tension_bodies", "anchor_names"):
                group[name] = self.shared_names(result[name])
        self.csv.writerow(self.row(result["id"], result["values"], result))  # from memory: h5 reads cost ms
        return True

    def flush(self):
        """Everything added so far to the files (runs.csv's rows are never ahead of runs.h5's runs)."""
        self.h5.flush()
        self.csv_file.flush()

    def shared_names(self, names):
        """The dataset names/<key> of the list `names`, written the first time: the runs that name the same
        nodes (most of a sweep's) link to one dataset (an HDF5 hard link: read as the run's own), which costs
        a fraction of writing it again."""
        key = hashlib.sha256(json.dumps(names).encode()).hexdigest()[:16]
        dataset = self.names_by_key.get(key)
        if dataset is None:
            dataset = self.names[key] if key in self.names else \
                self.names.create_dataset(key, data=np.array(names, dtype=h5py.string_dtype()))
            self.names_by_key[key] = dataset
        return dataset

    def row(self, run_id, values, fixed):
        """runs.csv's row of a run: its values, then FIXED_COLUMNS_AFTER taken from `fixed`."""
        fields = {"id": run_id,
                  **{k: v if isinstance(v, (int, float, str)) else json.dumps(v) for k, v in values.items()}}
        for name in FIXED_COLUMNS_AFTER:
            fields[name] = repr(float(fixed[name])) if name == "cpu_seconds" else fixed[name]
        return [fields.get(column, "") for column in self.columns]

    def write_csv(self):
        """runs.csv afresh: a row for each of this sweep's runs in runs.h5, in the sweep's order."""
        with open(self.csv_path, "w", newline="") as f:
            writer = csv.writer(f)
            writer.writerow(self.columns)
            for run in self.sweep.runs:
                if run.id in self.runs:
                    attrs = self.runs[run.id].attrs
                    writer.writerow(self.row(run.id, json.loads(attrs["values"]), attrs))

    def close(self):
        self.csv_file.close()
        self.write_csv()
        self.h5.close()

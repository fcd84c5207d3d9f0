"""python3 -m soft_body_sim.sweep SWEEP.yaml --out FOLDER [--scheduler tcp://HOST:8786] [--workers N]

Runs every run of a sweep file (docs/sweeps.md) on Dask: a local cluster of one single-threaded worker
process per core, or an existing cluster's scheduler. Results go to FOLDER/runs.h5 and FOLDER/runs.csv as the
runs finish; the same command after a stop runs only the runs FOLDER does not hold yet.
"""
import argparse
import collections
import logging
import os
import sys
import time

import dask
import distributed

from soft_body_sim import sweep_run
from soft_body_sim.sweep_file import SweepError, read_sweep
from soft_body_sim.sweep_store import Store

# A task that raises is tried this many times more (a worker that dies is another matter: the scheduler
# gives its tasks to the others, up to distributed.scheduler.allowed-failures deaths per task). A run's
# own errors (a refused scene) are results, not exceptions, so only the unexpected is retried.
RETRIES = 2

# Runs go to Dask in tasks of several runs, aimed at TASK_SECONDS of CPU each: a task costs the client and the
# scheduler about 5 ms of CPU (bench/bench_sweep.py), which on a 2-core machine is CPU the workers do not get;
# at 0.5 s a task that is 1 %. The first tasks hold a run each, and the first run to step sets the size of the
# rest; the last tasks shrink to a run each, so that no worker waits on another's long task at the end.
TASK_SECONDS = 0.5
MAX_RUNS_PER_TASK = 16
# Tasks a worker thread is given at the end (from the rest of the runs, at most one run each); also the number
# of one-run tasks a thread is given first, while the size of the rest is not known.
TAIL_TASKS_PER_THREAD = 4


class Progress:
    """A progress bar on stderr: redrawn in place on a terminal, a line every tenth of the runs otherwise."""

    def __init__(self, total, stream):
        self.total, self.done, self.failed = total, 0, 0
        self.stream = stream
        self.tty = stream.isatty()
        self.started = time.monotonic()
        self.shown_tenth = -1

    def update(self, failed):
        self.done += 1
        self.failed += failed
        tenth = 10 * self.done // max(self.total, 1)
        if not self.tty and tenth == self.shown_tenth and self.done != self.total:
            return
        self.shown_tenth = tenth
        width = 30
        filled = width * self.done // max(self.total, 1)
        elapsed = time.monotonic() - self.started
        line = (f"sweep: [{'#' * filled}{'.' * (width - filled)}] {self.done}/{self.total} runs, "
                f"{self.failed} failed, {elapsed:.0f} s")
        self.stream.write(("\r" + line if self.tty else line + "\n"))
        if self.tty and self.done == self.total:
            self.stream.write("\n")
        self.stream.flush()


# The local cluster's housekeeping, made rarer than Dask's defaults: at those, an idle cluster of two workers
# keeps 12 % of a core busy (each worker sampling its own stack for the dashboard's profile, every 10 ms, and
# measuring its memory every 0.1 s; the scheduler ticking every 20 ms and measuring the machine every 0.5 s),
# which on a 2-core machine the runs do not get; at these, 4 % (bench/bench_sweep.py). The cluster has no
# dashboard to show them; a worker still checks its memory limit every second.
LOCAL_CLUSTER_CONFIG = {
    "distributed.worker.profile.enabled": False,
    "distributed.worker.memory.monitor-interval": "1s",
    "distributed.admin.tick.interval": "1s",
    "distributed.admin.system-monitor.interval": "5s",
    "distributed.scheduler.active-memory-manager.start": False,
}


def make_client(scheduler, workers):
    """A Dask client: of the scheduler at `scheduler`, or of a local cluster of `workers` processes with one
    thread each (a run keeps one core busy for its whole length, and a process per worker keeps a crash in
    one run to that worker)."""
    if scheduler:
        return distributed.Client(scheduler), None
    with dask.config.set(LOCAL_CLUSTER_CONFIG):
        cluster = distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                           dashboard_address=None, silence_logs=logging.ERROR)
        return distributed.Client(cluster), cluster


def specs_of(sweep, runs):
    return [sweep_run.RunSpec(run.id, run.values, sweep.run_scene(run), sweep.scene_path, sweep.duration,
                              sweep.record_every) for run in runs]


class Tasks:
    """The runs of `specs` as Dask tasks on `client`, sized as TASK_SECONDS says; iterated, each task as it
    finishes (in any order): its future, its runs and their results (None if the task failed), fetched once."""

    def __init__(self, client, specs):
        self.client = client
        self.pending = collections.deque(specs)
        self.runs_of = {}
        self.finished = distributed.as_completed()
        self.threads = max(1, sum(client.nthreads().values()))
        self.runs_per_task = None
        for _ in range(min(len(self.pending), TAIL_TASKS_PER_THREAD * self.threads)):
            self.submit(1)

    def submit(self, count):
        runs = [self.pending.popleft() for _ in range(count)]
        future = self.client.submit(sweep_run.run_batch, runs, key=f"soft_body_sim-runs-{runs[0].id}-{count}",
                                    retries=RETRIES, pure=False)
        self.runs_of[future.key] = runs
        self.finished.add(future)

    def size_the_rest(self, run_seconds):
        """The rest of the runs in tasks of TASK_SECONDS at `run_seconds` [s] a run (None: unknown, a run a
        task), fewer near the end."""
        self.runs_per_task = 1 if run_seconds is None else \
            max(1, min(MAX_RUNS_PER_TASK, int(TASK_SECONDS / max(run_seconds, 1e-6))))
        while self.pending:
            tail = len(self.pending) // (TAIL_TASKS_PER_THREAD * self.threads)
            self.submit(max(1, min(self.runs_per_task, tail)))

    def __iter__(self):
        for future in self.finished:
            runs = self.runs_of.pop(future.key)
            results = None if future.status == "error" else future.result()
            if self.runs_per_task is None:
                stepped = [result["cpu_seconds"] for result in results or [] if "time" in result]
                if stepped or self.finished.is_empty():
                    self.size_the_rest(max(stepped) if stepped else None)
            yield future, runs, results


def run_sweep(sweep, out, scheduler=None, workers=None, stream=None, client=None):
    """Runs what `out` does not hold yet of `sweep`; the number of runs lost (a task Dask gave up on). On
    `client` if given (left open), else on a client of make_client(scheduler, workers), closed after.
    Progress goes to `stream` (default: sys.stderr as it is at the call)."""
    stream = sys.stderr if stream is None else stream
    store = Store(out, sweep)
    try:
        done = store.done()
        todo = [run for run in sweep.runs if run.id not in done]
        stream.write(f"sweep: {len(sweep.runs)} runs, {len(sweep.runs) - len(todo)} already in {out}, "
                     f"{len(todo)} to run\n")
        if not todo:
            return 0
        specs = specs_of(sweep, todo)
        own = client is None
        if own:
            client, cluster = make_client(scheduler, workers or len(os.sched_getaffinity(0)))
        try:
            progress = Progress(len(specs), stream)
            lost = []
            # Written here as each task finishes, and flushed, never by the workers: a task Dask retried or ran
            # on two workers arrives once per future, and store.add keeps the first.
            for future, runs, results in Tasks(client, specs):
                if results is None:
                    lost += [f"{run.id}: {future.exception()}" for run in runs]
                    for _ in runs:
                        progress.update(failed=True)
                else:
                    for result in results:
                        store.add(result)
                        progress.update(failed=result["status"] != "ok")
                    store.flush()
                future.release()
            for line in lost:
                stream.write(f"sweep: lost {line}\n")
            if lost:
                stream.write(f"sweep: {len(lost)} runs lost; the same command again runs them\n")
            return len(lost)
        finally:
            if own:
                client.close()
                if cluster is not None:
                    cluster.close()
    finally:
        store.close()


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python3 -m soft_body_sim.sweep", description=__doc__.split("\n\n")[1])
    parser.add_argument("sweep", help="the sweep file (YAML, docs/sweeps.md)")
    parser.add_argument("--out", help="the output folder: runs.h5, runs.csv")
    parser.add_argument("--scheduler", help="an existing Dask scheduler, tcp://HOST:8786 (default: a local cluster)")
    parser.add_argument("--workers", type=int, help="the local cluster's worker processes (default: one per core)")
    parser.add_argument("--scene-of", metavar="ID", help="print the scene of run ID (as simulate --scene reads it) "
                        "and exit")
    args = parser.parse_args(argv)
    if args.workers is not None and args.workers < 1:
        parser.error(f"--workers: must be >= 1, got {args.workers}")
    try:
        sweep = read_sweep(args.sweep)
    except SweepError as e:
        print(e, file=sys.stderr)
        return 2
    if args.scene_of:
        runs = {run.id: run for run in sweep.runs}
        if args.scene_of not in runs:
            print(f"{args.sweep}: no run {args.scene_of!r} in this sweep ({len(runs)} runs; ids in runs.csv)",
                  file=sys.stderr)
            return 2
        sys.stdout.write(sweep.run_scene(runs[args.scene_of]))
        return 0
    if not args.out:
        parser.error("--out is required")
    return 1 if run_sweep(sweep, args.out, args.scheduler, args.workers) else 0


if __name__ == "__main__":
    sys.exit(main())

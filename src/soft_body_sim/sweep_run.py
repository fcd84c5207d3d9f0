"""One run of a sweep, as a Dask worker (or this process) does it: a scene's text loaded by the package's
loader, stepped by the core, sampled (docs/sweeps.md). It depends on nothing but its arguments, so a retry
on another worker gives the same bits, and so does `simulate` of the same text written to a file.
"""
import dataclasses
import math
import time

import distributed
import numpy as np

from soft_body_sim import sim

# The guard's last resort (World::treatDiverged): a body it freezes has stopped being simulated, so the
# run's result is no longer the scene's; every earlier remedy (another integrator, a halved sub-step) is.
GAVE_UP = "frozen (its free nodes pinned at rest)"


@dataclasses.dataclass
class RunSpec:
    id: str
    values: dict
    text: str           # the run's scene, YAML
    source: str         # the base scene's path: meshes by a relative path are found from its folder
    duration: float     # [s]
    record_every: float  # [s]; 0: the final state only


def steps_of(duration, dt):
    """The steps of `duration` [s] at `dt` [s], rounded half away from zero as simulate's llround does."""
    return int(math.floor(duration / dt + 0.5))


def worker_name():
    """The Dask worker's address, or "in-process" for a run outside Dask."""
    try:
        return distributed.get_worker().address
    except ValueError:
        return "in-process"


def run(spec):
    """A dict of the run's result: status ("ok", "failed": the loader or the world refused the scene,
    "diverged": the guard froze a body), message, divergence_events, cpu_seconds, worker, and for a run
    that stepped, its samples: time (S,), positions (S, N, 3), tensions (S, L), wrenches (S, A, 6) with the
    names of the nodes, the tensions' bodies and the anchors."""
    started = time.thread_time()  # the step runs in this thread (it releases the GIL, not the thread)
    result = {"id": spec.id, "values": spec.values, "worker": worker_name(), "status": "ok",
              "message": "", "divergence_events": 0}
    try:
        world = sim.World.from_yaml(spec.text, spec.source)
    except ValueError as e:  # sim.SceneError (the loader's line) or what buildWorld refuses
        result.update(status="failed", message=str(e), cpu_seconds=time.thread_time() - started)
        return result

    bodies = world.bodies
    anchors = [(body, anchor) for body in bodies for anchor in world.anchors(body)]
    steps = steps_of(spec.duration, world.dt)
    # Samples at step 0 and every `every` steps, and the last step, as simulate --every writes its rows.
    every = max(1, steps_of(spec.record_every, world.dt)) if spec.record_every > 0 else None
    times, positions, tensions, wrenches = [], [], [], []

    def sample():
        times.append(world.time)
        positions.append(world.positions())
        tensions.append(np.concatenate([world.tensions(body) for body in bodies]))
        wrenches.append(np.array([np.concatenate(world.wrench(body, anchor)) for body, anchor in anchors])
                        .reshape(len(anchors), 6))

    catches = []
    if every is None:
        world.step(steps)
        catches += [str(event) for event in world.divergence_events]
        sample()
    else:
        sample()
        done = 0
        while done < steps:  # chunks of `every` steps, the last one shorter: it ends at `steps`
            n = min(every, steps - done)
            world.step(n)
            done += n
            catches += [str(event) for event in world.divergence_events]
            sample()
    gave_up = [c for c in catches if c.endswith(GAVE_UP)]
    result.update(
        status="diverged" if gave_up else "ok",
        message=gave_up[0] if gave_up else "",
        divergence_events=len(catches),
        time=np.array(times),
        positions=np.array(positions).reshape(len(times), -1, 3),
        tensions=np.array(tensions).reshape(len(times), -1),
        wrenches=np.array(wrenches).reshape(len(times), len(anchors), 6),
        node_names=[f"{body}/{k}" for body in bodies for k in range(world.positions(body).shape[0])],
        tension_bodies=[body for body in bodies for _ in range(world.tensions(body).shape[0])],
        anchor_names=[f"{body}/{anchor}" for body, anchor in anchors],
        cpu_seconds=time.thread_time() - started)
    return result


def run_batch(specs):
    """The results of `specs`, run one after another (a Dask task of several runs: sweep.TASK_SECONDS)."""
    return [run(spec) for spec in specs]

"""What the tests of soft_body_sim.sim share: the package's folders, the headless simulator and an exact
comparison of arrays."""
import pathlib

import numpy as np
import pytest
from catkin.find_in_workspaces import find_in_workspaces

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCENES = ROOT / "config" / "scenes"


def same_bits(a, b):
    """True if two float64 arrays hold the same bits (np.array_equal takes -0.0 for 0.0)."""
    a, b = np.ascontiguousarray(a, dtype=np.float64), np.ascontiguousarray(b, dtype=np.float64)
    return a.shape == b.shape and np.array_equal(a.view(np.uint64), b.view(np.uint64))


@pytest.fixture(scope="session")
def simulate():
    """The path of the headless simulator that this devel space built."""
    found = find_in_workspaces(search_dirs=["libexec"], project="soft_body_sim", path="simulate",
                               first_match_only=True)
    if not found:
        pytest.fail("the headless simulator `simulate` is not built (make simulate)")
    return found[0]

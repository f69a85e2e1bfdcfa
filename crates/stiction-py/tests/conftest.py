"""Shared fixtures: the repository's example loops, the CLI binary, small simulated fleets."""

import os
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import stiction

ROOT = Path(__file__).resolve().parents[3]
EXAMPLES = ROOT / "examples" / "data"


def cli_binary():
    """The `stiction` CLI: $STICTION_BIN, else target/debug or target/release, else on PATH."""
    given = os.environ.get("STICTION_BIN")
    if given:
        return given
    for profile in ("debug", "release"):
        p = ROOT / "target" / profile / "stiction"
        if p.exists():
            return str(p)
    return shutil.which("stiction")


@pytest.fixture(scope="session")
def cli():
    path = cli_binary()
    if path is None:
        pytest.skip("no stiction CLI binary: build it (cargo build) or set STICTION_BIN")
    return path


@pytest.fixture(scope="session")
def sticky_csv():
    return EXAMPLES / "sticky_loop.csv"


@pytest.fixture(scope="session")
def healthy_csv():
    return EXAMPLES / "healthy_loop.csv"


def simulated_loop(d, seed, samples=1000, disturbance=None):
    """A PI loop with a Stenman valve of band d (closed loop, PV noise 0.05)."""
    return stiction.simulate(
        "stenman", "closed", d=d, noise=0.05, seed=seed, samples=samples, disturbance=disturbance
    )


@pytest.fixture(scope="session")
def fleet():
    """Four loops in one long frame: two sticky, one healthy, one with a text cell (fails)."""
    parts = []
    for loop_id, d, seed, dist in [
        ("FIC101", 2.0, 3, None),
        ("FIC102", 0.0, 4, "sine:amplitude=0.5,period=80"),
        ("LIC201", 4.0, 5, None),
        ("TIC301", 1.0, 6, None),
    ]:
        df = simulated_loop(d, seed, samples=800, disturbance=dist)
        df.insert(0, "loop_id", loop_id)
        parts.append(df)
    frame = pd.concat(parts, ignore_index=True)
    frame["op"] = frame["op"].astype(object)
    bad_row = frame.index[frame["loop_id"] == "TIC301"][10]
    frame.loc[bad_row, "op"] = "abc"
    return frame

"""``diagnose_many``: a fleet of loops in one long DataFrame, diagnosed in parallel in Rust."""

from __future__ import annotations

import json
from typing import Any, Dict, List, Optional, Tuple

import numpy as np
import pandas as pd

from . import _stiction as _native
from ._signals import TIME_NAMES, StictionError, modes, numbers, require, seconds

#: The columns of ``diagnose_many``'s result, in order: the fleet row of ``stiction batch``'s
#: summary (the core's ``fleet::Row``).
FLEET_COLUMNS = [
    "loop_id",
    "source",
    "verdict",
    "probability",
    "severity",
    "band_percent_of_span",
    "band_source",
    "ellipse_percent_of_span",
    "small_band_percent_of_span",
    "period_s",
    "regularity",
    "reason",
    "samples",
    "seconds",
    "error",
]

#: ``diagnose_many``'s columns: :data:`FLEET_COLUMNS`, then ``same_period_loops``, the other loops
#: of the call that oscillate regularly at the loop's period (within 10 %), as ``stiction batch``'s
#: summary counts them (not in the Spark front end, which judges each loop apart).
MANY_COLUMNS = FLEET_COLUMNS + ["same_period_loops"]


def _signal(
    frame: pd.DataFrame, name: Optional[str], arg: str, role: str, order: np.ndarray, kind: str,
    bad: Dict[int, str], group_of_row: np.ndarray,
) -> Optional[np.ndarray]:
    """One signal of every loop, rows in loop order; a cell that cannot be read fails its loop
    only (its message in ``bad``), not the call."""
    if name is None:
        return None
    col = require(frame, name, arg, role).iloc[order]
    read = modes if kind == "mode" else (lambda s, n: numbers(s, n, role))
    try:
        return read(col, name)
    except StictionError:
        pass
    # find the loops whose cells cannot be read, cell by cell, and read the others
    out = np.zeros(len(col), dtype=bool) if kind == "mode" else np.full(len(col), np.nan)
    values = col.reset_index(drop=True)
    for k in range(len(values)):
        try:
            out[k] = read(values.iloc[k : k + 1], name)[0]
        except StictionError as e:
            g = int(group_of_row[k])
            if g not in bad:
                label = f"row {col.index[k]!r}"
                bad[g] = f"{label}, column '{name}': {str(e).split(': ', 1)[-1]}"
    return out


def _groups(frame: pd.DataFrame, by: str) -> Tuple[List[Any], np.ndarray, np.ndarray]:
    """The loop ids (in order of first appearance), the row order that puts each loop's rows
    together (stable: a loop's rows keep their order), and each loop's first row in that order."""
    key = require(frame, by, "by", "loop id")
    codes, uniques = pd.factorize(key, sort=False, use_na_sentinel=True)
    if (codes < 0).any():
        k = int(np.argmax(codes < 0))
        raise StictionError(f"row {frame.index[k]!r}, column '{by}': the loop id is missing; every row needs one")
    order = np.argsort(codes, kind="stable")
    counts = np.bincount(codes, minlength=len(uniques))
    starts = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    return list(uniques), order, starts


def diagnose_many(
    df: pd.DataFrame,
    by: str = "loop_id",
    op: str = "op",
    pv: str = "pv",
    sp: Optional[str] = None,
    mode: Optional[str] = None,
    mv: Optional[str] = None,
    ts: Optional[float] = None,
    integrating: Optional[bool] = None,
    quantify: bool = True,
    *,
    time: Optional[str] = None,
    op_range: Tuple[float, float] = (0.0, 100.0),
    estimate_start: bool = False,
    thorough: bool = False,
    threads: Optional[int] = None,
    progress: bool = True,
) -> pd.DataFrame:
    """Diagnose every loop of a long DataFrame (one row per sample, ``by`` names the loop), in
    parallel in Rust with the GIL released, on a pool of ``threads`` (default: one per core).

    Returns one row per loop (columns :data:`MANY_COLUMNS`: ``stiction batch``'s summary),
    ranked as ``batch`` ranks: severity (band x the probability of a sticky valve) first, then the verdict, then the
    loop id. A loop that cannot be read or diagnosed is a ``failed`` row with its reason; the
    others go on. The result does not depend on ``threads`` (only ``seconds``, the time each
    diagnosis took, varies). Time: the ``time`` column, else a DatetimeIndex, else a column
    t / time / timestamp, else ``ts`` (default 1 s). ``progress``: a line on standard error.
    """
    if not isinstance(df, pd.DataFrame):
        raise StictionError(f"df must be a pandas DataFrame; got {type(df).__name__}")
    if threads is not None and threads < 1:
        raise StictionError(f"threads={threads}: give at least 1 thread, or None for one per core")
    ids, order, starts = _groups(df, by)
    group_of_row = np.repeat(np.arange(len(ids)), np.diff(starts))
    bad: Dict[int, str] = {}
    args = dict(order=order, bad=bad, group_of_row=group_of_row)
    sig = {
        "op": _signal(df, op, "op", "controller output op", kind="number", **args),
        "pv": _signal(df, pv, "pv", "process variable pv", kind="number", **args),
        "sp": _signal(df, sp, "sp", "setpoint sp", kind="number", **args),
        "mv": _signal(df, mv, "mv", "valve position mv", kind="number", **args),
        "auto": _signal(df, mode, "mode", "controller mode", kind="mode", **args),
    }
    time_name = "time"
    t = None
    if time is not None:
        t, time_name = seconds(require(df, time, "time", "time").iloc[order], time), time
    elif isinstance(df.index, pd.DatetimeIndex):
        t, time_name = seconds(df.index[order], "index"), "index"
    else:
        found = next((c for c in TIME_NAMES if c in df.columns and c != by), None)
        if found is not None:
            t, time_name = seconds(df[found].iloc[order], found), found
    names = [str(i) for i in ids]
    sources = [f"{by}={n}" for n in names]
    text = _native.diagnose_many(
        names, sources, starts.tolist(), sig["op"], sig["pv"], sp=sig["sp"], mv=sig["mv"],
        auto=sig["auto"], time=t, ts=ts, integrating=integrating, quantify=quantify,
        tags=[c for c in (pv, op) if isinstance(c, str)],
        op_range=tuple(op_range), estimate_start=estimate_start, thorough=thorough, time_name=time_name,
        threads=threads, progress=progress, failed={g: f"{sources[g]}: {w}" for g, w in bad.items()},
    )
    rows = json.loads(text)
    out = pd.DataFrame(rows, columns=MANY_COLUMNS)
    # the loop ids as they were in the frame (numbers stay numbers)
    original = dict(zip(names, ids))
    out["loop_id"] = [original[i] for i in out["loop_id"]]
    return out

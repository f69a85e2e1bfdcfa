"""``report``: one loop's self-contained HTML page, the page ``stiction report`` writes."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import Any, Dict, Optional, Tuple, Union

import pandas as pd

from . import _stiction as _native
from ._signals import StictionError, loop_columns


def _target(path: Any) -> Path:
    """The file to write, or a sentence on why it cannot be written there."""
    if path is None:
        raise StictionError("path= is required: the HTML file to write, e.g. path='loop.html'")
    try:
        target = Path(os.fspath(path))
    except TypeError:
        raise StictionError(f"path= is a file name; got {type(path).__name__}") from None
    if target.is_dir():
        raise StictionError(f"path='{target}' is a folder; give the HTML file to write, e.g. '{target / 'loop.html'}'")
    folder = target.parent
    if not folder.is_dir():
        raise StictionError(f"path='{target}': the folder '{folder}' does not exist; create it or write elsewhere")
    return target


def _write(target: Path, html: str) -> None:
    """Write the page whole or not at all: a temporary file in the same folder, then a rename."""
    fd, tmp = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="") as f:
            f.write(html)
        os.replace(tmp, target)
    except OSError as e:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise StictionError(f"path='{target}': the report cannot be written: {e.strerror or e}") from None


def _names(data: Any, op: Any, pv: Any, sp: Any, mode: Any, time: Any) -> Optional[Dict[str, str]]:
    """The column names for the page's header (as the CLI names its column flags), when the
    signals are columns of a DataFrame."""
    if not isinstance(data, pd.DataFrame):
        return None
    # a MultiIndex column's tuple in words: FIC101 / op
    label = lambda v: v if isinstance(v, str) else " / ".join(map(str, v))
    names = {"op": label(op), "pv": label(pv)}
    if sp is not None:
        names["sp"] = label(sp)
    if mode is not None:
        names["mode"] = label(mode)
    if isinstance(time, (str, tuple)):
        names["time"] = label(time)
    elif time is None and isinstance(data.index, pd.DatetimeIndex):
        names["time"] = "index"
    return names


def report(
    data: Optional[pd.DataFrame] = None,
    op: Any = "op",
    pv: Any = "pv",
    sp: Any = None,
    mode: Any = None,
    mv: Any = None,
    ts: Optional[float] = None,
    integrating: Optional[bool] = None,
    window: Optional[int] = None,
    path: Union[str, "os.PathLike[str]", None] = None,
    *,
    quantify: bool = True,
    name: Optional[str] = None,
    time: Any = None,
    op_range: Tuple[float, float] = (0.0, 100.0),
    estimate_start: bool = False,
    thorough: bool = False,
) -> Path:
    """Diagnose one loop and write its report to ``path``: one self-contained HTML page (inline
    SVG charts and CSS, no scripts or network references), the page ``stiction report`` writes,
    rendered by the same code: trends, the PV-OP plot with the fitted model, every index with
    its vote, the oscillation, the estimates, the data-quality gates, the verdict per window
    (with ``window=``) and the caveat. Returns the path written.

    Data and settings as for :func:`stiction.diagnose` (``quantify=False`` skips the closed-loop
    estimate). path: the HTML file (written whole or not at all; its folder must exist).
    name: the loop's name in the title (default: the file name of ``path`` without .html).
    The page differs from run to run of the same loop only in the times the diagnosis and the
    estimate took.
    """
    target = _target(path)
    if op is None:
        op = "op"
    cols, time_name = loop_columns(data, op, pv, sp=sp, mode=mode, mv=mv, time=time)
    html = _native.report(
        cols["op"], cols["pv"], sp=cols["sp"], mv=cols["mv"], auto=cols["auto"], time=cols["time"],
        ts=ts, integrating=integrating, window=window, quantify=quantify,
        op_range=tuple(op_range), estimate_start=estimate_start, thorough=thorough, time_name=time_name,
        loop_id=target.stem if name is None else str(name),
        columns=_names(data, op, pv, sp, mode, time),
    )
    _write(target, html)
    return target

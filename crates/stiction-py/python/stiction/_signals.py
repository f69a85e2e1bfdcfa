"""From pandas and numpy to the float64 arrays the native module reads.

Only conversion lives here: which column is which, the time axis in seconds, text cells read
as numbers or controller modes. Each mistake is one sentence naming the column, the row and the
fix, raised as :class:`stiction.StictionError` (a ``ValueError``).
"""

from __future__ import annotations

from typing import Any, Dict, List, Optional, Tuple

import numpy as np
import pandas as pd

from . import _stiction as _native

StictionError = _native.StictionError

TIME_NAMES = tuple(_native.TIME_NAMES)  # stiction_core::record::TIME_NAMES


def require(df: pd.DataFrame, name: str, arg: str, role: str) -> pd.Series:
    """The column ``name``, or a sentence naming the columns there are."""
    if name in df.columns:
        col = df[name]
        if isinstance(col, pd.DataFrame):
            raise StictionError(
                f"{arg}='{name}': the DataFrame has {col.shape[1]} columns named '{name}'; "
                "rename them so each name is used once"
            )
        return col
    have = ", ".join(str(c) for c in df.columns)
    raise StictionError(
        f"no column '{name}' for the {role}; the columns are {have}. "
        f"Name the right one with {arg}='COLUMN'"
    )


def _row_label(series: pd.Series, k: int) -> str:
    return f"row {series.index[k]!r}" if len(series.index) > k else f"row {k}"


def _cells(series: pd.Series) -> List[Optional[str]]:
    out: List[Optional[str]] = []
    for v in series.tolist():
        if v is None or (isinstance(v, float) and v != v) or v is pd.NA or v is pd.NaT:
            out.append(None)
        else:
            out.append(str(v))
    return out


def numbers(series: Any, name: str, role: str) -> np.ndarray:
    """A signal as contiguous float64 (a view when it already is one); gaps are NaN."""
    if isinstance(series, pd.Series):
        if pd.api.types.is_bool_dtype(series.dtype) or pd.api.types.is_numeric_dtype(series.dtype):
            return np.ascontiguousarray(series.to_numpy(dtype=np.float64, na_value=np.nan))
        values, bad = _native.parse_numbers(_cells(series))
        if bad is not None:
            raise StictionError(
                f"{_row_label(series, bad)}, column '{name}' ({role}): "
                f"{series.iloc[bad]!r} is not a number; use plain decimal numbers such as 12.5 "
                "(None, NaN, #N/A and historian states such as Bad Input are read as gaps)"
            )
        return np.asarray(values, dtype=np.float64)
    arr = np.asarray(series)
    if arr.ndim != 1:
        raise StictionError(f"{name}: a signal is one-dimensional; got an array of shape {arr.shape}")
    if arr.dtype.kind in "biuf":
        return np.ascontiguousarray(arr, dtype=np.float64)
    return numbers(pd.Series(arr), name, role)


def modes(series: Any, name: str) -> np.ndarray:
    """Controller modes as automatic flags: bools, 1/0, or words (auto, manual, cas, ...)."""
    s = series if isinstance(series, pd.Series) else pd.Series(np.asarray(series))
    if pd.api.types.is_bool_dtype(s.dtype) and not s.isna().any():
        return np.ascontiguousarray(s.to_numpy(dtype=bool))
    if pd.api.types.is_numeric_dtype(s.dtype):
        v = s.to_numpy(dtype=np.float64, na_value=np.nan)
        return np.ascontiguousarray(np.nan_to_num(v, nan=0.0) != 0.0)
    flags, bad = _native.parse_modes(_cells(s))
    if bad is not None:
        raise StictionError(
            f"{_row_label(s, bad)}, column '{name}': {s.iloc[bad]!r} is not a controller mode; "
            "use auto or manual (also 1 or 0, True or False)"
        )
    return np.asarray(flags, dtype=bool)


def seconds(values: Any, name: str) -> np.ndarray:
    """A time axis in seconds: datetimes (since 1970, UTC for zoned ones) or numbers of seconds."""
    if isinstance(values, (pd.DatetimeIndex, pd.Index)) and not isinstance(values, pd.DatetimeIndex):
        values = pd.Series(values)
    if isinstance(values, pd.DatetimeIndex):
        idx = values.tz_convert("UTC").tz_localize(None) if values.tz is not None else values
        # nanoseconds whatever the index's unit (pandas 3 makes microsecond indexes)
        ns = np.asarray(idx, dtype="datetime64[ns]")
        out = ns.astype(np.int64).astype(np.float64) / 1e9
        out[np.isnat(ns)] = np.nan
        return out
    s = values if isinstance(values, pd.Series) else pd.Series(np.asarray(values))
    if pd.api.types.is_datetime64_any_dtype(s.dtype):
        return seconds(pd.DatetimeIndex(s), name)
    if pd.api.types.is_timedelta64_dtype(s.dtype):
        return s.dt.total_seconds().to_numpy(dtype=np.float64, na_value=np.nan)
    if pd.api.types.is_numeric_dtype(s.dtype):
        return np.ascontiguousarray(s.to_numpy(dtype=np.float64, na_value=np.nan))
    try:
        parsed = pd.to_datetime(s, utc=True, format="mixed")
    except (ValueError, TypeError) as e:
        raise StictionError(
            f"column '{name}' (time): {e}; give times as datetimes or seconds, or pass ts= and no time"
        ) from None
    return seconds(pd.DatetimeIndex(parsed), name)


def loop_columns(
    data: Any,
    op: Any,
    pv: Any,
    sp: Any = None,
    mode: Any = None,
    mv: Any = None,
    time: Any = None,
) -> Tuple[Dict[str, Optional[np.ndarray]], str]:
    """The signals of one loop from a DataFrame (column names) or arrays / Series (``data`` None).

    The time axis is, in this order: ``time`` (a column name, or an array), a DatetimeIndex of
    the frame (or of ``op`` when it is a Series), a column named as TIME_NAMES lists (t, time, timestamp, datetime, date, ...).
    Returns the arrays and the time column's name (for messages).
    """
    if data is not None:
        if not isinstance(data, pd.DataFrame):
            raise StictionError(
                f"data must be a pandas DataFrame (or None with arrays as op= and pv=); got {type(data).__name__}"
            )
        for arg, v in (("op", op), ("pv", pv), ("sp", sp), ("mode", mode), ("mv", mv)):
            # a name, or a tuple: a column of a MultiIndex (a frame pivoted by tag and signal)
            if v is not None and not isinstance(v, (str, tuple)):
                raise StictionError(
                    f"{arg}= names a column of data (a name, or a tuple for MultiIndex columns); got {type(v).__name__}"
                )
        out: Dict[str, Optional[np.ndarray]] = {
            "op": numbers(require(data, op, "op", "controller output op"), op, "controller output op"),
            "pv": numbers(require(data, pv, "pv", "process variable pv"), pv, "process variable pv"),
            "sp": None if sp is None else numbers(require(data, sp, "sp", "setpoint sp"), sp, "setpoint sp"),
            "mv": None if mv is None else numbers(require(data, mv, "mv", "valve position mv"), mv, "valve position mv"),
            "auto": None if mode is None else modes(require(data, mode, "mode", "controller mode"), mode),
        }
        name = "time"
        if isinstance(time, (str, tuple)):
            name = time if isinstance(time, str) else " / ".join(map(str, time))
            out["time"] = seconds(require(data, time, "time", "time"), name)
        elif time is not None:
            out["time"] = seconds(time, "time")
        elif isinstance(data.index, pd.DatetimeIndex):
            out["time"], name = seconds(data.index, "index"), "index"
        else:
            found = next((c for c in TIME_NAMES if c in data.columns), None)
            out["time"] = None if found is None else seconds(data[found], found)
            name = found or name
        return out, name
    if op is None or pv is None:
        raise StictionError("give a DataFrame as data, or the signals as arrays: op= and pv=")
    out = {
        "op": numbers(op, "op", "controller output op"),
        "pv": numbers(pv, "pv", "process variable pv"),
        "sp": None if sp is None else numbers(sp, "sp", "setpoint sp"),
        "mv": None if mv is None else numbers(mv, "mv", "valve position mv"),
        "auto": None if mode is None else modes(mode, "mode"),
        "time": None,
    }
    if time is not None:
        out["time"] = seconds(time, "time")
    elif isinstance(op, pd.Series) and isinstance(op.index, pd.DatetimeIndex):
        out["time"] = seconds(op.index, "index")
    # lengths are checked by the core, in the CLI's words
    return out, "time"

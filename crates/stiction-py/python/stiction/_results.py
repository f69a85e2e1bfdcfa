"""Result objects: thin views over the core's result structs, serialised by the same serde code
the CLI's ``--json`` uses, so ``to_dict()`` equals the CLI's JSON key for key."""

from __future__ import annotations

import copy
import json
from typing import Any, Dict, List

import pandas as pd


class _Result:
    """Attributes are the JSON's top-level keys (``result.verdict``, ``result.band``, ...)."""

    _what = "result"

    def __init__(self, text: str, notes: List[str]):
        self._d: Dict[str, Any] = json.loads(text)
        #: What the preparation of the record decided (rows sorted, gaps), as the CLI's notes.
        self.notes: List[str] = list(notes)

    def to_dict(self) -> Dict[str, Any]:
        """The result as a dict: the CLI's JSON for the same data, key for key."""
        return copy.deepcopy(self._d)

    def keys(self) -> List[str]:
        return list(self._d)

    def __getattr__(self, name: str) -> Any:
        d = self.__dict__.get("_d")
        if d is not None and name in d:
            return d[name]
        raise AttributeError(f"{type(self).__name__} has no attribute '{name}'; it has {', '.join(d or [])}")

    def __dir__(self) -> List[str]:
        return sorted(set(super().__dir__()) | set(self._d))

    def __eq__(self, other: object) -> bool:
        return isinstance(other, type(self)) and self._d == other._d


class Diagnosis(_Result):
    """The diagnosis of one loop (``stiction diagnose --json``).

    Main attributes: ``verdict`` (``stiction``, ``no_stiction``, ``undetermined``,
    ``insufficient_data``), ``probability`` (of a sticky valve, from the verdict's one calibrated
    model; None where the record could not be judged), ``reasons`` (the one or two findings that
    decided the verdict: each a dict with its ``kind``, its figures, its ``contribution`` to the
    log-odds and its ``text`` in words), ``next_step`` (a dict: ``action``, its qualifiers and its
    ``text``), ``statistics`` (the model's reading: each statistic's ``value`` and
    ``contribution``), ``band`` (the stiction band in % of valve span and where it comes from, for
    a ``stiction`` verdict), ``reach`` (the bands the record hides, from OP's noise: what a
    ``no_stiction`` verdict says little about), ``families`` (the evidence, each with its vote and
    its ``contribution`` to the log-odds), ``indices`` (the shape indices), ``oscillation``,
    ``quality`` (the data-quality gates), ``samples``, ``ts``, ``warnings``; without a setpoint
    column, ``setpoint_read_off`` (the setpoint's steps read off OP and PV, and the levels
    between) when any were found; on a long record, ``judged_on`` (the means it was judged on,
    and the samples). The words are the CLI's (the same Rust code fills them).
    """

    @property
    def why(self) -> List[str]:
        """The reasons in words, the one or two findings that decided the verdict."""
        return [r.get("text", "") for r in self._d.get("reasons") or []]

    @property
    def windows(self) -> pd.DataFrame:
        """The verdict per window (``window=`` samples) as a DataFrame; empty without windows.
        Its ``reasons`` are the window's reasons (dicts, each with its ``text``)."""
        rows = self._d.get("windows") or []
        return pd.DataFrame(rows, columns=None if rows else ["start", "end", "t_start", "t_end", "verdict", "probability", "reasons", "period", "votes"])

    @property
    def band_percent(self) -> Any:
        """The stiction band in % of valve span, or None."""
        b = self._d.get("band")
        return None if b is None else b.get("band_percent_of_span")

    def indices_frame(self) -> pd.DataFrame:
        """The shape indices (name, value, vote, threshold, ...) as a DataFrame."""
        return pd.DataFrame(self._d.get("indices") or [])

    def statistics_frame(self) -> pd.DataFrame:
        """The verdict model's reading (statistic, value, contribution to the log-odds) as a
        DataFrame; empty where the record could not be judged."""
        s = self._d.get("statistics") or {}
        return pd.DataFrame(s.get("contributions") or [], columns=["statistic", "value", "contribution"])

    def __repr__(self) -> str:
        p = self._d.get("probability")
        prob = "" if p is None else f", P {p:.2f}"
        band = self.band_percent
        b = "" if band is None else f", band {band:.2f} % of span"
        return f"<Diagnosis {self._d.get('verdict')}{prob}{b}; {self._d.get('samples')} samples>"


class Quantification(_Result):
    """Stiction quantified from OP and PV (``stiction quantify --json``): ``apparent_stiction``,
    ``params``, ``interval``, ``fit``, ``linear_model``, ``status``, ``mv`` (the estimated
    valve position), ``pv_simulated``."""

    def __repr__(self) -> str:
        return (
            f"<Quantification {self._d.get('model')} {self._d.get('method')}: "
            f"apparent stiction {self._d.get('apparent_stiction')}, status {self._d.get('status')}>"
        )


class Estimate(_Result):
    """Model parameters estimated from OP and MV (``stiction estimate --json``): ``params``,
    ``interval`` (the proven optimal set for ``exact``), ``sse``, ``r2``, ``certificate``."""

    def __repr__(self) -> str:
        return f"<Estimate {self._d.get('model')} {self._d.get('method')}: {self._d.get('params')}, R² {self._d.get('r2')}>"

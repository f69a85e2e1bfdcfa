"""stiction: find and measure stiction (static friction) in control valves.

The same core as the ``stiction`` command: diagnose routine loop data (``diagnose``), quantify
the stiction band from OP and PV (``quantify``), estimate a stiction model from OP and the valve
position (``estimate``), simulate sticky valves (``simulate``, ``Stenman``, ``He``, ``Kano``,
``Choudhury``), write a loop's HTML report (``report``, the page of ``stiction report``), and
diagnose a fleet in parallel (``diagnose_many``; ``stiction.spark`` for Spark). Results equal the CLI's ``--json`` key for key (``to_dict()``).

Bad input raises :class:`StictionError`, a ``ValueError`` with one sentence naming the argument,
column or row and the fix.
"""

from __future__ import annotations

from typing import Any, Dict, Optional, Sequence, Tuple

import numpy as np
import pandas as pd

from . import _stiction as _native
from ._many import FLEET_COLUMNS, MANY_COLUMNS, diagnose_many
from ._report import report
from ._results import Diagnosis, Estimate, Quantification
from ._signals import StictionError, loop_columns, numbers
from ._stiction import Choudhury, He, Kano, Stenman

__version__ = _native.__version__

__all__ = [
    "Choudhury",
    "Diagnosis",
    "Estimate",
    "FLEET_COLUMNS",
    "MANY_COLUMNS",
    "He",
    "Kano",
    "Quantification",
    "Stenman",
    "StictionError",
    "diagnose",
    "diagnose_many",
    "estimate",
    "quantify",
    "report",
    "simulate",
]


def diagnose(
    data: Optional[pd.DataFrame] = None,
    op: Any = "op",
    pv: Any = "pv",
    sp: Any = None,
    mode: Any = None,
    mv: Any = None,
    ts: Optional[float] = None,
    integrating: Optional[bool] = None,
    window: Optional[int] = None,
    quantify: bool = True,
    *,
    time: Any = None,
    op_range: Tuple[float, float] = (0.0, 100.0),
    estimate_start: bool = False,
    thorough: bool = False,
) -> Diagnosis:
    """Diagnose one loop from routine data, as ``stiction diagnose``: quality gates, the
    families of evidence (valve, closed-loop fit, stick-slip, shape, loop), the probability of a
    sticky valve from one calibrated model, the verdict with its reasons and next step in words.

    data: a DataFrame whose columns ``op``, ``pv`` (and ``sp``, ``mode``, ``mv`` if given) name
        the signals; its DatetimeIndex, or a column ``time`` / t / time / timestamp, gives the
        sampling time. Or None, with the signals as numpy arrays or Series: ``op=``, ``pv=``.
    sp: setpoint (without it the control error is the PV's deviation from its mean).
    mode: controller mode (auto/manual, 1/0, bools): only automatic stretches are judged.
    mv: the recorded valve position, when there is one (direct evidence).
    ts: sampling time in seconds (default: the median step of the time, else 1).
    integrating: True a level loop (the indices and fits use their integrating variants), False
        self-regulating, None (default): a column named by an ISA-5.1 tag (LIC..., FIC...) hints
        it, else the record's behaviour decides.
    window: also a verdict per window of this many samples (``Diagnosis.windows``).
    quantify: size the band with the closed-loop estimate when the verdict is stiction.
    op_range: OP of a closed and a fully open valve; the band is in % of this span.
    thorough: also the hidden-valve family (a particle filter over a sticky valve that slips
        between the samples, on a loop that oscillates; about 1 s more on two cores, 3 s where
        it finds one: the median of three draws); it reports beside the verdict, which does not
        read it.

    Missing values (NaN, None, historian states such as "Bad Input") are gaps.
    """
    if op is None:
        op = "op"
    cols, time_name = loop_columns(data, op, pv, sp=sp, mode=mode, mv=mv, time=time)
    text, notes = _native.diagnose(
        cols["op"], cols["pv"], sp=cols["sp"], mv=cols["mv"], auto=cols["auto"], time=cols["time"],
        ts=ts, integrating=integrating, window=window, quantify=quantify,
        op_range=tuple(op_range), estimate_start=estimate_start, thorough=thorough,
        time_name=time_name, tags=[c for c in (pv, op) if isinstance(c, str)],
    )
    return Diagnosis(text, notes)


def quantify(
    data: Optional[pd.DataFrame] = None,
    op: Any = "op",
    pv: Any = "pv",
    ts: Optional[float] = None,
    model: str = "stenman",
    method: Optional[str] = None,
    seed: int = 1,
    *,
    time: Any = None,
    integrating: Optional[bool] = None,
    max_delay: int = 30,
    quick: bool = False,
    full: bool = False,
    estimate_start: bool = False,
    ants: Optional[int] = None,
    iterations: Optional[int] = None,
    points: int = 40,
    bounds: Optional[Dict[str, Tuple[float, float]]] = None,
) -> Quantification:
    """Quantify stiction from OP and PV alone (closed-loop Hammerstein identification), as
    ``stiction quantify``: the apparent stiction band, the fitted model and its fit.

    Data as for :func:`diagnose`. Short gaps (at most 3 samples in a row, at most 1 % of the
    record) are bridged by straight lines; past longer gaps the longest stretch without one is
    used (see ``notes``).
    model: stenman, he, kano, choudhury; method: exact (Stenman's default), aco-r, aco, grid.
    integrating: True (a level loop), False (self-regulating), None (tried both ways).
    """
    cols, time_name = loop_columns(data, op, pv, time=time)
    text, notes = _native.quantify(
        cols["op"], cols["pv"], time=cols["time"], ts=ts, model=model, method=method, seed=seed,
        max_delay=max_delay, integrating=integrating, quick=quick, full=full,
        estimate_start=estimate_start, ants=ants, iterations=iterations, points=points,
        bounds=bounds, time_name=time_name,
    )
    return Quantification(text, notes)


def estimate(
    op: Any,
    mv: Any,
    model: str = "stenman",
    method: Optional[str] = None,
    seed: Optional[int] = None,
    **settings: Any,
) -> Estimate:
    """Estimate a stiction model's parameters from the command ``op`` and the valve position
    ``mv`` (arrays or Series), as ``stiction estimate``: the paper's problem.

    method: exact (Stenman's default: the whole optimal set, proven), aco (the paper's ant
    colony), aco-r (default for the two-parameter models), grid. seed: of the random methods
    (default 1, as the CLI). settings: the CLI's flags by name: ants, iterations, rho, q,
    elitist, resolution, tau0, epsilon, local_search, archive, locality, xi, points, lo, hi,
    bounds={name: (lo, hi)}.
    """
    text, notes = _native.estimate(
        numbers(op, "op", "controller output op"), numbers(mv, "mv", "valve position mv"),
        model=model, method=method, seed=1 if seed is None else seed, settings=settings,
    )
    return Estimate(text, notes)


def simulate(
    model: str = "stenman",
    loop: str = "open",
    *,
    signal: Optional[str] = None,
    ts: Optional[float] = None,
    samples: Optional[int] = None,
    noise: float = 0.0,
    seed: int = 1,
    process: Optional[str] = None,
    pi: Optional[str] = None,
    sp: Optional[str] = None,
    op0: Optional[float] = None,
    disturbance: Optional[str] = None,
    **params: float,
) -> pd.DataFrame:
    """Simulate a sticky valve, as ``stiction simulate``: a DataFrame with columns t, sp, op,
    mv, pv (sp and pv NaN open loop).

    model and its parameters by name, % of valve span: stenman d=; he fs=, fd=; kano and
    choudhury S=, J=. loop: "open" (``signal`` drives the valve, default
    "sine:amplitude=1,period=10", ts 0.1 s, 1001 samples) or "closed" (a PI loop: ``process``
    "foptd:K=3,tau=10,delay=10" or "integrating:K=,delay=", ``pi`` "Kc=0.2,Ti=10", setpoint
    ``sp`` "step:from=50,to=51,at=10", ``disturbance`` on pv; ts 1 s, 2000 samples).
    noise: standard deviation of Gaussian noise on mv (open loop) or pv (closed loop).
    """
    if loop not in ("open", "closed"):
        raise StictionError(f"loop='{loop}': use loop='open' or loop='closed'")
    d = _native.simulate(
        model, params, closed=loop == "closed", signal=signal, ts=ts, samples=samples,
        noise=noise, seed=seed, process=process, pi=pi, sp=sp, op0=op0, disturbance=disturbance,
    )
    n = len(d["t"])
    nan = np.full(n, np.nan)
    return pd.DataFrame({k: (d[k] if len(d[k]) == n else nan) for k in ("t", "sp", "op", "mv", "pv")})

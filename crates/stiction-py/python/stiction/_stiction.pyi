"""Type stubs of the native module (pyo3). The public API is in ``stiction``; these functions
take float64 arrays (read without copies when contiguous) and return the core's results as the
CLI's JSON text."""

from typing import Dict, List, Optional, Tuple

import numpy as np
import numpy.typing as npt

__version__: str

class StictionError(ValueError):
    """Bad input: one sentence names the argument, the column or the row, and the fix."""

def parse_numbers(cells: List[Optional[str]]) -> Tuple[List[float], Optional[int]]: ...
def parse_modes(cells: List[Optional[str]]) -> Tuple[List[bool], Optional[int]]: ...
def diagnose(
    op: npt.NDArray[np.float64],
    pv: npt.NDArray[np.float64],
    sp: Optional[npt.NDArray[np.float64]] = None,
    mv: Optional[npt.NDArray[np.float64]] = None,
    auto: Optional[npt.NDArray[np.bool_]] = None,
    time: Optional[npt.NDArray[np.float64]] = None,
    ts: Optional[float] = None,
    integrating: Optional[bool] = None,
    window: Optional[int] = None,
    quantify: bool = True,
    op_range: Tuple[float, float] = (0.0, 100.0),
    estimate_start: bool = False,
    thorough: bool = False,
    time_name: Optional[str] = None,
    tags: Optional[List[str]] = None,
) -> Tuple[str, List[str]]:
    """Diagnose one loop: the Diagnosis as the CLI's ``diagnose --json`` text (the reasons' and
    the next step's ``text`` filled by the same words), and the notes of the record's
    preparation."""

def report(
    op: npt.NDArray[np.float64],
    pv: npt.NDArray[np.float64],
    sp: Optional[npt.NDArray[np.float64]] = None,
    mv: Optional[npt.NDArray[np.float64]] = None,
    auto: Optional[npt.NDArray[np.bool_]] = None,
    time: Optional[npt.NDArray[np.float64]] = None,
    ts: Optional[float] = None,
    integrating: Optional[bool] = None,
    window: Optional[int] = None,
    quantify: bool = True,
    op_range: Tuple[float, float] = (0.0, 100.0),
    estimate_start: bool = False,
    thorough: bool = False,
    time_name: Optional[str] = None,
    loop_id: str = "loop",
    columns: Optional[Dict[str, str]] = None,
) -> str:
    """Diagnose one loop and render its report, the page ``stiction report`` writes (the same
    Rust code), as HTML text. loop_id: the loop's name in the title; columns: the names of the
    op, pv, sp, mode and time columns for the header (op and pv needed), or None. Bad input
    raises StictionError; ``stiction.report`` writes the page to a file."""

def diagnose_many(
    ids: List[str],
    sources: List[str],
    starts: List[int],
    op: npt.NDArray[np.float64],
    pv: npt.NDArray[np.float64],
    sp: Optional[npt.NDArray[np.float64]] = None,
    mv: Optional[npt.NDArray[np.float64]] = None,
    auto: Optional[npt.NDArray[np.bool_]] = None,
    time: Optional[npt.NDArray[np.float64]] = None,
    ts: Optional[float] = None,
    integrating: Optional[bool] = None,
    quantify: bool = True,
    op_range: Tuple[float, float] = (0.0, 100.0),
    estimate_start: bool = False,
    thorough: bool = False,
    time_name: Optional[str] = None,
    threads: Optional[int] = None,
    progress: bool = False,
    failed: Optional[Dict[int, str]] = None,
    tags: Optional[List[str]] = None,
) -> str:
    """Diagnose many loops: the ranked fleet rows as JSON (``stiction batch``'s summary rows:
    ``probability`` of a sticky valve, ``reason`` the reasons' words joined by "; ")."""
def quantify(
    op: npt.NDArray[np.float64],
    pv: npt.NDArray[np.float64],
    time: Optional[npt.NDArray[np.float64]] = None,
    ts: Optional[float] = None,
    model: str = "stenman",
    method: Optional[str] = None,
    seed: int = 1,
    max_delay: int = 30,
    integrating: Optional[bool] = None,
    quick: bool = False,
    full: bool = False,
    estimate_start: bool = False,
    ants: Optional[int] = None,
    iterations: Optional[int] = None,
    points: int = 40,
    bounds: Optional[Dict[str, Tuple[float, float]]] = None,
    time_name: Optional[str] = None,
) -> Tuple[str, List[str]]: ...
def estimate(
    op: npt.NDArray[np.float64],
    mv: npt.NDArray[np.float64],
    model: str = "stenman",
    method: Optional[str] = None,
    seed: int = 1,
    settings: Optional[Dict[str, object]] = None,
) -> Tuple[str, List[str]]: ...
def simulate(
    model: str,
    params: Dict[str, float],
    closed: bool = False,
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
) -> Dict[str, npt.NDArray[np.float64]]: ...

class _Model:
    @property
    def params(self) -> Dict[str, float]:
        """The parameters, {name: value} (% of valve span)."""
    def simulate(
        self, op: npt.NDArray[np.float64], start: Optional[float] = None
    ) -> npt.NDArray[np.float64]:
        """The valve position for the command op, from start (default: as if the valve had
        just moved to the first OP)."""

class Stenman(_Model):
    """Stenman's model: the valve moves to OP when OP is more than the band d away."""
    def __init__(self, d: float) -> None: ...

class He(_Model):
    """He et al. (2007): static band fs, kinetic band fd (fs >= fd)."""
    def __init__(self, fs: float, fd: float) -> None: ...

class Kano(_Model):
    """Kano et al. (2004): S (deadband + stickband), J (slip jump)."""
    def __init__(self, S: float, J: float) -> None: ...

class Choudhury(_Model):
    """Choudhury et al. (2005): S (deadband + stickband), J (slip jump)."""
    def __init__(self, S: float, J: float) -> None: ...

# Signatures of the Rust extension crr._crr (python/src/lib.rs). Private: use the package crr.
from os import PathLike
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

_Path = Union[str, PathLike[str]]

__version__: str
ANALYSIS_KEYS: List[str]

class Model:
    @staticmethod
    def load(path: _Path) -> Model: ...
    @staticmethod
    def assemble(
        path: _Path,
        planar: bool,
        all_contacts: bool,
        tolerance: float,
        ground_level: float,
        inscribed: bool,
    ) -> Model: ...
    @staticmethod
    def parse(text: str, is_json: bool, label: _Path, base_dir: _Path) -> Model: ...
    @property
    def label(self) -> Path: ...
    @property
    def base_dir(self) -> Path: ...
    @property
    def name(self) -> str: ...
    @property
    def coordinates(self) -> List[str]: ...
    @property
    def interfaces(self) -> List[str]: ...
    def to_json(self) -> str: ...
    def check_json(
        self,
        directions: Optional[List[str]] = None,
        friction: Optional[float] = None,
        exhaustive_sets: Optional[int] = None,
    ) -> str: ...
    def inspect_json(
        self, settings: Optional[Sequence[str]] = None, q: Optional[Sequence[float]] = None
    ) -> str: ...
    def poincare(
        self,
        amplitude: str,
        frequency: Optional[float],
        component: str,
        phase: float,
        periods: int,
        transient: int,
        section: Optional[str],
        coordinate: Optional[str],
        duration: Optional[float],
        rest: bool,
        amplitudes: Optional[str],
        frequencies: Optional[str],
        grid: Optional[str],
        jobs: Optional[int],
    ) -> Tuple[str, str, str]: ...

class Run:
    @property
    def samples(self) -> int: ...
    def history_columns(self) -> List[bytes]: ...
    def state_codes(self) -> Tuple[List[str], bytes]: ...
    def impacts(self) -> List[Dict[str, Any]]: ...
    @property
    def summary_json(self) -> str: ...
    @property
    def error(self) -> Optional[str]: ...
    def history_csv(self) -> str: ...
    def impacts_csv(self) -> str: ...
    def hops_csv(self) -> str: ...
    def openings_csv(self) -> str: ...

def simulate(
    model: Model,
    ground_motion: Optional[str] = None,
    initial: Optional[str] = None,
    analysis: Optional[str] = None,
    record_file: Optional[Tuple[_Path, str, Optional[str], str, float]] = None,
    records: Sequence[Tuple[str, Sequence[float], Sequence[float], str, float]] = ...,
    duration: Optional[float] = None,
    max_samples: Optional[int] = None,
    memory: Optional[float] = None,
) -> Run: ...

class Study:
    @staticmethod
    def load(path: _Path) -> Study: ...
    @staticmethod
    def parse(text: str, is_json: bool, label: _Path) -> Study: ...
    @property
    def name(self) -> str: ...
    @property
    def label(self) -> Path: ...
    @property
    def case_ids(self) -> List[str]: ...
    @property
    def header(self) -> str: ...
    def __len__(self) -> int: ...
    def run_rows(
        self, ids: Optional[Sequence[str]] = None, jobs: Optional[int] = None
    ) -> List[str]: ...
    def csv(self, rows: Sequence[str]) -> str: ...
    def run_into(
        self, out: _Path, jobs: Optional[int] = None, progress: bool = False
    ) -> Tuple[int, int, int, int]: ...

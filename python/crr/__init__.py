"""crr — coupled rocking rotations, from Python.

The dynamics of rigid-block masonry structures (blocks, columns of drums, trilithons, arches)
under earthquakes, computed by the Rust engine crr. The same model and study files as the
command line, the same numbers to the last digit, and the same error messages.

Units are SI throughout: lengths in m, angles in rad, rates in rad/s, times in s, accelerations
in m/s² (records also in g or cm/s² where their units are given), energies in J, masses in kg.

>>> import crr
>>> model = crr.Model.from_file("examples/models/single_block.toml")
>>> result = crr.simulate(model, duration=5.0)
>>> result.q[:, 0].max()          # peak rotation of the block, rad    # doctest: +SKIP

The heavy work runs in Rust with the GIL released: Python threads run simulations in parallel.
:mod:`crr.dask` spreads a study's cases over a ``dask.distributed`` cluster.
"""

from __future__ import annotations

import io
import json
import os
import sys
import time
import warnings
from pathlib import Path
from typing import TYPE_CHECKING, Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from . import _crr
from ._errors import (
    CrrError,
    CrrWarning,
    FileError,
    InputError,
    MissingFileError,
    OutOfMemoryError,
    SimulationError,
)

if TYPE_CHECKING:  # pragma: no cover
    import pandas
    import xarray

__all__ = [
    "CrrError",
    "CrrWarning",
    "FileError",
    "InputError",
    "MissingFileError",
    "Model",
    "OutOfMemoryError",
    "Poincare",
    "Record",
    "Result",
    "SimulationError",
    "Study",
    "cases_frame",
    "poincare",
    "simulate",
    "study",
    "__version__",
]

__version__: str = _crr.__version__

PathLike = Union[str, "os.PathLike[str]"]

# Columns of a history row of numbers after t, q and q̇ (history.csv).
_ENERGIES = ("kinetic", "potential", "work_in", "dissipated")


def _fspath(p: PathLike) -> str:
    return os.fspath(p)


def _json(value: Any, path: str = "", label: Optional[str] = None) -> str:
    """JSON of a model, study or table given as Python values, numpy scalars and arrays
    included (as the numbers and lists they hold). A number that is not finite (NaN, ±inf) is an
    :class:`InputError` naming its place (``label: `` when given, then ``path`` and the keys and
    indices down to it, as the parser names a key): JSON has no such numbers, and the parser
    would only report a position in a text the user never wrote."""

    def plain(o: Any) -> Any:
        if isinstance(o, np.generic):
            return o.item()
        if isinstance(o, np.ndarray):
            return o.tolist()
        raise TypeError(f"{type(o).__name__} is not a number, string, list or mapping")

    def refuse(at: str, x: Any) -> None:
        raise InputError(f"{label + ': ' if label else ''}{at}: {float(x)} is not a finite number")

    def check_finite(o: Any, at: str) -> None:
        if isinstance(o, (float, np.floating)) and not np.isfinite(o):
            refuse(at, o)
        if isinstance(o, np.ndarray):
            if o.dtype.kind in "fc":
                bad = np.argwhere(~np.isfinite(o))
                if len(bad):
                    index = tuple(int(i) for i in bad[0])
                    refuse(at + "".join(f"[{i}]" for i in index), o[index])
            elif o.dtype.kind == "O":
                check_finite(o.tolist(), at)
        elif isinstance(o, Mapping):
            for k, v in o.items():
                check_finite(v, f"{at}.{k}" if at else str(k))
        elif isinstance(o, (list, tuple)):
            for i, v in enumerate(o):
                check_finite(v, f"{at}[{i}]")

    check_finite(value, path)
    return json.dumps(value, default=plain)


def _is_one_direction(d: Any) -> bool:
    """A single direction (a name or three numbers), not a list of them."""
    if isinstance(d, str):
        return True
    items = list(np.asarray(d, dtype=object).ravel()) if not isinstance(d, Mapping) else []
    return len(items) == 3 and all(
        isinstance(x, (int, float, np.integer, np.floating)) for x in items
    )


def _direction_text(d: Any) -> str:
    """A direction as ``crr check --direction`` takes it."""
    if isinstance(d, str):
        return d
    try:
        values = list(np.asarray(d, dtype=float).ravel())
    except (TypeError, ValueError):
        values = []
    if len(values) != 3:
        raise InputError(f"direction: expected a name such as '+x' or three numbers, got {d!r}")
    return ",".join(repr(float(v)) for v in values)


def _cgroup_memory_left(
    root: str = "/sys/fs/cgroup", membership: str = "/proc/self/cgroup"
) -> Optional[float]:
    """Bytes the process's control groups still let it use (a container's or a batch job's
    memory limit, which ``MemAvailable`` does not see: a run sized on the machine's memory was
    killed by the limit instead of refused): the limit less the usage, the usage without the
    page cache the kernel reclaims first (``inactive_file`` of ``memory.stat``), of the process's
    group and of every group above it, the least. cgroup v2: ``memory.max``, ``memory.current``;
    v1: ``memory.limit_in_bytes``, ``memory.usage_in_bytes`` (an unset limit is a huge number).
    None where no limit is set or readable."""

    def read(path: str) -> Optional[str]:
        try:
            with open(path, encoding="utf-8", errors="replace") as f:
                return f.read()
        except OSError:
            return None

    def number(path: str) -> Optional[float]:
        text = read(path)
        try:
            return float(text.strip()) if text is not None else None
        except ValueError:
            return None  # "max": no limit

    def reclaimable(folder: str, key: str) -> float:
        for line in (read(os.path.join(folder, "memory.stat")) or "").splitlines():
            fields = line.split()
            if len(fields) == 2 and fields[0] == key:
                try:
                    return float(fields[1])
                except ValueError:
                    return 0.0
        return 0.0

    text = read(membership)
    if text is None:
        return None
    left: List[float] = []
    for line in text.splitlines():
        fields = line.strip().split(":", 2)
        if len(fields) != 3:
            continue
        _, controllers, path = fields
        parts = [p for p in path.split("/") if p]
        if controllers == "":
            base, files, cache = root, ("memory.max", "memory.current"), "inactive_file"
        elif "memory" in controllers.split(","):
            base = os.path.join(root, "memory")
            files, cache = ("memory.limit_in_bytes", "memory.usage_in_bytes"), "total_inactive_file"
        else:
            continue
        # The limits of the group and of every group above it apply.
        for depth in range(len(parts), -1, -1):
            folder = os.path.join(base, *parts[:depth])
            limit, used = number(os.path.join(folder, files[0])), number(os.path.join(folder, files[1]))
            if limit is None or used is None or limit >= 2.0**60:
                continue
            left.append(max(limit - max(used - reclaimable(folder, cache), 0.0), 0.0))
    return min(left) if left else None


def _memory_available() -> Optional[float]:
    """Bytes this process can still allocate, where the system tells: the memory available
    (``MemAvailable`` of ``/proc/meminfo``), what its control groups' memory limits leave
    (:func:`_cgroup_memory_left`), and below the address-space limit (``RLIMIT_AS``) what the
    process has not mapped yet; None when none is known."""
    known: List[float] = []
    cgroup = _cgroup_memory_left()
    if cgroup is not None:
        known.append(cgroup)
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    known.append(float(line.split()[1]) * 1024.0)
    except OSError:
        pass
    try:
        import resource

        soft, _ = resource.getrlimit(resource.RLIMIT_AS)
        if soft != resource.RLIM_INFINITY:
            with open("/proc/self/status") as f:
                mapped = next(float(l.split()[1]) * 1024.0 for l in f if l.startswith("VmSize:"))
            known.append(max(float(soft) - mapped, 0.0))
    except (ImportError, OSError, StopIteration, ValueError):
        pass
    # Nothing left is a limit too (0 would read as "unknown" to the sample limit below).
    return max(min(known), 1.0) if known else None


def _samples(name: str, values: npt.ArrayLike) -> np.ndarray:
    """A column of samples as a flat float array: a column or row vector of shape (n, 1) or
    (1, n) is one series; any other 2-D shape is refused with its shape named."""
    array = np.asarray(values, dtype=float)
    if array.ndim == 2 and 1 in array.shape:
        array = array.reshape(-1)
    if array.ndim != 1:
        raise InputError(f"{name} must be one series of samples, got an array of shape {array.shape}")
    return np.ascontiguousarray(array)


def _positive_count(name: str, value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise InputError(f"{name} must be a positive integer, got {value!r}")
    return int(value)


def _jobs(jobs: Optional[int]) -> Optional[int]:
    """Worker threads: None or -1 mean one per core."""
    if jobs is None or jobs == -1:
        return None
    if isinstance(jobs, bool) or not isinstance(jobs, (int, np.integer)) or jobs < 1:
        raise InputError(f"jobs must be a positive integer, or -1 for one per core, got {jobs!r}")
    return int(jobs)


class Model:
    """A structure read and validated as the command line reads a model file
    (``docs/model-format.md``): bodies, interfaces and the optional ``[ground_motion]``,
    ``[initial]`` and ``[analysis]`` tables.

    Build it with :meth:`from_file`, :meth:`from_toml` or :meth:`from_dict`.
    """

    __slots__ = ("_native",)

    def __init__(self, native: _crr.Model) -> None:
        if not isinstance(native, _crr.Model):
            raise TypeError(
                "crr.Model is built with crr.Model.from_file(path), crr.Model.from_toml(text) "
                f"or crr.Model.from_dict(mapping), not from {type(native).__name__}"
            )
        self._native = native

    @classmethod
    def from_file(cls, path: PathLike) -> "Model":
        """Reads a model file (TOML, or JSON when its name ends in ``.json``). Relative record
        files of its ``[ground_motion]`` are read from the file's folder. Errors name the file,
        the item and the problem, as ``crr`` prints them (:class:`InputError`,
        :class:`FileError`)."""
        return cls(_crr.Model.load(_fspath(path)))

    @classmethod
    def from_assembly(
        cls,
        path: PathLike,
        *,
        planar: bool = False,
        all_contacts: bool = False,
        tolerance: float = 1e-6,
        ground_level: float = 0.0,
        inscribed: bool = False,
    ) -> "Model":
        """The model of an assembly file (blocks only: ``[[body]]`` tables, ``[[obj]]`` files,
        the ``fixed`` blocks that are part of the ground), as ``crr assemble`` writes it: the
        contacts found from the blocks' shapes, every bed (``all_contacts``: every contact) a
        rocking base (``planar``: a hinge about y), faces closer than ``tolerance`` (m) touching,
        the ground the plane z = ``ground_level`` (m); with ``inscribed``, a face that is no
        rectangle (a drum's bed) rocks on the largest rectangle of its proportions inside it.
        Relative record files are read from the assembly's folder. See docs/assembly.md.

        Warns:
            CrrWarning: blocks whose faces face each other a little farther apart than
                ``tolerance`` (up to 1 % of the smaller block), which are no contact, with the
                tolerance that would make them one (as ``crr assemble`` warns).
        """
        native, messages = _crr.Model.assemble(
            _fspath(path),
            bool(planar),
            bool(all_contacts),
            float(tolerance),
            float(ground_level),
            bool(inscribed),
        )
        for message in messages:
            warnings.warn(CrrWarning(message), stacklevel=2)
        return cls(native)

    @classmethod
    def from_toml(
        cls, text: str, base_dir: Optional[PathLike] = None, label: str = "<string>"
    ) -> "Model":
        """A model from the text of a TOML model file. ``label`` names it in error messages;
        relative record files are read from ``base_dir`` (default: the working folder)."""
        base = _fspath(base_dir) if base_dir is not None else "."
        return cls(_crr.Model.parse(text, False, label, base))

    @classmethod
    def from_dict(
        cls, d: Mapping[str, Any], base_dir: Optional[PathLike] = None, label: str = "<dict>"
    ) -> "Model":
        """A model from a mapping with the keys of a model file (``name``, ``body``,
        ``interface``, ``ground_motion``, …), e.g. the output of :meth:`to_dict`. Relative
        record paths are read from ``base_dir`` (default: the working folder): to edit a model
        read from a file, ``Model.from_dict(d, base_dir=model.base_dir)`` keeps its records."""
        base = _fspath(base_dir) if base_dir is not None else "."
        return cls(_crr.Model.parse(_json(d, label=label), True, label, base))

    @property
    def name(self) -> str:
        """The structure's name."""
        return self._native.name

    @property
    def coordinates(self) -> List[str]:
        """The names of the coordinates (hinge angles and base tilts, rad), in the order of q."""
        return list(self._native.coordinates)

    @property
    def interfaces(self) -> List[str]:
        """The names of the interfaces, in the order of the state columns."""
        return list(self._native.interfaces)

    @property
    def source(self) -> str:
        """The file the model was read from, or its label."""
        return str(self._native.label)

    @property
    def base_dir(self) -> Path:
        """The folder its relative record paths are read from (the model file's folder)."""
        return Path(self._native.base_dir)

    def to_dict(self) -> Dict[str, Any]:
        """The model file as a dict (every table, defaults filled in)."""
        return json.loads(self._native.to_json())

    def check(
        self,
        direction: Union[None, str, Sequence[Any]] = None,
        friction: Optional[float] = None,
        exhaustive_sets: Optional[int] = None,
    ) -> Dict[str, Any]:
        """The report of ``crr check --json``: DOF, closures, the static multipliers, and for a
        one-DOF mechanism the activation multiplier λ, the equivalent block, r and the
        free-rocking frequencies (keys and units in ``docs/outputs.md``). Its ``warnings`` (a
        planar model whose hinge axis is not horizontal) are also issued as
        :class:`CrrWarning`.

        Args:
            direction: the directions of the ground acceleration for the static multipliers,
                as ``--direction`` (default ±x and ±y): one direction or a list of them, each
                ``"+x"``, ``"-y"``, … or three numbers (a string ``"1,1,0"`` or a sequence
                ``(1, 1, 0)``; any length, it may have a vertical part).
            friction: Coulomb μ at every contact (0 to 1000), as ``--friction``; default no
                sliding, and the report gives the μ each multiplier needs.
            exhaustive_sets: the most sets of joints that may open and slide the exhaustive
                pass tries per direction, as ``--exhaustive-sets`` (default 4096).

        Ctrl-C stops the check after the stage under way (one linear program of the statics,
        or the mobility's factorisation) and raises ``KeyboardInterrupt``.
        """
        directions: Optional[List[str]] = None
        if direction is not None:
            given = [direction] if _is_one_direction(direction) else list(direction)
            directions = [_direction_text(d) for d in given]
        mu = None if friction is None else float(friction)
        sets = None if exhaustive_sets is None else _positive_count("exhaustive_sets", exhaustive_sets)
        report = json.loads(
            self._native.check_json(directions=directions, friction=mu, exhaustive_sets=sets)
        )
        for message in report.get("warnings") or []:
            warnings.warn(CrrWarning(message), stacklevel=2)
        return report

    def inspect(self, q: Union[None, Mapping[str, float], npt.ArrayLike] = None) -> Dict[str, Any]:
        """The report of ``crr inspect --json`` at configuration ``q`` (rad): a mapping of
        coordinate names to angles (others 0, as ``--q NAME=VALUE``) or one angle per
        coordinate; default the rest configuration.

        The keys are those of ``docs/inspect.md``; ``mass_matrix`` M(q) (kg m²),
        ``generalized_gravity`` −∂U/∂q (N m), ``constraint_residual`` Φ(q) and
        ``constraint_jacobian`` Φ_q (closed chains only) are numpy arrays;
        ``potential_energy`` U (J) is a float.
        """
        if q is None:
            text = self._native.inspect_json()
        elif isinstance(q, Mapping):
            settings = [f"{name}={float(v)!r}" for name, v in q.items()]
            text = self._native.inspect_json(settings=settings)
        else:
            values = [float(v) for v in np.asarray(q, dtype=float).ravel()]
            text = self._native.inspect_json(q=values)
        report = json.loads(text)
        for key in (
            "mass_matrix",
            "generalized_gravity",
            "constraint_residual",
            "constraint_jacobian",
        ):
            if key in report:
                report[key] = np.asarray(report[key], dtype=float)
        return report

    def __reduce__(self) -> Tuple[Any, ...]:
        return (_restore_model, (self._native.to_json(), self.source, str(self._native.base_dir)))

    def __repr__(self) -> str:
        return repr(self._native)


def _restore_model(text: str, label: str, base_dir: str) -> Model:
    return Model(_crr.Model.parse(text, True, label, base_dir))


class Record:
    """An accelerogram driving one ground-motion component (``x``, ``y`` or ``z``), times a
    factor ``scale``: from a file in the command line's formats (:meth:`from_file`, as
    ``crr simulate --record``) or from arrays (:meth:`from_arrays`)."""

    __slots__ = ("path", "format", "units", "t", "a", "component", "scale")

    def __init__(
        self,
        *,
        component: str = "x",
        scale: float = 1.0,
        path: Optional[str] = None,
        format: Optional[str] = None,
        units: Optional[str] = None,
        t: Optional[np.ndarray] = None,
        a: Optional[np.ndarray] = None,
    ) -> None:
        self.component = component
        self.scale = float(scale)
        self.path = path
        self.format = format
        self.units = units
        self.t = t
        self.a = a

    @classmethod
    def from_file(
        cls,
        path: PathLike,
        format: str,
        units: Optional[str] = None,
        component: str = "x",
        scale: float = 1.0,
    ) -> "Record":
        """A record file: ``format`` ``peer-at2`` (values in g), ``csv`` or ``text`` (columns
        time in s and acceleration in ``units``: ``g``, ``m/s2`` or ``cm/s2``), as
        ``--record PATH --format F --units U --component C --scale S``
        (``docs/ground-motion.md``)."""
        return cls(
            path=_fspath(path), format=format, units=units, component=component, scale=scale
        )

    @classmethod
    def from_arrays(
        cls,
        t: npt.ArrayLike,
        a: npt.ArrayLike,
        units: str = "m/s2",
        component: str = "x",
        scale: float = 1.0,
    ) -> "Record":
        """Samples: times ``t`` (s, strictly increasing) and accelerations ``a`` in ``units``
        (``m/s2``, ``g`` = 9.80665 m/s² or ``cm/s2``), linear between samples and 0 outside
        them, as a ``csv`` record of the same numbers."""
        return cls(
            t=_samples("t", t),
            a=_samples("a", a),
            units=units,
            component=component,
            scale=scale,
        )

    def __repr__(self) -> str:
        if self.path is not None:
            return (
                f"Record.from_file({self.path!r}, format={self.format!r}, units={self.units!r}, "
                f"component={self.component!r}, scale={self.scale!r})"
            )
        n = 0 if self.t is None else len(self.t)
        return (
            f"Record.from_arrays(<{n} samples>, units={self.units!r}, "
            f"component={self.component!r}, scale={self.scale!r})"
        )


GroundMotion = Union[
    None, Record, Sequence[Record], Tuple[npt.ArrayLike, npt.ArrayLike], Mapping[str, Any]
]


class Result:
    """A simulation's results: the time histories of ``history.csv`` as numpy arrays, the
    impact log and the summary (``docs/outputs.md``).

    Attributes:
        t: sample times (s), shape (n,).
        q: coordinates (rad), shape (n, dof), columns in the order of :attr:`coordinates`.
        qdot: their rates (rad/s), shape (n, dof).
        kinetic, potential, work_in, dissipated: energies T, U − U(rest), the ground motion's
            work W and the dissipated energy D (J), shape (n,).
        states: state of every interface per sample (``seated``, ``+``, ``-``; the slots of a
            rocking base joined by ``/``), shape (n, interfaces), dtype str.
        coordinates, interfaces: the column names.
        impacts: the impact log, one dict per impact (``t`` s, ``interfaces``, ``rates_before``
            and ``rates_after`` rad/s, ``energy_lost`` J, ``opened``: the seated joints the
            impact opened, by slot name).
        summary: the content of ``summary.json`` (peaks, peak/α, impacts, uplift, collapse,
            energy balance, warnings).
    """

    def __init__(self, run: _crr.Run, coordinates: List[str], interfaces: List[str]) -> None:
        self._run = run
        self.coordinates = coordinates
        self.interfaces = interfaces
        n, dof = run.samples, len(coordinates)
        # Each column crosses as one bytes object that numpy reads in place (no per-sample
        # Python object).
        t, q, qdot, kinetic, potential, work_in, dissipated = (
            np.frombuffer(b, dtype=np.float64) for b in run.history_columns()
        )
        self.t: np.ndarray = t
        self.q: np.ndarray = q.reshape(n, dof)
        self.qdot: np.ndarray = qdot.reshape(n, dof)
        self.kinetic: np.ndarray = kinetic
        self.potential: np.ndarray = potential
        self.work_in: np.ndarray = work_in
        self.dissipated: np.ndarray = dissipated
        # Built on first use: the states from coded columns, the impacts one dict each.
        self._states: Optional[np.ndarray] = None
        self._impacts: Optional[List[Dict[str, Any]]] = None
        self.summary: Dict[str, Any] = json.loads(run.summary_json)

    @property
    def states(self) -> np.ndarray:
        """State of every interface per sample, shape (n, interfaces), dtype str."""
        if self._states is None:
            labels, codes = self._run.state_codes()
            index = np.frombuffer(codes, dtype=np.uint32).reshape(len(self.t), len(self.interfaces))
            self._states = np.array(labels or [""], dtype=str)[index]
        return self._states

    @property
    def impacts(self) -> List[Dict[str, Any]]:
        """The impact log, one dict per impact."""
        if self._impacts is None:
            self._impacts = self._run.impacts()
        return self._impacts

    @property
    def completed(self) -> bool:
        """Whether the run reached its end (or a collapse) without an error."""
        return bool(self.summary["completed"])

    @property
    def energies(self) -> Dict[str, np.ndarray]:
        """The energy columns by name (J)."""
        return {k: getattr(self, k) for k in _ENERGIES}

    def history_csv(self) -> str:
        """The text of ``history.csv``, as ``crr simulate`` writes it."""
        return self._run.history_csv()

    def impacts_csv(self) -> str:
        """The text of ``impacts.csv``, as ``crr simulate`` writes it."""
        return self._run.impacts_csv()

    def hops_csv(self) -> str:
        """The text of ``hops.csv``, as ``crr simulate`` writes it: every pull at a pivot just
        after an impact, measured by the motion with that face released (docs/simulation.md,
        "Hops"; the header alone when there is none)."""
        return self._run.hops_csv()

    def openings_csv(self) -> str:
        """The text of ``openings.csv``, as ``crr simulate`` writes it: the offset of every face
        open at a row of ``history.csv`` (the header alone when no face lifts off)."""
        return self._run.openings_csv()

    def history_frame(self) -> "pandas.DataFrame":
        """The history as a pandas DataFrame with the columns of ``history.csv``."""
        pd = _pandas("Result.history_frame")

        cols: Dict[str, Any] = {"t": self.t}
        for k, c in enumerate(self.coordinates):
            cols[c] = self.q[:, k]
        for k, c in enumerate(self.coordinates):
            cols[f"{c}_rate"] = self.qdot[:, k]
        cols.update(self.energies)
        for k, i in enumerate(self.interfaces):
            cols[f"{i}_state"] = self.states[:, k]
        return pd.DataFrame(cols)

    def to_xarray(self) -> "xarray.Dataset":
        """The history as an ``xarray.Dataset`` on the time index ``t`` (s).

        Variables: ``q`` (rad) and ``qdot`` (rad/s) over (``t``, ``coordinate``); ``kinetic``,
        ``potential``, ``work_in``, ``dissipated`` (J) over ``t``; ``state`` over (``t``,
        ``interface``). Every variable and ``t`` carry ``units`` and ``long_name`` attributes; the
        dataset's attributes hold the model's name, the number of impacts, whether the run
        completed or collapsed, ``outside_model_from_s`` (the time of the run's first failure
        of the rigid-contact hypotheses, ``summary["hypothesis_violation"]``, after which the
        history is outside crr's model; NaN when the run kept them all) and ``summary_json``
        (the whole summary as text: netCDF attributes are flat).

        ``t`` is not unique: at an impact the history has two rows at the same time, the rates
        before and then after it (as ``history.csv``). Select those by position (``isel``), or
        keep the after-impact rows for a unique index with
        ``ds.isel(t=~ds.indexes["t"].duplicated(keep="last"))``.
        """
        try:
            import xarray as xr
        except ImportError as e:
            raise ImportError(
                "Result.to_xarray needs xarray, which is not installed: pip install xarray"
            ) from e

        def energy(v: np.ndarray, name: str) -> Any:
            return ("t", v, {"units": "J", "long_name": name})

        ds = xr.Dataset(
            {
                "q": (("t", "coordinate"), self.q, {"units": "rad", "long_name": "angle"}),
                "qdot": (
                    ("t", "coordinate"),
                    self.qdot,
                    {"units": "rad/s", "long_name": "angular rate"},
                ),
                "kinetic": energy(self.kinetic, "kinetic energy T"),
                "potential": energy(self.potential, "potential energy U - U(rest)"),
                "work_in": energy(self.work_in, "work of the ground motion W"),
                "dissipated": energy(self.dissipated, "energy dissipated at impacts D"),
                "state": (
                    ("t", "interface"),
                    self.states,
                    {"long_name": "active pivot (seated, +, -; slots joined by /)"},
                ),
            },
            coords={
                "t": ("t", self.t, {"units": "s", "long_name": "time"}),
                "coordinate": list(self.coordinates),
                "interface": list(self.interfaces),
            },
            attrs={
                "model": str(self.summary.get("model", {}).get("name", "")),
                "impacts": int(self.summary["impacts"]),
                "completed": int(self.completed),
                "collapsed": int(self.summary["collapse"]["collapsed"]),
                "outside_model_from_s": float(
                    (self.summary.get("hypothesis_violation") or {}).get("time", float("nan"))
                ),
                "summary_json": json.dumps(self.summary, ensure_ascii=False),
            },
        )
        return ds

    def impacts_frame(self) -> "pandas.DataFrame":
        """The impact log as a pandas DataFrame (columns ``t``, ``interfaces``,
        ``rates_before``, ``rates_after``, ``energy_lost``, ``opened``; the list-valued columns
        hold lists)."""
        pd = _pandas("Result.impacts_frame")

        return pd.DataFrame(
            self.impacts,
            columns=["t", "interfaces", "rates_before", "rates_after", "energy_lost", "opened"],
        )

    def write(self, folder: PathLike) -> None:
        """Writes ``history.csv``, ``impacts.csv``, ``hops.csv``, ``openings.csv`` and
        ``summary.json`` into ``folder`` (created if needed), the files of ``crr simulate``."""
        d = Path(folder)
        d.mkdir(parents=True, exist_ok=True)
        for name, text in (
            ("history.csv", self.history_csv()),
            ("impacts.csv", self.impacts_csv()),
            ("hops.csv", self.hops_csv()),
            ("openings.csv", self.openings_csv()),
            ("summary.json", self._run.summary_json),
        ):
            with open(d / name, "w", newline="", encoding="utf-8") as f:
                f.write(text)

    def __getstate__(self) -> Dict[str, Any]:
        # The native run does not pickle: its arrays do, and its CSV texts go as strings
        # (history_csv, impacts_csv, hops_csv and openings_csv give the same bytes after a
        # round trip).
        _ = (self.states, self.impacts)  # built now: the native run that builds them does not pickle
        state = {k: v for k, v in self.__dict__.items() if k != "_run"}
        state["_csv"] = (
            self._run.history_csv(),
            self._run.impacts_csv(),
            self._run.openings_csv(),
            self._run.hops_csv(),
            self._run.summary_json,
        )
        return state

    def __setstate__(self, state: Dict[str, Any]) -> None:
        history, impacts, openings, hops, summary = state.pop("_csv")
        self.__dict__.update(state)
        self._run = _CsvTexts(history, impacts, openings, hops, summary)

    def __repr__(self) -> str:
        s = self.summary
        return (
            f"<crr.Result {len(self.t)} samples to t = {s['end_time']} s, {s['impacts']} "
            f"impact(s), collapsed: {s['collapse']['collapsed']}>"
        )


class _CsvTexts:
    """What an unpickled :class:`Result` keeps of its native run: the texts of its CSV files and
    of its summary.json."""

    __slots__ = ("_history", "_impacts", "_openings", "_hops", "summary_json")

    def __init__(self, history: str, impacts: str, openings: str, hops: str, summary: str) -> None:
        self._history = history
        self._impacts = impacts
        self._openings = openings
        self._hops = hops
        self.summary_json = summary

    def history_csv(self) -> str:
        return self._history

    def impacts_csv(self) -> str:
        return self._impacts

    def hops_csv(self) -> str:
        return self._hops

    def openings_csv(self) -> str:
        return self._openings


def simulate(
    model: Union[Model, PathLike],
    ground_motion: GroundMotion = None,
    initial: Optional[Mapping[str, Any]] = None,
    duration: Optional[float] = None,
    max_samples: Optional[int] = None,
    **analysis: Any,
) -> Result:
    """Runs a model as ``crr simulate`` does and returns its results (nothing is written).

    Args:
        model: a :class:`Model`, or the path of a model file.
        ground_motion: None (the model's own ``[ground_motion]``); a :class:`Record` or a list
            of them (each replaces its component of the model's motion, as ``--record``; at
            most one record file); a pair ``(t, a)`` of arrays (s, m/s²) driving ``x``; or a
            mapping that replaces the whole ``[ground_motion]`` table (same keys as the model
            file, ``docs/ground-motion.md``; record paths relative to the model's folder).
        initial: replaces the ``[initial]`` table: ``{"angles": {name: rad}, "rates":
            {name: rad/s}}``.
        duration: simulated time (s), as ``--duration``; default the ``[analysis]`` duration,
            else the ground motion's duration + 5 s, else 10 s.
        max_samples: most output samples kept in memory; past them the run stops (a
            :class:`SimulationError` with the results until then). By default, what fits in
            80 % of the memory this process can still take, and a run whose samples alone would
            not fit raises :class:`OutOfMemoryError` (a ``MemoryError``) before it starts.
        **analysis: keys of the ``[analysis]`` table that override the model's (``rtol``,
            ``atol``, ``method``, ``output_interval`` s, ``max_step`` s, ``friction``, …).

    Warns:
        CrrWarning: one per string of ``summary["warnings"]`` (a loose tolerance, an energy
            balance off, the rigid-contact hypotheses failing, a history of gigabytes, …).

    Raises:
        InputError: invalid model tables, records or arguments (the command line's message).
        FileError: a record file that cannot be read.
        SimulationError: the run failed part-way; its ``result`` holds the partial results.
        KeyboardInterrupt: Ctrl-C (SIGINT) during the run stops it after its current step,
            within a few hundredths of a second; the exception's ``result`` holds the results
            until then (``result.summary["error"]`` says it was interrupted).
    """
    if not isinstance(model, Model):
        model = Model.from_file(model)
    native = model._native
    gm_json: Optional[str] = None
    record_file: Optional[Tuple[str, str, Optional[str], str, float]] = None
    arrays: List[Tuple[str, List[float], List[float], str, float]] = []
    if ground_motion is None:
        pass
    elif isinstance(ground_motion, Mapping):
        gm_json = _json(ground_motion, "ground_motion")
    else:
        if isinstance(ground_motion, Record):
            records: List[Record] = [ground_motion]
        elif (
            isinstance(ground_motion, tuple)
            and len(ground_motion) == 2
            and not isinstance(ground_motion[0], Record)
        ):
            records = [Record.from_arrays(ground_motion[0], ground_motion[1])]
        else:
            records = list(ground_motion)  # type: ignore[arg-type]
        driven: Dict[str, Record] = {}
        for r in records:
            if not isinstance(r, Record):
                raise TypeError(f"ground_motion: expected crr.Record items, got {type(r).__name__}")
            if r.component in driven:
                # Each replaces its component: a second one would silently win.
                raise InputError(
                    f"ground_motion: two records drive component {r.component!r} "
                    "(each record replaces its component; give one per component)"
                )
            driven[r.component] = r
            if r.path is not None:
                if record_file is not None:
                    raise InputError("ground_motion: at most one record file per run")
                if r.format is None:
                    raise InputError("Record.from_file needs format='peer-at2', 'csv' or 'text'")
                record_file = (r.path, r.format, r.units, r.component, r.scale)
            else:
                assert r.t is not None and r.a is not None
                arrays.append(
                    (r.component, r.t.tolist(), r.a.tolist(), r.units or "m/s2", r.scale)
                )
    init_json = _json(initial, "initial") if initial is not None else None
    unknown = sorted(set(analysis) - set(_crr.ANALYSIS_KEYS))
    if unknown:
        raise TypeError(
            f"simulate() got an unexpected keyword argument {unknown[0]!r} (besides model, "
            "ground_motion, initial and duration it takes the keys of [analysis]: "
            + ", ".join(_crr.ANALYSIS_KEYS)
            + ")"
        )
    if duration is not None:
        d = float(duration)
        if not (np.isfinite(d) and d > 0.0):
            raise InputError(f"duration must be a positive number of seconds, got {duration!r}")
    analysis_json: Optional[str] = None
    if analysis:
        table = dict(model.to_dict().get("analysis") or {})
        table.update(analysis)
        analysis_json = _json(table, "analysis")
    try:
        run = _crr.simulate(
            native,
            ground_motion=gm_json,
            initial=init_json,
            analysis=analysis_json,
            record_file=record_file,
            records=arrays,
            duration=None if duration is None else float(duration),
            max_samples=None if max_samples is None else _positive_count("max_samples", max_samples),
            memory=_memory_available() if max_samples is None else None,
        )
    except KeyboardInterrupt as interrupt:
        # Ctrl-C stops the run after its current step; what it computed rides on the exception.
        partial = getattr(interrupt, "run", None)
        if partial is not None:
            interrupt.result = Result(partial, model.coordinates, model.interfaces)  # type: ignore[attr-defined]
        raise
    result = Result(run, model.coordinates, model.interfaces)
    for message in result.summary.get("warnings") or []:
        warnings.warn(CrrWarning(message), stacklevel=2)
    if run.error is not None:
        raise SimulationError(f"{model.source}: the simulation failed: {run.error}", result)
    return result


Range = Union[str, Sequence[Any]]


def _range_text(name: str, r: Range, in_g: bool = False) -> str:
    """A range as the command line takes it, ``START:END:COUNT``, from that text or from a
    sequence ``(start, end, count)`` (with ``in_g``, its ends may be accelerations in g as
    ``"0.3g"``)."""
    if isinstance(r, str):
        return r
    items = list(r)
    if len(items) != 3:
        raise InputError(f"{name} must be (start, end, count) or 'START:END:COUNT', got {r!r}")
    start, end, count = items
    ends = f"{_number_text(name, start, in_g)}:{_number_text(name, end, in_g)}"
    return f"{ends}:{_positive_count(name + ' count', count)}"


def _number_text(name: str, x: Any, in_g: bool = False) -> str:
    """A number as text for the command line's parser, written exactly (``repr``); with
    ``in_g`` a string is passed on as given (an acceleration in g, ``"0.3g"``)."""
    if isinstance(x, str) and in_g:
        return x
    if isinstance(x, bool) or not isinstance(x, (int, float, np.integer, np.floating)):
        raise InputError(f"{name}: expected a number, got {x!r}")
    return repr(float(x))


class Poincare:
    """What ``crr poincare`` computes (``docs/poincare.md``): a section, a bifurcation sweep or
    basins of initial conditions, as the command line's data file and ``poincare.json``.

    Attributes:
        kind: ``"section"`` (the data file ``poincare.csv``), ``"bifurcation"``
            (``bifurcation.csv``) or ``"basins"`` (``basins.csv``).
        csv: the text of that data file, byte for byte what ``crr poincare`` writes.
        summary: ``poincare.json`` as a dict (the settings, and for a section its points,
            distinct points, period, overturning, error; for a sweep the same per case).
    """

    _KINDS = {"poincare.csv": "section", "bifurcation.csv": "bifurcation", "basins.csv": "basins"}

    def __init__(self, texts: Tuple[str, str, str]) -> None:
        name, csv, summary = texts
        self._name = name
        self.kind: str = self._KINDS[name]
        self.csv: str = csv
        self._summary_json = summary
        self.summary: Dict[str, Any] = json.loads(summary)

    def frame(self) -> "pandas.DataFrame":
        """The data file as a pandas DataFrame: the section's points (``k``, ``t``, every
        coordinate and ``<coordinate>_rate``, every ``<interface>_state`` as text), the sweep's
        points (``case``, the parameter, ``k``, ``t``, the coordinate and its rate) or the
        basins' cases (``angle``, ``rate``, ``outcome`` as text, ``end_time``, ``points``,
        ``overturn_time``, NaN where the case did not overturn)."""
        pd = _pandas("Poincare.frame")
        header = self.csv.split("\n", 1)[0].split(",")
        text_columns = [c for c in header if c.endswith("_state") or c == "outcome"]
        return pd.read_csv(
            io.StringIO(self.csv), dtype={c: object for c in text_columns}, keep_default_na=False,
            na_values={c: [""] for c in header if c not in text_columns},
        )

    def write(self, folder: PathLike) -> None:
        """Writes the data file and ``poincare.json`` into ``folder`` (created if needed), as
        ``crr poincare --out folder`` names them."""
        d = Path(folder)
        d.mkdir(parents=True, exist_ok=True)
        for name, text in ((self._name, self.csv), ("poincare.json", self._summary_json)):
            with open(d / name, "w", newline="", encoding="utf-8") as f:
                f.write(text)

    def __repr__(self) -> str:
        s = self.summary
        if s.get("section") is not None:
            sec = s["section"]
            return (
                f"<crr.Poincare section: {sec['points']} point(s), {sec['distinct_points']} "
                f"distinct, period {sec['period']}, overturned: {sec['overturned']}>"
            )
        return f"<crr.Poincare {self.kind}: {len(s.get('cases') or [])} case(s)>"


def poincare(
    model: Union[Model, PathLike],
    amplitude: Union[float, str] = 0.0,
    frequency: Optional[float] = None,
    *,
    component: str = "x",
    phase: float = 0.0,
    periods: int = 100,
    transient: int = 100,
    section: Optional[str] = None,
    coordinate: Optional[str] = None,
    duration: Optional[float] = None,
    rest: bool = False,
    amplitudes: Optional[Range] = None,
    frequencies: Optional[Range] = None,
    grid: Optional[Tuple[Range, Range]] = None,
    jobs: Optional[int] = None,
) -> Poincare:
    """Poincaré sections, bifurcation diagrams and basins, as ``crr poincare`` computes them
    (``docs/poincare.md``; nothing is written: :meth:`Poincare.write` writes its files).

    The model is driven by a_g(t) = A sin(2πF t + φ) on one component, which replaces its own
    ground motion, and sampled at t = k/F (a stroboscopic section), or where a coordinate crosses
    0 upward (a crossing section: ``section=NAME``, or ``amplitude=0``).

    Args:
        model: a :class:`Model`, or the path of a model file.
        amplitude: A, m/s², or a string in g (``"0.3g"``); 0: no forcing (a crossing section).
        frequency: F, Hz.
        component: ``"x"``, ``"y"`` or ``"z"``.
        phase: φ, rad.
        periods: N, the points kept; transient: M, the periods (or crossings) dropped first.
        section: a crossing section of this coordinate.
        coordinate: the coordinate of a bifurcation diagram and of the basins grid.
        duration: time limit of a crossing section (s; default 1000).
        rest: start from rest instead of the model's ``[initial]``.
        amplitudes, frequencies: a bifurcation sweep, ``(start, end, count)`` or
            ``"START:END:COUNT"`` (amplitudes in m/s², or strings in g).
        grid: basins, ``((θ0, θ1, n), (ω0, ω1, m))`` in rad × rad/s, or ``"T0:T1:N,W0:W1:M"``.
        jobs: worker threads of a sweep (None or -1: one per core); results do not depend on it.

    Raises:
        InputError: invalid arguments or model, named as here (the command line's checks).
        KeyboardInterrupt: Ctrl-C stops the cases under way within one integration step; the
            exception's ``result`` is a :class:`Poincare` of the points computed until then
            (the cases stopped or not started have an ``error`` in its summary).
    """
    if not isinstance(model, Model):
        model = Model.from_file(model)
    grid_text: Optional[str] = None
    if grid is not None:
        if isinstance(grid, str):
            grid_text = grid
        else:
            parts = list(grid)
            if len(parts) != 2:
                raise InputError(
                    f"grid must be ((θ0, θ1, n), (ω0, ω1, m)) or 'T0:T1:N,W0:W1:M', got {grid!r}"
                )
            grid_text = f"{_range_text('grid (angles)', parts[0])},{_range_text('grid (rates)', parts[1])}"
    counts = {}
    for name, value, least in (("periods", periods, 1), ("transient", transient, 0)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < least:
            raise InputError(f"{name} must be an integer ≥ {least}, got {value!r}")
        counts[name] = int(value)
    try:
        texts = model._native.poincare(
            _number_text("amplitude", amplitude, in_g=True),
            None if frequency is None else float(frequency),
            str(component),
            float(phase),
            counts["periods"],
            counts["transient"],
            section,
            coordinate,
            None if duration is None else float(duration),
            bool(rest),
            None if amplitudes is None else _range_text("amplitudes", amplitudes, in_g=True),
            None if frequencies is None else _range_text("frequencies", frequencies),
            grid_text,
            _jobs(jobs),
        )
    except KeyboardInterrupt as interrupt:
        partial = getattr(interrupt, "poincare", None)
        if partial is not None:
            interrupt.result = Poincare(partial)  # type: ignore[attr-defined]
        raise
    return Poincare(texts)


class Study:
    """A study (``docs/studies.md``): one model under a pulse family's amplitude × frequency
    grid, or records scaled to intensity levels, expanded into cases with stable ids
    (``c000000``, …). Build it with :meth:`from_file`, :meth:`from_toml` or :meth:`from_dict`.
    """

    __slots__ = ("_native", "_source")

    def __init__(self, native: _crr.Study, source: Tuple[str, ...]) -> None:
        self._native = native
        self._source = source

    @classmethod
    def from_file(cls, path: PathLike) -> "Study":
        """Reads a study file (TOML), its model and its records; the model and record paths are
        relative to the file's folder."""
        p = _fspath(path)
        return cls(_crr.Study.load(p), ("file", p))

    @classmethod
    def from_toml(cls, text: str, base_dir: Optional[PathLike] = None) -> "Study":
        """A study from the text of a study file, read as if it were the file
        ``base_dir/study.toml`` (``base_dir`` default the working folder): model and record
        paths relative to ``base_dir``, default name ``study``."""
        label = os.path.join(_fspath(base_dir) if base_dir is not None else ".", "study.toml")
        return cls(_crr.Study.parse(text, False, label), ("toml", text, label))

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], base_dir: Optional[PathLike] = None) -> "Study":
        """A study from a mapping with the keys of a study file, read as :meth:`from_toml`."""
        label = os.path.join(_fspath(base_dir) if base_dir is not None else ".", "study.toml")
        text = _json(d, label=label)
        return cls(_crr.Study.parse(text, True, label), ("json", text, label))

    @property
    def name(self) -> str:
        """The study's name."""
        return self._native.name

    @property
    def case_ids(self) -> List[str]:
        """The ids of the cases, in order."""
        return list(self._native.case_ids)

    @property
    def columns(self) -> List[str]:
        """The columns of ``cases.csv``."""
        return self._native.header.split(",")

    def __len__(self) -> int:
        return len(self._native)

    def run_rows(
        self, ids: Optional[Sequence[str]] = None, jobs: Optional[int] = None
    ) -> List[str]:
        """Runs the cases ``ids`` (default all) on ``jobs`` threads (default one per core) and
        returns their lines of ``cases.csv`` (without newlines), in the order of ``ids``."""
        return self._native.run_rows(None if ids is None else list(ids), _jobs(jobs))

    def csv(self, rows: Sequence[str]) -> str:
        """The text of ``cases.csv`` from rows given in any order, as ``crr study`` writes it
        (header, then the rows in case-id order)."""
        return self._native.csv(list(rows))

    def run(
        self, jobs: Optional[int] = None, out: Optional[PathLike] = None, progress: bool = False
    ) -> "pandas.DataFrame":
        """Runs every case and returns the DataFrame of ``cases.csv``; see :func:`study`."""
        return _warn_outside_model(self._frame(jobs, out, progress), stacklevel=2)

    def _frame(
        self, jobs: Optional[int], out: Optional[PathLike], progress: bool
    ) -> "pandas.DataFrame":
        """:meth:`run` without its warning."""
        # Before any case runs: without pandas the rows would be computed and then lost.
        _pandas("a study's DataFrame")
        self._warn_before_running(stacklevel=4)
        if out is not None:
            self._native.run_into(_fspath(out), _jobs(jobs), progress)
            text = (Path(out) / "cases.csv").read_text()
        elif progress:
            text = self.csv(self._rows_with_progress(_jobs(jobs)))
        else:
            text = self.csv(self.run_rows(None, jobs))
        return cases_frame(text)

    def _warn_before_running(self, stacklevel: int) -> None:
        """Issues the study's warnings found before any case runs (a ``duration`` that cuts
        motions short), as ``crr study`` prints them first."""
        for message in self._native.warnings:
            warnings.warn(CrrWarning(message), stacklevel=stacklevel)

    def _rows_with_progress(self, jobs: Optional[int]) -> List[str]:
        """Every case's row, run in batches of a few cases per thread, with a tqdm bar when tqdm
        is installed, else a line on stderr updated in place."""
        ids = self.case_ids
        batch = 8 * (jobs or os.cpu_count() or 1)
        try:
            from tqdm import tqdm  # type: ignore[import-untyped]

            bar: Any = tqdm(total=len(ids), unit="case", desc=self.name)
        except ImportError:
            bar = _ProgressLine(self.name, len(ids))
        rows: List[str] = []
        try:
            for start in range(0, len(ids), batch):
                chunk = ids[start : start + batch]
                rows.extend(self.run_rows(chunk, jobs))
                bar.update(len(chunk))
        finally:
            bar.close()
        return rows

    def __reduce__(self) -> Tuple[Any, Tuple[Tuple[str, ...]]]:
        # Rebuilt from its description (file path, or text and folder): what a Dask worker or a
        # process pool receives.
        return (_load_study, (self._source,))

    def __repr__(self) -> str:
        return repr(self._native)


class _ProgressLine:
    """A progress line on stderr, rewritten in place (what a study shows without tqdm)."""

    def __init__(self, name: str, total: int) -> None:
        self._name, self._total, self._done = name, total, 0
        self._start = time.monotonic()

    def update(self, n: int) -> None:
        self._done += n
        pct = 100.0 * self._done / max(self._total, 1)
        elapsed = time.monotonic() - self._start
        sys.stderr.write(
            f"\rcrr: {self._name}: {self._done}/{self._total} cases ({pct:.0f} %), {elapsed:.1f} s"
        )
        sys.stderr.flush()

    def close(self) -> None:
        sys.stderr.write("\n")
        sys.stderr.flush()


def _load_study(source: Tuple[str, ...]) -> Study:
    """A study from the description :attr:`Study._source` (what a Dask worker receives)."""
    kind = source[0]
    if kind == "file":
        return Study(_crr.Study.load(source[1]), source)
    return Study(_crr.Study.parse(source[1], kind == "json", source[2]), source)


def _pandas(what: str) -> Any:
    """pandas, or an ImportError saying what needs it and which extra installs it."""
    try:
        import pandas
    except ImportError as e:
        raise ImportError(
            f"{what} needs pandas, which is not installed: pip install 'crr-rocking[pandas]' "
            "(or 'crr-rocking[dask]' for crr.dask)"
        ) from e
    return pandas


#: The text columns of ``cases.csv``: read as text whatever they hold, so that a study whose
#: cases all ran cleanly (``violation``, ``violation_interface`` and ``error`` all empty) still
#: takes ``frame["error"].str`` (read alone, an all-empty column is a float64 of NaN).
CASES_TEXT_COLUMNS = ("id", "record", "status", "violation", "violation_interface", "error")


def cases_frame(text: str) -> "pandas.DataFrame":
    """The text of a ``cases.csv`` as a pandas DataFrame, every number read back exactly; the
    empty cells are NaN. The text columns (:data:`CASES_TEXT_COLUMNS`) are text (``object``)
    whatever their values, ``collapse`` is a nullable integer (``Int64``: empty for a case
    stopped by an error before it could tell)."""
    pd = _pandas("a study's DataFrame")
    header = text.split("\n", 1)[0].split(",")
    dtype: Dict[str, Any] = {c: object for c in CASES_TEXT_COLUMNS if c in header}
    if "collapse" in header:
        dtype["collapse"] = "Int64"
    # pandas < 3 reads floats exactly only with the round-trip converter; pandas 3 always does
    # (and deprecates the option).
    if int(pd.__version__.split(".")[0]) >= 3:
        frame = pd.read_csv(io.StringIO(text), dtype=dtype)
    else:  # pragma: no cover
        frame = pd.read_csv(io.StringIO(text), dtype=dtype, float_precision="round_trip")
    frame.attrs["cases_csv"] = text
    return frame


def _warn_outside_model(frame: "pandas.DataFrame", stacklevel: int) -> "pandas.DataFrame":
    """Issues a :class:`CrrWarning`, as ``crr study`` warns on stderr, when some cases' runs left
    crr's model (their ``violation_time_s`` is filled: the rigid-contact hypotheses fail, see
    ``docs/studies.md``); returns ``frame``. ``stacklevel`` counts from the caller of this
    function, as :func:`warnings.warn`'s does from its own caller. Cases that stopped with an
    error (``status`` ``error``) are warned about too, as ``crr study`` does."""
    if "status" in frame.columns:
        failed = int((frame["status"] == "error").sum())
        if failed:
            warnings.warn(
                CrrWarning(
                    f"{failed} of the {len(frame)} case(s) stopped with an error (status "
                    "`error`, the message in column `error`): they have no outcome"
                ),
                stacklevel=stacklevel + 1,
            )
    if "violation_time_s" in frame.columns:
        outside = int(frame["violation_time_s"].notna().sum())
        if outside:
            warnings.warn(
                CrrWarning(
                    f"{outside} of the {len(frame)} case(s) left crr's model (the rigid-contact "
                    "hypotheses fail: a flight, a resultant outside its face, sliding, an "
                    "impulse that pulls or a lift-off it cannot follow; columns "
                    "violation_time_s, violation, violation_interface): their results after "
                    "that time are outside the model"
                ),
                stacklevel=stacklevel + 1,
            )
    return frame


def study(
    study: Union[Study, PathLike, Mapping[str, Any]],
    jobs: Optional[int] = None,
    out: Optional[PathLike] = None,
    progress: bool = False,
) -> "pandas.DataFrame":
    """Runs every case of a study, as ``crr study``, and returns ``cases.csv`` as a pandas
    DataFrame (same columns; ``frame.attrs["cases_csv"]`` holds the file's exact text).

    Args:
        study: a :class:`Study`, the path of a study file, a mapping of its keys, or the text
            of a study file (a string with a newline; read as :meth:`Study.from_toml`).
        jobs: worker threads (default one per core); the results do not depend on it.
        out: when given, the study is run into this folder exactly as
            ``crr study FILE --out OUT`` (``cases.csv``, ``study.json``; a rerun resumes).
        progress: show progress on stderr: with ``out``, the command line's progress line;
            otherwise a tqdm bar when tqdm is installed, else a line updated in place. The rows
            are the same either way.

    Warns:
        CrrWarning: when some cases' runs left crr's model (a hypotheses violation, in their
            ``violation_time_s``, ``violation`` and ``violation_interface`` columns), with the
            count, as ``crr study`` warns; and before any case runs, when the study's
            ``duration`` ends cases before their ground motion does (a collapse after it would
            not be seen).
    """
    return _warn_outside_model(_as_study(study)._frame(jobs, out, progress), stacklevel=2)


def _as_study(study: Union[Study, PathLike, Mapping[str, Any]]) -> Study:
    """A :class:`Study` from a study, a mapping, TOML text (a string with a newline) or a path."""
    if isinstance(study, Study):
        return study
    if isinstance(study, Mapping):
        return Study.from_dict(study)
    if isinstance(study, str) and "\n" in study:
        return Study.from_toml(study)
    return Study.from_file(study)

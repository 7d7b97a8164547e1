"""The exceptions of crr. Their messages are those the command line prints after ``crr: error:``."""

from __future__ import annotations

from typing import Any, Optional

__all__ = [
    "CrrError",
    "InputError",
    "FileError",
    "MissingFileError",
    "OutOfMemoryError",
    "SimulationError",
    "CrrWarning",
]


class CrrError(Exception):
    """Base class of every error raised by crr."""


class InputError(CrrError, ValueError):
    """A model, study, record or argument that is not valid (the command line exits with 2)."""


class FileError(CrrError, OSError):
    """A file that cannot be read or a folder that cannot be written (the command line exits
    with 2). ``errno`` and ``filename`` are those of the operating system's error (None when
    unknown); the message is the command line's."""

    def __init__(
        self, message: str, errno: Optional[int] = None, filename: Optional[Any] = None
    ) -> None:
        if errno is None:
            super().__init__(message)
        else:
            super().__init__(errno, message, str(filename) if filename is not None else None)
        self._message = message

    def __str__(self) -> str:
        return self._message

    def __reduce__(self) -> Any:
        return (type(self), (self._message, self.errno, self.filename))


class MissingFileError(FileError, FileNotFoundError):
    """A file that does not exist: a :class:`FileError` that ``except FileNotFoundError``
    catches too."""


class SimulationError(CrrError, RuntimeError):
    """A run that failed part-way (the command line writes the partial results and exits with 1).

    ``result`` holds what was computed until the failure (``result.summary["completed"]`` is
    false, ``result.summary["error"]`` says why).
    """

    def __init__(self, message: str, result: Optional[Any] = None) -> None:
        super().__init__(message)
        self.result = result


class OutOfMemoryError(CrrError, MemoryError):
    """A run whose output samples would not fit in the memory this process can still take,
    refused before it starts (the message gives the estimate and what to change)."""


class CrrWarning(UserWarning):
    """What a user must know before trusting a run's results: each string of
    ``summary["warnings"]`` (the lines the command line prints after ``crr: warning:``) is
    raised as one, so that ``warnings.simplefilter("error", crr.CrrWarning)`` makes them fatal."""


# Shown and pickled as crr.CrrError, crr.InputError, … (the names the package exports).
for _cls in (
    CrrError,
    InputError,
    FileError,
    MissingFileError,
    OutOfMemoryError,
    SimulationError,
    CrrWarning,
):
    _cls.__module__ = "crr"

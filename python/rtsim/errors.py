"""The exceptions rtsim raises for bad input, in pure Python so that catching them does not load
the C++ extension. ``rtsim._core`` raises the same ``RtsimError`` class for C++ errors."""

from __future__ import annotations


class RtsimError(RuntimeError):
    """Bad input: a file, field, key or ray that rtsim cannot use; the message names it."""


class UnknownSceneError(RtsimError, ValueError):
    """A scene name that is not a file, not a built-in scene and not a shared scene."""


class HitMismatchError(RtsimError):
    """A simulation whose hits or work counts differ from the reference tracer's (exit 3).
    ``stats`` holds the run's stats; ``stats.validation`` lists the first differences."""

    def __init__(self, message: str, stats: object) -> None:
        super().__init__(message)
        self.stats = stats

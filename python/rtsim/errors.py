"""The exceptions rtsim raises for bad input, in pure Python so that catching them does not load
the C++ extension. ``rtsim._core`` raises the same ``RtsimError`` class for C++ errors.

Every one is an ``RtsimError``; where Python's conventions call for a built-in type, it is also
that type: a bad argument value is a ``ValueError``, an argument of the wrong type a
``TypeError``, an index out of range an ``IndexError``.
"""

from __future__ import annotations


class RtsimError(RuntimeError):
    """Bad input: a file, field, key or ray that rtsim cannot use; the message names it."""


class ArgumentValueError(RtsimError, ValueError):
    """An argument of a usable type whose value rtsim cannot use (width=0, timeout=-1)."""


class ArgumentTypeError(RtsimError, TypeError):
    """An argument of a type rtsim does not take (None for a path, a string for a size)."""


class RtsimIndexError(RtsimError, IndexError):
    """An index past the end of what it indexes (a frame the trace does not have)."""


class UnknownSceneError(RtsimError, ValueError):
    """A scene name that is not a file, not a built-in scene and not a shared scene."""


class HitMismatchError(RtsimError):
    """A simulation whose hits or work counts differ from the reference tracer's (exit 3).
    ``stats`` holds the run's stats; ``stats.validation`` lists the first differences."""

    def __init__(self, message: str, stats: object) -> None:
        super().__init__(message)
        self.stats = stats

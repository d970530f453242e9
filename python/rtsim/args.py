"""Checks of the Python API's arguments, so a misuse raises an RtsimError that names the argument
(also a TypeError or ValueError, rtsim/errors.py) instead of pybind11's "incompatible function
arguments", a bare OverflowError or a traceback from deep inside. Standard library only."""

from __future__ import annotations

import math
import numbers
import os
from typing import Any

from rtsim.errors import ArgumentTypeError, ArgumentValueError

UINT32_MAX = 2**32 - 1
UINT64_MAX = 2**64 - 1


def _kind(value: Any) -> str:
    return type(value).__name__


def path_arg(value: Any, name: str) -> str:
    """A filesystem path as str: str, bytes or os.PathLike; it must be valid UTF-8, because rtsim
    records paths in JSON (manifests, provenance) and in its messages."""
    if isinstance(value, (str, bytes, os.PathLike)):
        try:
            text = os.fsdecode(value)
        except TypeError as err:  # os.PathLike returning something else
            raise ArgumentTypeError(f"{name}: {err}") from err
    else:
        raise ArgumentTypeError(f"{name}: expected a path (str or os.PathLike), got {_kind(value)}")
    if not text:
        raise ArgumentValueError(f"{name}: the path is empty")
    if "\0" in text:
        raise ArgumentValueError(f"{name}: {text!r} contains a NUL byte")
    check_utf8_path(text, name)
    return text


def check_utf8_path(text: str, name: str) -> None:
    """Refuses a path holding bytes that are not UTF-8 (os.fsdecode keeps them as surrogates)."""
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        shown = os.fsencode(text)
        raise ArgumentValueError(
            f"{name}: the path {shown!r} is not valid UTF-8; rtsim records paths in JSON "
            "(manifests, provenance): rename the file or folder"
        ) from None


def int_arg(
    value: Any, name: str, lo: int, hi: int, range_error: type[Exception] = ArgumentValueError
) -> int:
    """An integer in [lo, hi] (bool refused; numpy integers and integer-valued floats taken);
    out of range raises `range_error` (RtsimIndexError for an index)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ArgumentTypeError(f"{name}: expected an integer, got {_kind(value)} {value!r}")
    integral = isinstance(value, numbers.Integral)
    if not integral and not (math.isfinite(float(value)) and float(value).is_integer()):
        raise ArgumentValueError(f"{name}: expected an integer, got {value!r}")
    number = int(value)
    if not lo <= number <= hi:
        raise range_error(f"{name}: {number} is out of range ({lo}..{hi})")
    return number


def float_arg(value: Any, name: str, finite: bool = True) -> float:
    """A real number (bool refused), finite unless `finite` is False."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ArgumentTypeError(f"{name}: expected a number, got {_kind(value)} {value!r}")
    number = float(value)
    if finite and not math.isfinite(number):
        raise ArgumentValueError(f"{name}: expected a finite number, got {number}")
    return number


def timeout_arg(value: Any) -> float | None:
    """Seconds before a run is killed: None or infinity for none, else a positive number."""
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ArgumentTypeError(f"timeout: expected seconds (a number) or None, got {value!r}")
    seconds = float(value)
    if seconds == math.inf:
        return None
    if not (seconds > 0 and math.isfinite(seconds)):
        raise ArgumentValueError(
            f"timeout: {seconds:g} is not a positive number of seconds (None: no timeout)"
        )
    return seconds


def bool_arg(value: Any, name: str) -> bool:
    """A truth value: bool or numpy bool (not a string: "false" would be true)."""
    if isinstance(value, bool) or (
        type(value).__module__ == "numpy" and type(value).__name__ in ("bool", "bool_")
    ):
        return bool(value)
    raise ArgumentTypeError(f"{name}: expected True or False, got {_kind(value)} {value!r}")

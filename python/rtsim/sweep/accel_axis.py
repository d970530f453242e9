"""The sweep's `accel` axis: which acceleration structures (and builders) each scene is traced
with (docs/sweeps.md, "Acceleration structures").

An entry is ``KIND`` or ``KIND:BUILDER`` (``bvh8``, ``bvh2:sbvh``), or a mapping
``{kind: bvh2, builder: sbvh, label: sbvh}``. Kinds and builders are checked against the
structures this build registers (``rtsim trace --help``); an empty builder means the kind's
default (its first). The trace cache keys on the kind, the resolved builder and the trace format
version, so a trace of another structure, builder or format is never reused.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

#: The structure a spec without an `accel` key traces with (the tracer's default).
DEFAULT_KIND = "bvh2"


@dataclass(frozen=True)
class AccelSpec:
    """One acceleration structure of the axis: kind, builder (resolved) and display label."""

    label: str
    kind: str
    builder: str  # resolved: never empty

    def key(self, trace_version: int) -> dict[str, Any]:
        return {"kind": self.kind, "builder": self.builder, "trace_version": trace_version}


def registered_kinds() -> dict[str, list[str]]:
    """kind -> its builders (first: the default), from the C++ registry of this build."""
    from rtsim import _core

    return {k["name"]: list(k["builders"]) for k in _core.accel_kinds()}


def trace_format_version() -> int:
    """The trace format version this build writes (a trace cache key)."""
    from rtsim import _core

    return int(_core.trace_version)


def default_accel(kinds: dict[str, list[str]] | None = None) -> AccelSpec:
    builders = (kinds if kinds is not None else registered_kinds()).get(DEFAULT_KIND) or [""]
    return AccelSpec(DEFAULT_KIND, DEFAULT_KIND, builders[0])


def parse_accel_entry(
    entry: Any, kinds: dict[str, list[str]], fail: Callable[[str, str], Exception]
) -> AccelSpec:
    """One entry of the axis. fail(subkey, message) builds the error naming the entry's key
    (subkey "" for the entry itself, "kind"/"builder"/"label" for a mapping's fields)."""
    if isinstance(entry, str):
        kind, sep, builder = entry.strip().partition(":")
        if sep and not builder:
            raise fail("", f"{entry!r}: expected KIND or KIND:BUILDER (builder missing)")
        label = entry.strip()
    elif isinstance(entry, dict):
        unknown = [k for k in entry if k not in ("kind", "builder", "label")]
        if unknown:
            raise fail(str(unknown[0]), "unknown key (expected one of: kind, builder, label)")
        kind = entry.get("kind")
        if not isinstance(kind, str) or not kind:
            raise fail("kind", "missing (a structure's name, e.g. bvh8)")
        builder = entry.get("builder", "")
        if not isinstance(builder, str):
            raise fail("builder", f"expected a builder name, got {builder!r}")
        label = str(entry.get("label") or (f"{kind}:{builder}" if builder else kind))
    else:
        raise fail("", f"expected KIND, KIND:BUILDER or a mapping with kind, got {entry!r}")
    if kind not in kinds:
        raise fail(
            "kind" if isinstance(entry, dict) else "",
            f"unknown acceleration structure {kind!r}; this build has: {', '.join(kinds)}",
        )
    if builder and builder not in kinds[kind]:
        raise fail(
            "builder" if isinstance(entry, dict) else "",
            f"{kind} has no builder {builder!r}; it takes: {', '.join(kinds[kind])}",
        )
    return AccelSpec(label, kind, builder or kinds[kind][0])


def folder_label(accel: AccelSpec) -> str:
    """The label as a file-name part (bvh2:sbvh -> bvh2-sbvh)."""
    return "".join(c if c.isalnum() or c in "_-." else "-" for c in accel.label)

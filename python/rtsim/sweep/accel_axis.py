"""The sweep's `accel` axis: which acceleration structures (and builders) each scene is traced
with (docs/sweeps.md, "Acceleration structures").

An entry is ``KIND`` or ``KIND:BUILDER`` (``bvh8``, ``bvh2:sbvh``), or a mapping
``{kind: bvh2, builder: sbvh, label: sbvh, build: {alpha: 1e-4}}``. Kinds and builders are checked
against the structures this build registers (``rtsim trace --help``); an empty builder means the
kind's default (its first). ``build`` overrides the builder's documented settings (``rtsim trace
--build-set``; docs/accel.md, "Builder settings"); a list of values makes one entry per value (the
cross product over several lists), so builder settings are a sweep axis:
``{kind: kdtree, build: {empty_bonus: [0, 0.2, 0.5]}}`` traces three kd-trees, labelled
``kdtree empty_bonus=0``, ... The trace cache keys on the kind, the resolved builder, the settings
given and the trace format version, so a trace of another structure, builder, settings or format
is never reused.
"""

from __future__ import annotations

import itertools
import math
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
    settings: tuple[tuple[str, Any], ...] = ()  # builder settings given (name, value), sorted

    def key(self, trace_version: int) -> dict[str, Any]:
        key: dict[str, Any] = {
            "kind": self.kind,
            "builder": self.builder,
            "trace_version": trace_version,
        }
        if self.settings:  # (absent without settings: the keys of earlier sweeps stay valid)
            key["build"] = dict(self.settings)
        return key


def registered_kinds() -> dict[str, list[str]]:
    """kind -> its builders (first: the default), from the C++ registry of this build."""
    from rtsim import _core

    return {k["name"]: list(k["builders"]) for k in _core.accel_kinds()}


def registered_settings(kind: str, builder: str) -> dict[str, dict[str, Any]]:
    """The settings a kind's builder takes: name -> {type, default, unit, min, max, doc}."""
    from rtsim import _core

    for k in _core.accel_kinds():
        if k["name"] == kind:
            return dict(k["settings"].get(builder, {}))
    return {}


def check_setting(name: str, value: Any, schema: dict[str, dict[str, Any]]) -> str:
    """'' when value suits setting `name`, else what is wrong (naming what it takes)."""
    if name not in schema:
        return f"unknown setting; the builder takes: {', '.join(schema) or 'none'}"
    field = schema[name]
    if field["type"] == "bool":
        return "" if isinstance(value, bool) else f"expected true or false, got {value!r}"
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return f"expected a number, got {value!r}"
    if field["type"] == "int" and float(value) != int(value):
        return f"expected an integer, got {value!r}"
    if not field["min"] <= value <= field["max"]:
        return f"{value!r} is out of range [{field['min']:g}, {field['max']:g}] {field['unit']}"
    return ""


def trace_format_version() -> int:
    """The trace format version this build writes (a trace cache key)."""
    from rtsim import _core

    return int(_core.trace_version)


def default_accel(kinds: dict[str, list[str]] | None = None) -> AccelSpec:
    builders = (kinds if kinds is not None else registered_kinds()).get(DEFAULT_KIND) or [""]
    return AccelSpec(DEFAULT_KIND, DEFAULT_KIND, builders[0])


def parse_accel_entries(
    entry: Any,
    kinds: dict[str, list[str]],
    fail: Callable[[str, str], Exception],
    limit: int | None = None,
) -> list[AccelSpec]:
    """One entry of the axis, expanded over the lists in its `build` settings. fail(subkey,
    message) builds the error naming the entry's key (subkey "" for the entry itself,
    "kind"/"builder"/"label"/"build" for a mapping's fields). An entry that would expand into
    more than `limit` structures is refused from the lists' lengths, before any is made."""
    build: dict[str, Any] = {}
    explicit_label = isinstance(entry, dict) and bool(entry.get("label"))
    if isinstance(entry, str):
        kind, sep, builder = entry.strip().partition(":")
        if sep and not builder:
            raise fail("", f"{entry!r}: expected KIND or KIND:BUILDER (builder missing)")
        label = entry.strip()
    elif isinstance(entry, dict):
        unknown = [k for k in entry if k not in ("kind", "builder", "label", "build")]
        if unknown:
            raise fail(
                str(unknown[0]), "unknown key (expected one of: kind, builder, label, build)"
            )
        kind = entry.get("kind")
        if not isinstance(kind, str) or not kind:
            raise fail("kind", "missing (a structure's name, e.g. bvh8)")
        builder = entry.get("builder", "")
        if not isinstance(builder, str):
            raise fail("builder", f"expected a builder name, got {builder!r}")
        build = entry.get("build") or {}
        if not isinstance(build, dict):
            raise fail(
                "build", f"expected a mapping of setting: value (or [values]), got {build!r}"
            )
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
    builder = builder or kinds[kind][0]
    schema = registered_settings(kind, builder) if build else {}
    names = sorted(build)
    choices = [build[n] if isinstance(build[n], list) else [build[n]] for n in names]
    count = math.prod(len(c) for c in choices)
    if limit is not None and count > limit:
        sizes = " x ".join(
            f"{len(c)} {n}" for n, c in zip(names, choices, strict=True) if len(c) > 1
        )
        raise fail(
            "build",
            f"{kind}:{builder} settings expand into {count:,} structures ({sizes}), each at "
            f"least one run; the sweep has room for {limit:,} more within its run limit "
            "(docs/sweeps.md); sweep fewer values",
        )
    for name, values in zip(names, choices, strict=True):
        for value in values or [None]:
            problem = check_setting(str(name), value, schema)
            if problem:
                raise fail("build", f"{kind}:{builder} setting {name!r}: {problem}")
    swept = [n for n in names if isinstance(build[n], list)]
    out = []
    for values in itertools.product(*choices):
        settings = tuple(zip(names, values, strict=True))
        # Labels name what differs: the swept settings, or all given when no label says it.
        named = [(n, v) for n, v in settings if n in swept or (not swept and not explicit_label)]
        suffix = " ".join(f"{n}={v}" for n, v in named)
        out.append(AccelSpec(f"{label} {suffix}" if suffix else label, kind, builder, settings))
    return out


def folder_label(accel: AccelSpec) -> str:
    """The label as a file-name part (bvh2:sbvh -> bvh2-sbvh)."""
    return "".join(c if c.isalnum() or c in "_-." else "-" for c in accel.label)

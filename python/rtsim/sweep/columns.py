"""The tidy table of a sweep: which columns a run's row has, their units and where each value
comes from (docs/sweeps.md, "The results table").

One declaration serves `Results.to_pandas()`, `rtsim results` (printed, `--csv`, `--parquet`) and
the docs, so the three cannot drift apart. The summary columns are read from rtsim-sim's own
declaration of `stats.json` (`rtsim-sim --dump-stats-schema`, each key's unit and meaning): a
summary key the C++ side adds becomes a column with no change here. Swept keys come from the
store (every key any run swept), their units from the config tree's declaration.
"""

from __future__ import annotations

import functools
import json
import subprocess
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

from rtsim.config import field_info, flatten
from rtsim.kinds import DATA_KINDS
from rtsim.sweep.store import RunRecord


@dataclass(frozen=True)
class Column:
    """One column of the tidy table: its name, unit, meaning and how a run's value is read."""

    name: str
    unit: str
    doc: str
    get: Callable[[RunRecord], Any]
    #: Left out of a table where no run has a value (a feature no run of the sweep used).
    where_present: bool = False
    #: Where the value is in stats.json (a dotted path), for the docs and the tests.
    source: str = ""


#: Summary keys that are not a column: prose (the verdict's sentence; `bottleneck` names it).
_SKIPPED = {"verdict"}
#: Data kinds DRAM bytes per ray are split by, in the order the tables show them (others follow).


@functools.lru_cache(maxsize=1)
def summary_schema() -> tuple[dict[str, Any], ...]:
    """The summary's keys as rtsim-sim declares them (key, unit, meaning, optional, timed)."""
    from rtsim.launcher import find_sim

    out = subprocess.run(
        [str(find_sim()), "--dump-stats-schema"], capture_output=True, text=True, check=True
    )
    blocks = {b["path"]: b["stats"] for b in json.loads(out.stdout)}
    return tuple(blocks["summary"])


def _summary(key: str) -> Callable[[RunRecord], Any]:
    return lambda rec: rec.summary.get(key)


def _ci(key: str, side: int) -> Callable[[RunRecord], Any]:
    def get(rec: RunRecord) -> Any:
        pair = rec.summary.get(key)
        return pair[side] if isinstance(pair, list) and len(pair) == 2 else None

    return get


def _stat(*path: str) -> Callable[[RunRecord], Any]:
    def get(rec: RunRecord) -> Any:
        node: Any = rec.stats or {}
        for part in path:
            node = node.get(part) if isinstance(node, dict) else None
        return node

    return get


def bytes_per_ray_by_kind(rec: RunRecord) -> dict[str, float]:
    """DRAM bytes (read + written) per ray for each data kind the run moved."""
    stats = rec.stats or {}
    rays = stats.get("summary", {}).get("rays") or 0
    # A functional run has no model: its `model` is null.
    kinds = ((stats.get("model") or {}).get("dram") or {}).get("by_kind", {})
    if not rays:
        return {}
    return {k: (v.get("read_bytes", 0) + v.get("write_bytes", 0)) / rays for k, v in kinds.items()}


def _kind(kind: str) -> Callable[[RunRecord], Any]:
    return lambda rec: bytes_per_ray_by_kind(rec).get(kind)


def sram_bytes(rec: RunRecord) -> float | None:
    """The run's on-chip SRAM in bytes, as the C++ area model counts it (stats.json
    `area.sram_total_bytes`: L1s, L2, stacks, ray contexts, mailboxes, ray buffer); None for a run
    without stats (a failed run)."""
    v = _stat("area", "sram_total_bytes")(rec)
    return float(v) if isinstance(v, (int, float)) else None


def key_value(rec: RunRecord, key: str) -> tuple[Any, bool]:
    """A run's value of a swept key and whether the run swept it. A store can mix specs that
    swept different keys: a run that did not sweep a key still ran with some value of it (its
    resolved config, or its preset for the special key `preset`), never a blank."""
    if key in rec.params:
        return rec.params[key], True
    if key == "preset":
        return rec.preset, False
    if key == "accel":
        return rec.accel, False
    return flatten(rec.config or {}).get(key), False


def _identity() -> list[Column]:
    def attr(name: str) -> Callable[[RunRecord], Any]:
        return lambda rec: getattr(rec, name)

    docs = {
        "run_id": "the run's id: a hash of its trace and its resolved config",
        "scene": "the scene's label in the spec",
        "workload": "the workload's name in the spec",
        "accel": "the acceleration structure's label (`bvh2` without an `accel` axis)",
        "preset": "the preset and modifiers the config was composed from",
        "status": "`ok`, `mismatch` (hits differ from the reference) or `failed`",
        "error": "why a run failed (the tail of rtsim-sim's stderr); empty when ok",
    }
    return [Column(n, "", d, attr(n)) for n, d in docs.items()]


def _swept(key: str) -> Column:
    unit, doc = "", "a swept config key"
    if key == "point":
        doc = "the label of the spec's `points` entry the run came from"
    elif key not in ("preset", "accel"):
        try:
            meta = field_info(key).metadata
            unit, doc = str(meta.get("unit", "")), str(meta.get("doc", doc))
        except Exception:  # a key of an older config tree: keep the column, without a unit
            pass
    return Column(key, unit, doc, lambda rec: key_value(rec, key)[0], source=f"config {key}")


def _summary_columns(kinds: Iterable[str]) -> list[Column]:
    cols: list[Column] = []
    for entry in summary_schema():
        key, unit, doc = entry["key"], entry["unit"], entry["meaning"]
        if key in _SKIPPED or key == "fidelity":
            continue
        present = True  # a summary key no run has a value for is a feature the sweep never used
        if key.endswith("_ci95"):
            for i, side in enumerate(("lo", "hi")):
                cols.append(
                    Column(
                        f"{key}_{side}",
                        unit,
                        f"{side} end: {doc}",
                        _ci(key, i),
                        True,
                        f"summary.{key}[{i}]",
                    )
                )
            continue
        cols.append(Column(key, unit, doc, _summary(key), present, f"summary.{key}"))
        if key == "dram_bytes_per_ray":
            for kind in kinds:
                cols.append(
                    Column(
                        f"dram_bytes_per_ray.{kind}",
                        "bytes/ray",
                        f"DRAM bytes read and written per ray for {kind} data",
                        _kind(kind),
                        True,
                        f"model.dram.by_kind.{kind} (read + write) / rays",
                    )
                )
    return cols


def _chip_columns() -> list[Column]:
    return [
        Column(
            "sram_mm2",
            "mm^2",
            "area of the SRAM blocks (L1s, L2, stacks, ray buffer)",
            _stat("area", "sram_mm2"),
            True,
            "area.sram_mm2",
        ),
        Column(
            "logic_mm2",
            "mm^2",
            "area of the pipelines",
            _stat("area", "logic_mm2"),
            True,
            "area.logic_mm2",
        ),
        Column(
            "sram_bytes",
            "bytes",
            "on-chip SRAM as the area model counts it: L1s x units, L2, traversal stacks, ray "
            "contexts, mailboxes and the ray buffer (with treelets)",
            sram_bytes,
            True,
            "area.sram_total_bytes",
        ),
    ]


def columns(records: list[RunRecord], keys: list[str]) -> list[Column]:
    """The table's columns for these runs: identity, every swept key, the summary, DRAM bytes per
    ray by data kind, area and SRAM. A where-present column no run has a value for is left out."""
    moved = {k for r in records for k in bytes_per_ray_by_kind(r)}
    kinds = [k for k in DATA_KINDS if k in moved] + sorted(moved - set(DATA_KINDS))
    swept = [k for k in keys if k not in ("accel", "preset")]
    level = Column(
        "fidelity",
        "",
        "the level that ran (functional, analytic, approx, detailed)",
        _summary("fidelity"),
        True,
        "summary.fidelity",
    )
    cols = [
        *_identity(),
        *(_swept(k) for k in swept if k != "fidelity"),
        level,
        *_summary_columns(kinds),
        *_chip_columns(),
    ]
    return [c for c in cols if not c.where_present or any(c.get(r) is not None for r in records)]


def swept_keys(records: list[RunRecord], store_keys: Iterable[str] = ()) -> list[str]:
    """Every key any run swept, in first-seen order (the store's columns first)."""
    seen = dict.fromkeys(store_keys)
    for r in records:
        seen.update(dict.fromkeys(r.params))
    return list(seen)

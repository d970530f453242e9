"""The tidy table of a sweep: one row per run with scene, workload, acceleration structure,
status, every config key, the on-chip SRAM and the summary stats (plus DRAM bytes per ray by
data kind)."""

from __future__ import annotations

import csv
import io
from collections.abc import Iterable
from typing import Any

from rtsim.config import config_keys, flatten
from rtsim.sweep.store import RunRecord

ID_COLUMNS = (
    "run_id",
    "scene",
    "workload",
    "accel",
    "preset",
    "status",
    "exit_code",
    "error",
    "started_utc",
    "finished_utc",
    "wall_seconds",
)


def sram_bytes(rec: RunRecord) -> float | None:
    """The run's on-chip SRAM in bytes, as the C++ area model counts it (stats.json
    `area.sram_total_bytes`: L1s, L2, stacks, ray contexts, mailboxes, ray buffer); None for a run
    without stats (a failed run, an older store)."""
    area = (rec.stats or {}).get("area") or {}
    v = area.get("sram_total_bytes")
    return float(v) if isinstance(v, (int, float)) else None


def bytes_per_ray_by_kind(rec: RunRecord) -> dict[str, float]:
    """DRAM bytes (read + written) per ray for each data kind the run moved."""
    stats = rec.stats or {}
    rays = stats.get("summary", {}).get("rays") or 0
    kinds = stats.get("model", {}).get("dram", {}).get("by_kind", {})
    if not rays:
        return {}
    return {k: (v.get("read_bytes", 0) + v.get("write_bytes", 0)) / rays for k, v in kinds.items()}


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


def tidy_row(rec: RunRecord) -> dict[str, Any]:
    row: dict[str, Any] = {c: getattr(rec, c) for c in ID_COLUMNS}
    config = flatten(rec.config)
    row.update({k: config.get(k) for k in config_keys()})
    row["sram_bytes"] = sram_bytes(rec)
    for key, value in rec.summary.items():
        row[key] = value
    for kind, value in bytes_per_ray_by_kind(rec).items():
        row[f"dram_bytes_per_ray.{kind}"] = value
    return row


def tidy_rows(records: Iterable[RunRecord]) -> list[dict[str, Any]]:
    return [tidy_row(r) for r in records]


def to_csv(rows: list[dict[str, Any]]) -> str:
    """CSV with the union of columns, in first-seen order (failed runs leave stats empty)."""
    columns: dict[str, None] = {}
    for row in rows:
        columns.update(dict.fromkeys(row))
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=list(columns), lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: _csv_cell(v) for k, v in row.items()})
    return buf.getvalue()


def _csv_cell(value: Any) -> Any:
    if isinstance(value, bool):
        return "true" if value else "false"
    return "" if value is None else value

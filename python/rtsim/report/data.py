"""A sweep's results as the report needs them: runs grouped by scene and workload, labels for
config points, SRAM sizes and Pareto fronts."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rtsim.config import ConfigError, field_info
from rtsim.sweep.results import sram_bytes
from rtsim.sweep.store import RunRecord, open_store

# Short names for keys architects sweep often: (label, unit suffix).
SHORT_KEYS: dict[str, tuple[str, str]] = {
    "traversal.units": ("TU", ""),
    "traversal.ray_contexts": ("ctx", ""),
    "traversal.stack_entries": ("stack", ""),
    "l1.size_kib": ("L1", " KiB"),
    "l2.size_kib": ("L2", " KiB"),
    "dram.bytes_per_cycle": ("DRAM", " B/cyc"),
    "dram.channels": ("ch", ""),
    "clock_ghz": ("clk", " GHz"),
    "treelets.buffer_kib": ("RB", " KiB"),
    "treelets.treelet_kib": ("treelet", " KiB"),
}
# On/off keys: a word when on, nothing when off.
FLAG_KEYS: dict[str, str] = {"treelets.enabled": "treelets", "ideal_memory": "ideal mem"}


def short_label(key: str, value: Any) -> str:
    if key in FLAG_KEYS:
        return FLAG_KEYS[key] if value else f"no {FLAG_KEYS[key]}"
    if key in SHORT_KEYS:
        name, unit = SHORT_KEYS[key]
        return f"{name} {value}{unit}"
    return f"{key.split('.')[-1]}={value}"


def axis_label(key: str) -> str:
    """'l1.size_kib (KiB)': the key with its unit, from the config tree."""
    try:
        unit = field_info(key).metadata.get("unit", "")
    except ConfigError:
        unit = ""
    return f"{key} ({unit})" if unit and unit != key.split(".")[-1] else key


@dataclass
class Group:
    """The runs of one scene under one workload."""

    scene: str
    workload: str
    runs: list[RunRecord] = field(default_factory=list)

    @property
    def title(self) -> str:
        return f"{self.scene} / {self.workload}"

    @property
    def ok(self) -> list[RunRecord]:
        return [r for r in self.runs if r.status == "ok" and r.summary.get("rays_per_second")]


@dataclass
class SweepData:
    path: Path
    meta: dict[str, str]
    keys: list[str]  # swept keys, in spec order
    runs: list[RunRecord]

    def label(self, rec: RunRecord) -> str:
        text = " · ".join(short_label(k, rec.params[k]) for k in self.keys if k in rec.params)
        return text or rec.preset

    def groups(self) -> list[Group]:
        out: dict[tuple[str, str], Group] = {}
        for r in self.runs:
            out.setdefault((r.scene, r.workload), Group(r.scene, r.workload)).runs.append(r)
        return list(out.values())

    def trace_render(self, rec: RunRecord) -> Path | None:
        for path in (self.path / "traces").glob(f"*-{rec.trace_id[:8]}/render.png"):
            return path
        return None


def load(sweep: Path) -> SweepData:
    with open_store(sweep, readonly=True) as store:
        meta = store.meta()
        runs = list(store.runs())
    keys = [k for k in meta.get("swept_keys", "").split(",") if k]
    for r in runs:
        keys += [k for k in r.params if k not in keys]
    return SweepData(Path(sweep), meta, keys, runs)


def mrays(rec: RunRecord) -> float:
    return float(rec.summary.get("rays_per_second") or 0.0) / 1e6


def sram_kib(rec: RunRecord) -> float:
    return sram_bytes(rec.config) / 1024


def pareto_front(runs: list[RunRecord]) -> list[RunRecord]:
    """Runs no other run beats on both axes (less or equal SRAM and more rays/s), by SRAM."""
    best: list[RunRecord] = []
    for r in sorted(runs, key=lambda r: (sram_kib(r), -mrays(r))):
        if not best or mrays(r) > mrays(best[-1]):
            best.append(r)
    return best

"""A sweep's results as the report needs them: runs grouped by scene and workload, labels for
config points, SRAM sizes, area and energy, the baseline point and Pareto fronts."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from rtsim.config import ConfigError, field_info, flatten, key_inactive
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
# Keys that do nothing unless a switch is on: (key prefix, switch). A treelets-off run is not
# labelled with a ray-buffer size.


def key_active(key: str, config: dict[str, Any]) -> bool:
    """False for a key whose switch is off in this run's config (treelets.buffer_kib without
    treelets.enabled, traversal.simt.lanes under traversal.model mimd)."""
    return not key_inactive(key, flatten(config) if config else {})


def param(rec: RunRecord, key: str) -> Any:
    """A run's value of a swept key: its own swept value, else (a run of another spec in the
    same store, which did not sweep the key) its structure, preset or config value."""
    if key in rec.params:
        return rec.params[key]
    if key == "accel":
        return rec.accel
    if key == "preset":
        return rec.preset
    flat = flatten(rec.config) if rec.config else {}
    return flat.get(key)


def is_categorical(values: list[Any]) -> bool:
    """Switches and named choices (treelets on/off, a preset name), not numbers."""
    return bool(values) and all(isinstance(v, (bool, str)) for v in values)


def short_label(key: str, value: Any) -> str:
    if key == "accel":  # a structure's name says what it is
        return str(value)
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

    # The spec's baseline point (swept key -> value) the report's speed-ups are measured against.
    baseline: dict[str, Any] = field(default_factory=dict)

    def label(self, rec: RunRecord, keys: list[str] | None = None) -> str:
        """The run's values of the swept keys (or of `keys`), short."""
        text = " · ".join(
            short_label(k, v)
            for k in (self.keys if keys is None else keys)
            if (v := param(rec, k)) is not None and key_active(k, rec.config)
        )
        return text or rec.preset

    def values(self, key: str) -> list[Any]:
        """The distinct values of a swept key over the runs, in first-seen order (a run of
        another spec that did not sweep it has its config's value)."""
        vals = (param(r, key) for r in self.runs)
        return list(dict.fromkeys(v for v in vals if v is not None))

    def categorical_keys(self) -> list[str]:
        return [k for k in self.keys if is_categorical(self.values(k))]

    def baseline_run(self, runs: list[RunRecord], skip: tuple[str, ...] = ()) -> RunRecord | None:
        """The run among `runs` at the baseline point (keys in `skip` aside), if there is one: a
        run whose every baseline key is active and equal first; else one that differs only in
        keys its config leaves inactive (a ray-buffer size with treelets off). A run's value of a
        key its spec did not sweep is its config's, so a store holding two specs never takes
        one spec's run for the other's baseline."""
        wanted = {k: v for k, v in self.baseline.items() if k not in skip}

        def matches(r: RunRecord, lenient: bool) -> bool:
            return all(
                param(r, k) == v or (lenient and not key_active(k, r.config))
                for k, v in wanted.items()
            )

        for lenient in (False, True):
            for r in runs:
                if matches(r, lenient):
                    return r
        return None

    def groups(self) -> list[Group]:
        out: dict[tuple[str, str], Group] = {}
        for r in self.runs:
            out.setdefault((r.scene, r.workload), Group(r.scene, r.workload)).runs.append(r)
        return list(out.values())

    def trace_render(self, rec: RunRecord) -> Path | None:
        for path in (self.path / "traces").glob(f"*-{rec.trace_id[:8]}/render.png"):
            return path
        return None


def spec_baseline(spec_text: str, runs: list[RunRecord], keys: list[str]) -> dict[str, Any]:
    """The spec's `baseline` over the first value of each grid key; without a spec (or for keys
    it does not list), each key's first value in the runs."""
    try:
        docs = (
            [d for d in yaml.safe_load_all(spec_text) if isinstance(d, dict)] if spec_text else []
        )
    except yaml.YAMLError:
        docs = []
    out: dict[str, Any] = {}
    # A store holding several specs: the first spec's point, over the keys it sweeps. Keys only
    # another spec sweeps are left out (their runs differ in the first spec's keys anyway), so
    # the baseline is one real run of one spec, never a mix no run has.
    several = len(docs) > 1
    docs = docs[:1]
    for k in keys:
        for doc in docs:
            grid = doc.get("grid") if isinstance(doc.get("grid"), dict) else {}
            named = doc.get("baseline") if isinstance(doc.get("baseline"), dict) else {}
            if k in named:
                out[k] = named[k]
            elif isinstance(grid.get(k), list) and grid[k]:
                out[k] = grid[k][0]
            elif k == "accel" and isinstance(doc.get("accel"), list) and doc["accel"]:
                first = doc["accel"][0]
                out[k] = _accel_label(first)
            else:
                continue
            break
        if k not in out and not several:
            first = next((r.params[k] for r in runs if k in r.params), None)
            if first is not None:
                out[k] = first
    return out


def _accel_label(entry: Any) -> str:
    """An accel axis entry's label, as the sweep labels it (sweep/accel_axis.py)."""
    if isinstance(entry, dict):
        kind, builder = entry.get("kind"), entry.get("builder")
        return str(entry.get("label") or (f"{kind}:{builder}" if builder else kind))
    return str(entry).strip()


def load(sweep: Path) -> SweepData:
    with open_store(sweep, readonly=True) as store:
        meta = store.meta()
        runs = list(store.runs())
    keys = [k for k in meta.get("swept_keys", "").split(",") if k]
    for r in runs:
        keys += [k for k in r.params if k not in keys]
    baseline = spec_baseline(meta.get("spec", ""), runs, keys)
    return SweepData(Path(sweep), meta, keys, runs, baseline)


def mrays(rec: RunRecord) -> float:
    return float(rec.summary.get("rays_per_second") or 0.0) / 1e6


def sram_kib(rec: RunRecord) -> float | None:
    """On-chip SRAM in KiB (the C++ area model's count, stats.json `area.sram_total_bytes`)."""
    b = sram_bytes(rec)
    return None if b is None else b / 1024


def area_mm2(rec: RunRecord) -> float | None:
    """Chip area of the run's config (the energy and area model, docs/energy_area.md)."""
    v = rec.summary.get("area_mm2")
    return float(v) if isinstance(v, (int, float)) else None


def energy_nj(rec: RunRecord) -> float | None:
    """Energy per ray in nJ (null at the functional level)."""
    v = rec.summary.get("energy_per_ray_nj")
    return float(v) if isinstance(v, (int, float)) else None


@dataclass(frozen=True)
class Cost:
    """An x axis for a Pareto front: what a configuration costs."""

    name: str
    axis: str
    unit: str
    of: Callable[[RunRecord], float | None]


COSTS: dict[str, Cost] = {
    "sram": Cost(
        "on-chip SRAM",
        "on-chip SRAM: L1s + L2 + stacks + contexts + ray buffer (KiB)",
        "KiB",
        sram_kib,
    ),
    "area": Cost("area", "chip area: SRAM + pipelines (mm², docs/energy_area.md)", "mm²", area_mm2),
    "energy": Cost("energy", "energy per ray (nJ, docs/energy_area.md)", "nJ/ray", energy_nj),
}


def pareto_front(
    runs: list[RunRecord], cost: Callable[[RunRecord], float | None] = sram_kib
) -> list[RunRecord]:
    """Runs no other run beats on both axes (less or equal cost and more rays/s), by cost. Runs
    without the cost (an older store, the functional level) are left out."""
    best: list[RunRecord] = []
    priced = [r for r in runs if cost(r) is not None]
    for r in sorted(priced, key=lambda r: (cost(r), -mrays(r))):
        if not best or mrays(r) > mrays(best[-1]):
            best.append(r)
    return best

"""The report's acceleration-structure comparison: when a sweep has an `accel` axis, one table
per scene and workload with each structure's build figures (from its trace's manifest) and its
simulated figures at the baseline point of the other swept keys (docs/sweeps.md, "The report")."""

from __future__ import annotations

import json
from dataclasses import dataclass
from html import escape
from typing import Any

import yaml

from rtsim.report.data import Group, SweepData, mrays
from rtsim.sweep.spec import ACCEL_KEY
from rtsim.sweep.store import RunRecord

HEADER = [
    "structure",
    "footprint MiB",
    "node B",
    "SAH cost",
    "steps/ray",
    "box tests/ray",
    "tri tests/ray",
    "Mrays/s",
    "vs first",
    "DRAM B/ray",
    "L1 hit",
    "L2 hit",
    "mismatches",
]


@dataclass
class AccelRow:
    """One structure of one scene and workload at the baseline point."""

    accel: str
    run: RunRecord
    manifest: dict[str, Any]

    def work_per_ray(self, what: str) -> float | None:
        """Mean of a work count per ray over the rays the trace holds (and the model simulated):
        each kind weighted by its written rays, so the primary rays a diffuse workload traces
        only to find its bounces do not count."""
        kinds = self.manifest.get("counts", {}).get("by_kind", {})
        # Manifests written before kinds recorded "written" traced exactly what they wrote.
        weights = [(k, k.get("written", k.get("traced", 0))) for k in kinds.values()]
        rays = sum(w for _, w in weights)
        if not rays:
            return None
        return sum(k.get(f"{what}_per_ray", 0.0) * w for k, w in weights) / rays


def has_accel_axis(data: SweepData) -> bool:
    return ACCEL_KEY in data.keys and len(data.values(ACCEL_KEY)) > 1


def trace_manifest(data: SweepData, rec: RunRecord) -> dict[str, Any]:
    """The manifest of the run's trace in the sweep's trace cache ({} if it is gone)."""
    for path in (data.path / "traces").glob(f"*-{rec.trace_id[:8]}/manifest.json"):
        try:
            return dict(json.loads(path.read_text()))
        except (OSError, ValueError):
            return {}
    return {}


def at_baseline(data: SweepData, runs: list[RunRecord]) -> RunRecord | None:
    """The run at the baseline value of every swept key but `accel` (data.baseline_run: a run
    of another spec in the same store is read by its own config, never taken for this one's)."""
    return data.baseline_run(runs, skip=(ACCEL_KEY,))


def axis_order(data: SweepData) -> list[str]:
    """The axis's labels in the spec's order (the first is what speeds are measured against);
    labels only the runs know (a store mixing specs) follow in first-seen order."""
    try:
        doc = yaml.safe_load(data.meta.get("spec", "")) or {}
    except yaml.YAMLError:
        doc = {}
    entries = doc.get("accel") if isinstance(doc, dict) else None
    entries = entries if isinstance(entries, list) else [entries] if entries else []
    labels = []
    for e in entries:
        if isinstance(e, dict):
            kind, builder = e.get("kind"), e.get("builder")
            labels.append(str(e.get("label") or (f"{kind}:{builder}" if builder else kind)))
        else:
            labels.append(str(e).strip())
    seen = data.values(ACCEL_KEY)
    return [x for x in labels if x in seen] + [x for x in seen if x not in labels]


def accel_rows(data: SweepData, group: Group) -> list[AccelRow]:
    rows = []
    for accel in axis_order(data):
        runs = [r for r in group.runs if r.accel == accel and r.status != "failed"]
        run = at_baseline(data, runs)
        if run is not None:
            rows.append(AccelRow(accel, run, trace_manifest(data, run)))
    return rows


def _num(x: Any, fmt: str) -> str:
    return "-" if not isinstance(x, (int, float)) or isinstance(x, bool) else format(x, fmt)


def _cells(row: AccelRow, first: AccelRow) -> list[str]:
    a, s = row.manifest.get("accel", {}), row.run.summary
    footprint = a.get("footprint_bytes")
    speed, ref = mrays(row.run), mrays(first.run)
    mismatches = (s.get("hit_mismatches") or 0) + (s.get("work_mismatches") or 0)
    return [
        escape(row.accel),
        _num(footprint / 2**20 if isinstance(footprint, (int, float)) else None, ".2f"),
        _num(a.get("node_bytes"), "d"),
        _num(a.get("sah_cost"), ".1f"),
        _num(row.work_per_ray("steps"), ".1f"),
        _num(row.work_per_ray("box_tests"), ".1f"),
        _num(row.work_per_ray("tri_tests"), ".1f"),
        _num(speed, ".2f"),
        _num(speed / ref if ref else None, ".2f") + ("x" if ref else ""),
        _num(s.get("dram_bytes_per_ray"), ",.0f"),
        _num(s.get("l1_hit_rate"), ".3f"),
        _num(s.get("l2_hit_rate"), ".3f"),
        f"<span class='{'bad' if mismatches else 'good'}'>{mismatches}</span>",
    ]


def accel_section(data: SweepData, table: Any) -> list[str]:
    """The section's HTML parts (empty without an accel axis); table renders header and rows."""
    if not has_accel_axis(data):
        return []
    parts = [
        "<h2>Acceleration structures</h2>",
        "<p>Each structure of the sweep's <code>accel</code> axis at the baseline point of the "
        "other swept keys (each table names the configuration its rows ran). Footprint, node "
        "bytes, SAH cost and work per ray (every ray kind of the trace) come from the trace's "
        "manifest; Mrays/s, DRAM bytes per "
        "ray and hit rates from the simulation; <em>vs first</em> is the speed over the axis's "
        "first structure. Mismatches (hit + work) must be 0. docs/accel.md explains the "
        "structures.</p>",
    ]
    for group in data.groups():
        rows = accel_rows(data, group)
        if not rows:
            continue
        parts.append(f"<h3>{escape(group.title)}</h3>")
        # The configuration the rows really ran, from the runs themselves (not the spec's point:
        # in a store holding two specs it named one spec while the rows were the other's).
        others = [k for k in data.keys if k != ACCEL_KEY]
        point = " · ".join(dict.fromkeys(data.label(r.run, others) for r in rows))
        parts.append(f"<p class='muted'>at {escape(point or 'the only point')}</p>")
        numeric = set(range(1, len(HEADER)))
        parts.append(table(HEADER, [_cells(r, rows[0]) for r in rows], numeric))
    return parts

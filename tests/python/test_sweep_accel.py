"""The sweep's `accel` axis: spec syntax and its errors, the trace cache key, the store column,
the tidy table and the report's comparison section (docs/sweeps.md, "Acceleration structures")."""

from __future__ import annotations

import json
import textwrap
from pathlib import Path

import pytest

from rtsim.report.accel_section import accel_section, has_accel_axis
from rtsim.report.data import load
from rtsim.report.html import _table
from rtsim.sweep.results import tidy_row
from rtsim.sweep.runner import trace_task
from rtsim.sweep.spec import SpecError, parse_spec
from rtsim.sweep.store import RunRecord, open_store

BASE = """\
scenes: [cornell]
workloads: [{name: primary, rays: [primary], resolution: 16x12}]
grid:
  traversal.units: [2, 4]
"""


def spec(accel: str) -> object:
    return parse_spec(BASE + accel, source="s.yaml")


def spec_error(accel: str) -> str:
    with pytest.raises(SpecError) as info:
        parse_spec(BASE + textwrap.dedent(accel), source="s.yaml")
    return str(info.value)


def test_accel_axis_multiplies_traces_and_runs() -> None:
    s = spec("accel: [bvh2, 'bvh2:sbvh', bvh8, {kind: cwbvh8, label: compressed}]\n")
    assert [a.label for a in s.accels] == ["bvh2", "bvh2:sbvh", "bvh8", "compressed"]
    assert [(a.kind, a.builder) for a in s.accels][:2] == [("bvh2", "binned"), ("bvh2", "sbvh")]
    assert s.swept_keys[0] == "accel"
    traces = s.traces()
    assert len(traces) == 4 and len({t.trace_id for t in traces}) == 4
    runs = s.runs()
    assert len(runs) == 4 * 2 and len({r.run_id for r in runs}) == 8
    assert {r.params["accel"] for r in runs} == {"bvh2", "bvh2:sbvh", "bvh8", "compressed"}
    folders = {t.folder_name for t in traces}
    assert any("bvh2-sbvh" in f for f in folders) and all(":" not in f for f in folders)


def test_trace_cache_keys_structure_builder_and_format() -> None:
    plain, named = spec(""), spec("accel: ['bvh2:binned']\n")
    # the default builder spelled out or not is the same trace; no axis traces bvh2
    assert plain.traces()[0].trace_id == named.traces()[0].trace_id
    assert "accel" not in plain.runs()[0].params
    sbvh = spec("accel: ['bvh2:sbvh']\n").traces()[0]
    assert sbvh.trace_id != plain.traces()[0].trace_id
    other_format = parse_spec(BASE, source="s.yaml")
    other_format.trace_version += 1
    assert other_format.traces()[0].trace_id != plain.traces()[0].trace_id


def test_trace_task_passes_structure_and_builder(tmp_path: Path) -> None:
    plan = spec("accel: ['bvh2:sbvh', grid]\n").traces()
    cmd = trace_task(plan[0], tmp_path).command("OUT")
    assert cmd[cmd.index("--accel") + 1] == "bvh2" and cmd[cmd.index("--builder") + 1] == "sbvh"
    grid = trace_task(plan[1], tmp_path).command("OUT")
    assert grid[grid.index("--accel") + 1] == "grid"


@pytest.mark.parametrize(
    ("accel", "expected"),
    [
        ("accel: [bvh2, bvh9]\n", "s.yaml:5: accel[1]: unknown acceleration structure 'bvh9'"),
        ("accel: ['bvh2:fast']\n", "s.yaml:5: accel[0]: bvh2 has no builder 'fast'"),
        ("accel: ['bvh2:']\n", "s.yaml:5: accel[0]: 'bvh2:': expected KIND or KIND:BUILDER"),
        ("accel: []\n", "s.yaml:5: accel: expected a non-empty list"),
        ("accel: [bvh2, 'bvh2']\n", "s.yaml:5: accel: two entries named 'bvh2'"),
        ("accel: [3]\n", "s.yaml:5: accel[0]: expected KIND, KIND:BUILDER or a mapping"),
        (
            "accel:\n  - kind: bvh4\n    buildr: binned\n",
            "s.yaml:7: accel[0].buildr: unknown key",
        ),
        ("accel:\n  - {builder: sbvh}\n", "s.yaml:6: accel[0].kind: missing"),
        (
            "accel:\n  - kind: grid\n    builder: sbvh\n",
            "s.yaml:7: accel[0].builder: grid has no builder 'sbvh'",
        ),
    ],
)
def test_accel_errors_name_line_and_key(accel: str, expected: str) -> None:
    assert spec_error(accel).startswith(expected)


def test_a_single_structure_may_be_a_scalar() -> None:
    s = spec("accel: bvh4\n")
    assert [a.kind for a in s.accels] == ["bvh4"]


def _record(sweep: Path, accel: str, units: int, mrays: float, footprint: int) -> RunRecord:
    trace_id = f"{accel:0<8}"[:8].replace(":", "0") + "0000"
    folder = sweep / "traces" / f"cornell-primary-{accel}-{trace_id[:8]}"
    folder.mkdir(parents=True)
    manifest = {
        "accel": {"kind": accel, "footprint_bytes": footprint, "node_bytes": 64, "sah_cost": 9.5},
        "counts": {"by_kind": {"primary": {"traced": 10, "steps_per_ray": 3.0}}},
    }
    (folder / "manifest.json").write_text(json.dumps(manifest))
    summary = {"rays_per_second": mrays * 1e6, "mrays_per_second": mrays, "hit_mismatches": 0}
    return RunRecord(
        run_id=f"{accel}-{units}",
        scene="cornell",
        workload="primary",
        trace_id=trace_id,
        preset="base",
        status="ok",
        params={"accel": accel, "traversal.units": units},
        config={"traversal": {"units": units}},
        stats={"summary": summary},
    )


def test_store_results_and_report_show_the_axis(tmp_path: Path) -> None:
    records = [
        _record(tmp_path, "bvh2", 2, 10.0, 2**20),
        _record(tmp_path, "bvh8", 2, 15.0, 2**21),
    ]
    with open_store(tmp_path) as store:
        store.set_meta({"swept_keys": "accel,traversal.units"})
        for r in records:
            store.record(r)
        assert "accel" in store.swept_keys()
    assert tidy_row(records[1])["accel"] == "bvh8"
    data = load(tmp_path)
    assert has_accel_axis(data)
    html = "".join(accel_section(data, _table))
    assert "Acceleration structures" in html and "cornell / primary" in html
    assert "1.50x" in html  # bvh8 over the first structure
    assert "2.00" in html and "3.0" in html  # footprint MiB and steps/ray from the manifest


def test_no_axis_no_section(tmp_path: Path) -> None:
    rec = _record(tmp_path, "bvh2", 2, 10.0, 2**20)
    rec.params = {"traversal.units": 2}
    with open_store(tmp_path) as store:
        store.record(rec)
    assert accel_section(load(tmp_path), _table) == []
    assert tidy_row(rec)["accel"] == "bvh2"


def test_report_follows_the_spec_order(tmp_path: Path) -> None:
    """The first structure of the spec's axis is the one speeds are measured against."""
    records = [
        _record(tmp_path, "bvh2", 2, 10.0, 2**20),
        _record(tmp_path, "bvh8", 2, 15.0, 2**21),
    ]
    with open_store(tmp_path) as store:
        store.set_meta({"swept_keys": "accel", "spec": "accel: [bvh8, bvh2]\n"})
        for r in records:
            store.record(r)
    html = "".join(accel_section(load(tmp_path), _table))
    assert html.index(">bvh8<") < html.index(">bvh2<")
    assert "0.67x" in html  # bvh2 over bvh8

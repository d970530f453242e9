"""Sweeps from Python (`rtsim.sweep`) and the results table: a Python sweep and `rtsim sweep` of
the same spec fill the same store; a Python sweep killed with SIGKILL resumes losing and
duplicating nothing; `Results.to_pandas()` has exactly the columns `rtsim results` prints and
writes, and its numbers are the runs' stats.json values; a study re-run reuses its runs."""

from __future__ import annotations

import csv
import io
import json
import os
import signal
import sqlite3
import subprocess
import sys
import time
from contextlib import closing
from pathlib import Path

import pytest
import yaml

import rtsim
from conftest import run_rtsim

SPEC = """\
name: api
scenes: [cornell]
workloads:
  - {name: diffuse, rays: [diffuse], resolution: 16x12}
grid:
  traversal.units: [2, 4]
points:
  - {label: small}
  - {label: big, set: {l1.size_kib: 32}}
"""
#: What differs between two runs of one config: host times, memory and provenance.
HOST = {"wall_seconds", "simulated_rays_per_wall_second", "peak_memory_mib"}


def rows(sweep: Path) -> list[dict]:
    with closing(sqlite3.connect(sweep / "results.sqlite")) as conn:
        conn.row_factory = sqlite3.Row
        return [dict(r) for r in conn.execute("SELECT * FROM runs ORDER BY run_id")]


def comparable(row: dict) -> dict:
    stats = json.loads(row["stats_json"])
    stats["summary"] = {k: v for k, v in stats["summary"].items() if k not in HOST}
    for key in ("provenance", "latency", "sampling"):
        stats.pop(key, None)
    return {
        "run_id": row["run_id"],
        "status": row["status"],
        "params": json.loads(row["params_json"]),
        "config": json.loads(row["config_json"]),
        "summary": stats["summary"],
        "model": stats.get("model"),
        "area": stats.get("area"),
    }


@pytest.fixture(scope="module")
def py_sweep(tmp_path_factory: pytest.TempPathFactory) -> rtsim.Results:
    out = tmp_path_factory.mktemp("api") / "py"
    return rtsim.sweep(yaml.safe_load(SPEC), out, workers=2, progress=False, quiet=True)


def test_python_and_cli_sweeps_fill_the_same_store(py_sweep: rtsim.Results, tmp_path: Path) -> None:
    spec = tmp_path / "api.yaml"
    spec.write_text(SPEC)
    cli = tmp_path / "cli"
    done = run_rtsim("sweep", str(spec), "-o", str(cli), "--workers", "2", "--no-progress")
    assert done.returncode == 0, done.stdout + done.stderr
    ours, theirs = rows(py_sweep.path), rows(cli)
    assert len(ours) == 4 and [r["run_id"] for r in ours] == [r["run_id"] for r in theirs]
    assert [comparable(r) for r in ours] == [comparable(r) for r in theirs]
    assert {json.loads(r["params_json"])["point"] for r in ours} == {"small", "big"}


def test_resume_from_python_after_kill(tmp_path: Path) -> None:
    """SIGKILL a Python sweep (its process group: client, cluster, simulations) after its first
    result; rtsim.sweep again finishes the rest, keeps the finished rows and duplicates none."""
    spec = yaml.safe_load(SPEC)
    spec["grid"]["traversal.units"] = [1, 2, 4, 8]
    out = tmp_path / "out"
    code = f"import rtsim; rtsim.sweep({spec!r}, {str(out)!r}, workers=1, progress=False)"
    proc = subprocess.Popen(
        [sys.executable, "-c", code],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    deadline = time.monotonic() + 120
    try:
        while time.monotonic() < deadline and proc.poll() is None:
            try:
                if rows(out):
                    break
            except sqlite3.Error:
                pass  # the store is being created
            time.sleep(0.02)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    first = {r["run_id"]: r for r in rows(out)}
    assert 1 <= len(first) < 8, "the sweep finished before it could be killed"
    results = rtsim.sweep(spec, out, workers=1, progress=False, quiet=True)
    final = rows(out)
    assert len(final) == 8 and len({r["run_id"] for r in final}) == 8
    assert all(r["status"] == "ok" and r["attempts"] == 1 for r in final)
    for r in final:
        if r["run_id"] in first:
            assert r["finished_utc"] == first[r["run_id"]]["finished_utc"]
    assert results.outcome is not None and results.outcome.skipped == len(first)
    assert len(results.to_pandas()) == 8


def test_dataframe_columns_are_rtsim_results_columns(
    py_sweep: rtsim.Results, tmp_path: Path
) -> None:
    df = py_sweep.to_pandas()
    names = list(df.columns)
    for key in (
        "scene",
        "workload",
        "accel",
        "fidelity",
        "traversal.units",
        "l1.size_kib",
        "point",
        "mrays_per_second",
        "dram_bytes_per_ray.node",
        "l1_hit_rate",
        "box_utilization",
        "energy_per_ray_nj",
        "area_mm2",
        "sram_bytes",
    ):
        assert key in names, key
    assert df.attrs["units"]["mrays_per_second"] == "Mrays/s"
    assert df.attrs["units"]["l1.size_kib"] == "KiB"
    printed = run_rtsim("results", str(py_sweep.path))
    assert printed.returncode == 0, printed.stderr
    lines = printed.stdout.splitlines()
    assert lines[0].split() == names and len(lines) == 1 + len(df)  # piped: no name is cut
    written = run_rtsim("results", str(py_sweep.path), "--csv")
    table = list(csv.reader(io.StringIO(written.stdout)))
    assert table[0] == names and len(table) == 1 + len(df)
    parquet = tmp_path / "r.parquet"
    pytest.importorskip("pyarrow")
    assert run_rtsim("results", str(py_sweep.path), "--parquet", str(parquet)).returncode == 0
    import pandas as pd

    assert list(pd.read_parquet(parquet).columns) == names


def test_numeric_columns_match_stats_json(py_sweep: rtsim.Results) -> None:
    df = py_sweep.to_pandas()
    cols = {c.name: c for c in py_sweep.columns()}
    for row in df.iloc[[0, len(df) - 1]].itertuples(index=False):
        row = dict(zip(df.columns, row, strict=True))
        stats = json.loads((py_sweep.run_dir(row["run_id"]) / "stats.json").read_text())
        checked = 0
        for name, value in row.items():
            source = cols[name].source
            if source.startswith("summary.") and "[" not in source:
                expected = stats["summary"][source.removeprefix("summary.")]
            elif name.startswith("dram_bytes_per_ray."):
                kind = stats["model"]["dram"]["by_kind"][name.split(".", 1)[1]]
                expected = (kind["read_bytes"] + kind["write_bytes"]) / stats["summary"]["rays"]
            elif source.startswith("area."):
                expected = stats["area"][source.removeprefix("area.")]
            else:
                continue
            if isinstance(expected, (int, float)) and not isinstance(expected, bool):
                assert value == pytest.approx(expected, rel=1e-12), name
                checked += 1
        assert checked >= 20


STUDY = """\
from rtsim.study import Study, Table

def table(run):
    rows = run.rows()
    return "\\n".join(f"{r['point']} {r['traversal.units']} {r['mrays_per_second']:.3f}"
                     for r in rows) + "\\n"

STUDY = Study(
    name="tiny",
    about="a test study",
    specs=lambda o: [{
        "name": "tiny",
        "scenes": ["cornell"],
        "workloads": [{"name": "diffuse", "rays": ["diffuse"], "resolution": o["resolution"]}],
        "points": [{"label": "a", "set": {"traversal.units": 2}},
                   {"label": "b", "set": {"traversal.units": 2}}],
    }],
    tables=[Table("doc.md", "tiny", table)],
    options={"resolution": "16x12"},
)
"""


def test_study_reruns_reuse_runs_and_write_its_markers(tmp_path: Path) -> None:
    study = tmp_path / "tiny_study.py"
    study.write_text(STUDY)
    docs = tmp_path / "docs"
    docs.mkdir()
    (docs / "doc.md").write_text("before\n<!-- tiny:begin -->\nold\n<!-- tiny:end -->\nafter\n")
    args = [
        "study",
        str(study),
        "-o",
        str(tmp_path / "out"),
        "--workers",
        "1",
        "--no-progress",
        "--write-docs",
        "--docs",
        str(docs),
    ]
    first = run_rtsim(*args)
    assert first.returncode == 0, first.stdout + first.stderr
    text = (docs / "doc.md").read_text()
    # Two labels, one config: one run, a row under each label.
    assert len(rows(tmp_path / "out")) == 1
    body = text.split("<!-- tiny:begin -->\n")[1].split("<!-- tiny:end -->")[0]
    assert [line.split()[:2] for line in body.splitlines()] == [["a", "2"], ["b", "2"]]
    again = run_rtsim(*args)
    assert again.returncode == 0
    assert "1 already in results.sqlite" in " ".join(again.stderr.split())
    assert (docs / "doc.md").read_text() == text
    bad = run_rtsim("study", str(study), "--option", "bogus=1", "-o", str(tmp_path / "x"))
    assert bad.returncode == 2 and "unknown option 'bogus'" in bad.stderr


def test_spec_dict_errors_name_the_key(tmp_path: Path) -> None:
    spec = yaml.safe_load(SPEC)
    spec["points"][1]["set"] = {"l1.size_kb": 32}
    with pytest.raises(rtsim.RtsimError, match=r"points\[1\]\.set\.l1\.size_kb: unknown key"):
        rtsim.sweep(spec, tmp_path / "never", quiet=True)
    assert not (tmp_path / "never").exists()


def test_every_builtin_study_has_its_markers_in_docs() -> None:
    # A study whose table has no markers in its page would write nowhere with --write-docs.
    from rtsim import studies

    docs = Path(__file__).resolve().parents[2] / "docs"
    for name in studies.names():
        for t in studies.load(name).tables:
            text = (docs / t.doc).read_text()
            assert f"<!-- {t.marker}:begin -->" in text, (name, t.doc, t.marker)
            assert f"<!-- {t.marker}:end -->" in text, (name, t.doc, t.marker)


def test_vulkansim_baseline_study_quick(tmp_path: Path) -> None:
    # The warp baseline across two structures and its treelet prefetching, end to end.
    args = ["study", "vulkansim_baseline", "--quick", "-o", str(tmp_path / "out")]
    done = run_rtsim(*args, "--workers", "1", "--no-progress")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "warp + treelet prefetch" in done.stdout and "cwbvh6" in done.stdout

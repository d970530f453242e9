"""The techniques study (rtsim/studies/techniques.py): every memory-traffic technique runs beside
its off run, with zero mismatches, and its table has one row per technique, scene and level."""

from __future__ import annotations

from pathlib import Path

from rtsim.studies import techniques
from rtsim.study import run_study


def test_matrix_runs_every_technique_with_zero_mismatches(tmp_path: Path) -> None:
    run = run_study(techniques.STUDY, tmp_path / "out", quick=True, workers=1, progress=False)
    assert run.options["scenes"] == ["cornell"]
    rows = techniques.rows(run)
    names = {r["technique"] for r in rows}
    assert len(names) == len(techniques.TECHNIQUES) >= 4
    assert len(rows) == len(names) * 2  # one scene, two timed levels
    assert {r["level"] for r in rows} == {"approx", "detailed"}
    for r in rows:
        assert r["rays"] > 0 and r["mrays_per_second"] > 0
        assert r["hit_mismatches"] == r["work_mismatches"] == r["off_mismatches"] == 0
    table = [line for line in techniques.table(run).splitlines() if line.startswith("| ")]
    assert len(table) == 1 + len(rows)  # the header, then a row per run

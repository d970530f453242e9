"""scripts/techniques_matrix.py: every memory-traffic technique runs beside its off run, with zero
mismatches, and the table it writes has one row per technique, scene and level."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


def test_matrix_runs_every_technique_with_zero_mismatches(tmp_path: Path) -> None:
    out = tmp_path / "matrix"
    script = str(REPO / "scripts" / "techniques_matrix.py")
    cmd = [sys.executable, script, "--out", str(out), "--scenes", "cornell",
           "--levels", "approx,detailed", "--resolution", "24x18"]  # fmt: skip
    done = subprocess.run(cmd, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[-2000:]
    result = json.loads((out / "matrix.json").read_text())
    rows = result["rows"]
    techniques = {r["technique"] for r in rows}
    assert len(techniques) >= 4
    assert len(rows) == len(techniques) * 2  # one scene, two timed levels
    assert {r["level"] for r in rows} == {"approx", "detailed"}
    for r in rows:
        assert r["rays"] > 0 and r["mrays_per_second"] > 0
        assert r["hit_mismatches"] == r["work_mismatches"] == r["off_mismatches"] == 0
    table = [line for line in done.stdout.splitlines() if line.startswith("| ")]
    assert len(table) == 1 + len(rows)  # the header, then a row per run

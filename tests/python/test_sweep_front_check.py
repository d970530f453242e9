"""`rtsim sweep ... --check-front` (docs/sweeps.md): after the sweep, each Pareto-front design is
re-run with --check-verdict, and the verdict's named knob is set beside its measured gain and the
best measured one, in a printed table and SWEEP/front_check.json."""

from __future__ import annotations

import json
from pathlib import Path

from conftest import run_rtsim

SPEC = """\
name: front
scenes: [cornell]
workloads:
  - {name: primary, rays: [primary], resolution: 32x24}
grid:
  traversal.units: [2, 8]
"""


def test_check_front_measures_each_front_designs_named_knob(tmp_path: Path) -> None:
    (tmp_path / "front.yaml").write_text(SPEC)
    out = tmp_path / "out"
    result = run_rtsim("sweep", str(tmp_path / "front.yaml"), "-o", str(out), "--workers", "2",
                       "--no-progress", "--check-front")  # fmt: skip
    assert result.returncode == 0, result.stdout + result.stderr
    assert "Pareto front" in result.stdout and "front check:" in result.stdout
    rows = json.loads((out / "front_check.json").read_text())
    assert 1 <= len(rows) <= 2
    for row in rows:
        assert "error" not in row, row
        assert row["named"] and "=" in row["named"]
        assert row["estimated"] > 0 and row["measured"] > 0 and row["best_measured"] > 0
        assert row["best_measured"] >= row["measured"]
        assert (out / "front_check" / row["run"] / "check" / "1" / "stats.json").is_file()
        # The named knob is the one the verdict acts on: its `relax`, structural or not.
        stats = json.loads((out / "front_check" / row["run"] / "stats.json").read_text())
        relax = stats["verdict"]["relax"]
        to = relax["to"] if isinstance(relax["to"], str) else json.dumps(relax["to"])
        assert row["named"] == f"{relax['key']}={to}"

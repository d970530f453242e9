"""`rtsim demo` reports its own wall time, and the README's figure for it agrees with the
measurements recorded in docs/benchmarks.md."""

from __future__ import annotations

import io
import re
from pathlib import Path

import pytest
from rich.console import Console

from conftest import REPO
from rtsim.sweep import demo

TINY = """\
name: demo
scenes: [cornell]
workloads:
  - {name: primary, rays: [primary], resolution: 16x12}
grid:
  traversal.units: [2, 4]
"""


def test_demo_prints_its_wall_time(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(demo, "demo_spec_text", lambda: TINY)
    out = io.StringIO()
    code = demo.run_demo(tmp_path / "demo", Console(file=out, width=200), workers=1)
    assert code == 0, out.getvalue()
    assert (tmp_path / "demo" / "report.html").is_file()
    match = re.search(r"demo: (\d+) s \(1 local workers on \d+ cores", out.getvalue())
    assert match and int(match.group(1)) < 600, out.getvalue()


def test_readme_demo_figures_match_the_measurements() -> None:
    """README states the demo's CPU time as a range; every run recorded in docs/benchmarks.md
    falls in it (the CPU time hardly depends on load; the wall time does, so it is recorded)."""
    readme = " ".join((REPO / "README.md").read_text().split())
    stated = re.search(r"(\d+) to (\d+) CPU-seconds", readme)
    assert stated, "the README states the demo's CPU time as a range"
    low, high = int(stated.group(1)), int(stated.group(2))
    assert "prints its wall time" in readme
    bench = (REPO / "docs" / "benchmarks.md").read_text()
    section = bench[bench.index("## The demo") :]
    runs = re.findall(r"^\| demo run \d+ \|[^|]*\|[^|]*\| ([\d.]+) \| ([\d.]+) \|$", section, re.M)
    assert len(runs) >= 3, "docs/benchmarks.md records at least three demo runs"
    for wall, cpu in runs:
        assert low <= float(cpu) <= high, (low, high, cpu)
        assert float(wall) > float(cpu) / 2  # 2 workers cannot beat the CPU time halved

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


def test_readme_demo_time_matches_the_measurements() -> None:
    readme = " ".join((REPO / "README.md").read_text().split())
    stated = re.search(r"(\d+) to (\d+) s on 2 cores", readme)
    assert stated, "the README states the demo's wall time as a range on 2 cores"
    low, high = int(stated.group(1)), int(stated.group(2))
    bench = (REPO / "docs" / "benchmarks.md").read_text()
    section = bench[bench.index("## The demo") :]
    rows = re.findall(r"^\| demo run \d+ \|[^|]*\| ([\d.]+) \|", section, re.M)
    measured = [float(s) for s in rows]
    assert len(measured) >= 3, "docs/benchmarks.md records at least three demo runs"
    assert all(low <= s <= high for s in measured), (low, high, measured)

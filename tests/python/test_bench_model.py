"""`rtsim bench --model`: the simulator's own speed per fidelity level, end to end on a tiny trace.

No timing assertions (the machine may be shared): the report's shape, that every level ran, and
that the ratios are the medians' quotients.
"""

from __future__ import annotations

import json
from pathlib import Path

from conftest import rtsim_trace, run_rtsim


def test_bench_model_reports_every_level_and_the_ratios(tmp_path: Path) -> None:
    trace = tmp_path / "trace"
    rtsim_trace(
        "cornell", "-o", str(trace), "--workload", "diffuse",
        "--resolution", "32x24",
    )  # fmt: skip
    out = tmp_path / "bench.json"
    result = run_rtsim("bench", "--model", str(trace), "--repeat", "1", "--json", str(out),
                       "--levels", "functional,analytic,approx,treelets",
                       "--set", "traversal.units=2")  # fmt: skip
    assert result.returncode == 0, result.stdout + result.stderr
    report = json.loads(out.read_text())
    assert report["repeat"] == 1 and report["set"] == ["traversal.units=2"]
    (t,) = report["traces"]
    assert set(t["levels"]) == {"functional", "analytic", "approx", "treelets"}
    rays = {s["rays"] for s in t["levels"].values()}
    assert len(rays) == 1 and rays.pop() > 0
    for s in t["levels"].values():
        assert s["error"] is None
        assert len(s["wall_seconds"]) == len(s["cpu_seconds"]) == 1
        assert s["rays_per_wall_second"] > 0 and s["median_cpu_seconds"] >= 0
    # The analytic level's first run (which builds its per-trace analysis) is kept apart.
    assert t["levels"]["analytic"]["first_wall_seconds"] > 0
    cpu = {k: s["median_cpu_seconds"] for k, s in t["levels"].items()}
    for slow, fast in (("approx", "functional"), ("treelets", "approx")):
        if cpu[slow] and cpu[fast]:  # CPU time is counted in ticks: a tiny run may show 0
            assert t["ratios"][f"{slow}/{fast}"] == cpu[slow] / cpu[fast]
    assert t["ratios"]["detailed/approx"] is None  # not run
    assert "approx/functional (CPU)" in result.stdout


def test_bench_model_refuses_an_unknown_level(tmp_path: Path) -> None:
    result = run_rtsim("bench", "--model", str(tmp_path), "--levels", "approx,fastest")
    assert result.returncode == 2
    assert "fastest" in result.stdout + result.stderr


def test_bench_model_against_another_binary_compares_cpu_and_cycles(tmp_path: Path) -> None:
    from rtsim.launcher import find_sim

    trace = tmp_path / "trace"
    rtsim_trace("cornell", "-o", str(trace), "--resolution", "16x12")
    out = tmp_path / "bench.json"
    # Against itself: the same simulation, so the cycles agree.
    result = run_rtsim("bench", "--model", str(trace), "--repeat", "1", "--json", str(out),
                       "--levels", "approx", "--against", str(find_sim()))  # fmt: skip
    assert result.returncode == 0, result.stdout + result.stderr
    report = json.loads(out.read_text())
    assert report["against"] == str(find_sim())
    s = report["traces"][0]["levels"]["approx"]
    assert len(s["against_cpu_seconds"]) == 1 and s["against_error"] is None
    assert s["same_cycles_as_against"] is True and s["cycles"] == s["against_cycles"] > 0
    assert "| yes |" in result.stdout.replace("\n", " ") or "yes |" in result.stdout


def test_bench_model_against_a_missing_binary_is_refused(tmp_path: Path) -> None:
    result = run_rtsim("bench", "--model", str(tmp_path), "--against", str(tmp_path / "nope"))
    assert result.returncode == 2
    assert "nope" in result.stdout + result.stderr


def test_bench_model_says_whether_it_times_the_verdict(tmp_path: Path) -> None:
    trace = tmp_path / "trace"
    rtsim_trace("cornell", "-o", str(trace), "--resolution", "16x12")
    for flag, included in (((), False), (("--verdict",), True)):
        out = tmp_path / f"bench-{included}.json"
        result = run_rtsim("bench", "--model", str(trace), "--repeat", "1", "--json", str(out),
                           "--levels", "approx", *flag)  # fmt: skip
        assert result.returncode == 0, result.stdout + result.stderr
        report = json.loads(out.read_text())
        assert report["verdict"] is included
        said = "the bottleneck verdict is included" if included else "verdict is not included"
        assert said in " ".join(result.stdout.split())
        # Where and when: the doc generator (scripts/bench_doc.py --model) quotes these.
        assert report["host"]["cpu"] and report["host"]["hardware_threads"] >= 1
        assert report["host"]["load_average_start"] is not None
        assert report["date_start"] <= report["date_end"] and report["git"]


def test_bench_doc_renders_the_model_tables(tmp_path: Path) -> None:
    import importlib.util

    path = Path(__file__).resolve().parents[2] / "scripts" / "bench_doc.py"
    spec = importlib.util.spec_from_file_location("bench_doc", path)
    assert spec and spec.loader
    bench_doc = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench_doc)
    level = {"level": "approx", "rays": 1000, "error": None, "median_wall_seconds": 2.0,
             "median_cpu_seconds": 1.0, "rays_per_wall_second": 500.0,
             "rays_per_cpu_second": 1000.0, "against_cpu_seconds": []}  # fmt: skip
    bench = {"date_start": "2026-01-02T03:04:05+00:00", "date_end": "2026-01-02T03:09:00+00:00",
             "host": {"cpu": "Test CPU", "hardware_threads": 2, "load_average_start": 1.5,
                      "load_average_end": 2.0},
             "git": "abc123", "against": None, "repeat": 3, "set": [], "verdict": False,
             "traces": [{"trace": "/x/cornell", "levels": {"approx": level},
                         "ratios": {"approx/functional": None}}]}  # fmt: skip
    text = bench_doc.render_model(bench)
    assert "2026-01-02, 03:04-03:09 UTC, on Test CPU (2 hardware threads)" in text
    assert "load average 1.5" in text and "`abc123`" in text and "verdict is not included" in text
    assert "| cornell | approx | 1,000 |" in text and "/x/" not in text

"""`rtsim bench` end to end on a tiny procedural scene: the JSON it writes has every figure.

No timing assertions (the machine may be shared); only the shape and sanity of the report.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from conftest import run_rtsim
from rtsim.cli import find_bench

TOP_LEVEL = (
    "scene",
    "triangles",
    "resolution",
    "repeat",
    "rtsim_version",
    "git",
    "embree_version",
    "hardware_threads",
    "light",
    "light_note",
    "build",
    "rays",
    "date",
    "host",
)
RAY_KINDS = {"primary": "closest_hit", "diffuse": "closest_hit", "shadow": "any_hit"}
TIMES = ("wall_ms", "cpu_ms")
THROUGHPUT = (*TIMES, "mrays_per_s_wall", "mrays_per_s_cpu", "hits")


@pytest.fixture(scope="module")
def bench_json(tmp_path_factory: pytest.TempPathFactory) -> dict:
    if find_bench() is None:
        pytest.skip("rtsim-bench is not built (no Embree)")
    out = tmp_path_factory.mktemp("bench") / "bench.json"
    result = run_rtsim(
        "bench", "cornell", "--repeat", "1", "--resolution", "32x24", "--json", str(out),
        "--accel", "bvh8,bvh2:sbvh,cwbvh8", "--build-threads", "2",
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert "rtsim/Embree" in result.stdout
    return json.loads(out.read_text())


def test_bench_json_keys(bench_json: dict) -> None:
    for key in TOP_LEVEL:
        assert key in bench_json, key
    assert bench_json["repeat"] == 1
    assert bench_json["resolution"] == [32, 24]
    assert bench_json["triangles"] > 0
    for tracer in ("rtsim", "embree"):
        for key in TIMES:
            assert bench_json["build"][tracer][key] >= 0.0
    assert set(bench_json["rays"]) == set(RAY_KINDS)
    assert set(bench_json["build"]["structures"]) == {"bvh8", "bvh2:sbvh", "cwbvh8"}
    # The host and its load: what the figures of a shared machine need to be read.
    assert bench_json["host"]["cpu"]
    assert bench_json["host"]["load_average_start"] >= 0
    assert bench_json["host"]["load_average_end"] >= 0
    assert len(bench_json["date"]) == 20 and bench_json["date"].endswith("Z")


def test_bench_parallel_build(bench_json: dict) -> None:
    parallel = bench_json["build"]["parallel"]
    assert parallel["threads"] == 2
    assert set(parallel["structures"]) == {"bvh8", "bvh2:sbvh", "cwbvh8"}
    for figures in parallel["structures"].values():
        assert figures["wall_ms"] > 0 and figures["process_cpu_ms"] > 0
        assert figures["speedup_wall"] > 0


def test_bench_on_the_command_line() -> None:
    """docs/benchmarks.md runs `rtsim-bench` directly: it is installed beside rtsim-sim."""
    from rtsim.launcher import find_sim

    if find_bench() is None:
        pytest.skip("rtsim-bench is not built (no Embree)")
    sim = find_sim()
    if "build" in sim.parts:
        pytest.skip("rtsim-sim runs from the build tree: the package is not installed")
    assert (sim.parent / "rtsim-bench").is_file()


def test_bench_refuses_an_unknown_builder(tmp_path: Path) -> None:
    if find_bench() is None:
        pytest.skip("rtsim-bench is not built (no Embree)")
    result = run_rtsim("bench", "cornell", "--accel", "bvh8:bogus", "--repeat", "1")
    assert result.returncode == 2
    assert "bvh8:bogus" in result.stderr and "no builder 'bogus'" in result.stderr


@pytest.mark.parametrize("kind", list(RAY_KINDS))
def test_bench_ray_figures(bench_json: dict, kind: str) -> None:
    figures = bench_json["rays"][kind]
    assert figures["mode"] == RAY_KINDS[kind]
    assert figures["rays"] > 0
    for tracer in ("rtsim", "embree"):
        for key in THROUGHPUT:
            assert figures[tracer][key] >= 0, (tracer, key)
        assert figures[tracer]["mrays_per_s_cpu"] > 0
    # Both tracers trace the same rays; on the cornell box they agree on the hit count.
    assert figures["rtsim"]["hits"] == figures["embree"]["hits"]
    for name, structure in figures["structures"].items():
        assert structure["rtsim"]["hits"] == figures["embree"]["hits"], name
    assert figures["ratio_cpu"] > 0 and figures["ratio_wall"] > 0


def test_bench_missing_executable(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    from rtsim.cli import main

    monkeypatch.setenv("RTSIM_BENCH", str(tmp_path / "nope"))
    assert main(["bench", "cornell"]) == 2

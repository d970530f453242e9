"""The model's laws end to end: every simulation is one `rtsim-sim` process on a small trace.

- every scene traces with zero hit and work mismatches, at several model configurations;
- monotonic sanity: more DRAM bandwidth, more units, bigger L1 and ideal memory never hurt;
- bad input (config field, config file, truncated trace) exits 2 naming the field or file;
- a doctored reference is caught: listed in stats.json and exit code 3;
- stats.json carries the documented summary, config.resolved.json round-trips, --timeline works.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import zlib
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import rtsim
from conftest import rtsim_trace

SIM_EXE = "rtsim-sim"
RESOLUTION = "48x32"
WORKLOAD = "primary,shadow,reflection,diffuse"
PROCEDURAL = ["cornell", "hairball", "teapot_stadium", "rotated_walls"]
SHARED = {
    "sponza": "sponza/Sponza.gltf",
    "bunny": "stanford_bunny/bunny.gltf",
    "lamp": "LightsPunctualLamp/LightsPunctualLamp.gltf",
    "spheres": "MetalRoughSpheresNoTextures/MetalRoughSpheresNoTextures.gltf",
    "alpha": "AlphaBlendModeTest/AlphaBlendModeTest.gltf",
    "instancing": "SimpleInstancing/SimpleInstancing.gltf",
}
# Model configurations that must all reproduce the reference exactly.
CONFIGS = {
    "default": [],
    "functional": ["fidelity=functional"],
    "analytic": ["fidelity=analytic"],
    "detailed": ["fidelity=detailed"],
    "shared_pipelines": ["box.sharing=shared", "triangle.sharing=shared"],
    "stack_spills": ["traversal.stack_entries=1"],
    "ideal_memory": ["ideal_memory=true"],
    # More rays in flight than a dispatch chunk: rays finish many chunks out of order.
    "small_chunks": ["dispatch.chunk_rays=64", "traversal.ray_contexts=64"],
    # Treelet scheduling: rays wait in per-treelet queues between steps; a 1 KiB buffer forces
    # overflow to DRAM and tiny treelets force a park at almost every node.
    "treelets": ["treelets.enabled=true"],
    "treelets_overflow": [
        "treelets.enabled=true",
        "treelets.buffer_kib=1",
        "treelets.policy=oldest",
    ],
    "treelets_tiny": [
        "treelets.enabled=true",
        "treelets.treelet_kib=1",
        "treelets.policy=round_robin",
    ],
}
NOISE = 1.02  # timing comparisons allow 2% (rays interleave differently when timing changes)


Sim = Callable[..., subprocess.CompletedProcess[str]]


@pytest.fixture(scope="session")
def sim(sim_exe: Path) -> Sim:
    """sim(trace, out, *sets, extra=[...]): runs rtsim-sim once and returns the process."""

    def run(trace: Path, out: Path, *sets: str, extra: tuple[str, ...] = ()) -> Any:
        args = [str(sim_exe), str(trace), "-o", str(out), *extra]
        for s in sets:
            args += ["--set", s]
        return subprocess.run(args, capture_output=True, text=True, timeout=300, check=False)

    return run


@pytest.fixture(scope="session")
def trace_of(tmp_path_factory: pytest.TempPathFactory) -> Callable[[str, str], Path]:
    """trace_of(name, scene): `rtsim trace` once per scene per session (48x32, one bounce)."""
    root = tmp_path_factory.mktemp("model_traces")
    made: dict[str, Path] = {}

    def trace(name: str, scene: str) -> Path:
        if name not in made:
            out = root / name
            rtsim_trace(
                scene, "-o", str(out), "--workload", WORKLOAD,
                "--resolution", RESOLUTION, "--bounces", "1",
            )  # fmt: skip
            made[name] = out
        return made[name]

    return trace


@pytest.fixture(scope="session")
def hairball(trace_of: Callable[[str, str], Path]) -> Path:
    return trace_of("hairball", "hairball")


@pytest.fixture(scope="session")
def cornell_small(trace_of: Callable[[str, str], Path]) -> Path:
    return trace_of("cornell", "cornell")


def stats_of(run: Path) -> dict[str, Any]:
    return json.loads((run / "stats.json").read_text())


def scene_cases() -> list[Any]:
    cases = [pytest.param(name, None, id=name) for name in PROCEDURAL]
    cases += [pytest.param(name, rel, id=name) for name, rel in SHARED.items()]
    return cases


# --- hit equality on every scene and configuration ---------------------------------------


@pytest.mark.parametrize("config", list(CONFIGS))
@pytest.mark.parametrize(("name", "shared_path"), scene_cases())
def test_model_matches_reference(
    request: pytest.FixtureRequest,
    trace_of: Callable[[str, str], Path],
    sim: Sim,
    tmp_path: Path,
    name: str,
    shared_path: str | None,
    config: str,
) -> None:
    scene = name
    if shared_path is not None:
        scene = str(request.getfixturevalue("scenes_dir") / shared_path)
    trace = trace_of(name, scene)
    result = sim(trace, tmp_path / "run", *CONFIGS[config])
    assert result.returncode == 0, result.stderr
    stats = stats_of(tmp_path / "run")
    summary, validation = stats["summary"], stats["validation"]
    rays = len(rtsim.open_trace(trace).rays)
    assert summary["rays"] == validation["rays_checked"] == rays > 0
    assert summary["hit_mismatches"] == 0, validation["first_mismatches"]
    assert summary["work_mismatches"] == 0, validation["first_mismatches"]
    if config == "functional":
        assert summary["cycles"] is None
    else:
        assert summary["cycles"] > 0
    if config == "stack_spills":
        units = stats["model"]["units"].values()
        writes = sum(u["stack_spill_writes"] for u in units)
        reads = sum(u["stack_spill_reads"] for u in units)
        # Every spilled entry is read back at most once (any-hit rays stop with entries left).
        assert 0 < reads <= writes, "with one on-chip entry, deeper entries must spill"


# --- monotonic sanity ----------------------------------------------------------------------


@pytest.fixture(scope="module")
def hairball_runs(hairball: Path, sim: Sim, tmp_path_factory: pytest.TempPathFactory) -> dict:
    """Stats of the hairball (memory-bound: most L1 reads miss) under several configs."""
    root = tmp_path_factory.mktemp("hairball_runs")
    configs = {
        "base": [],
        "dram_x2": ["dram.bytes_per_cycle=32"],
        "dram_x4": ["dram.bytes_per_cycle=64"],
        "units_4": ["traversal.units=4"],
        "units_16": ["traversal.units=16"],
        "l1_32": ["l1.size_kib=32"],
        "l1_64": ["l1.size_kib=64"],
        "ideal": ["ideal_memory=true"],
    }
    runs = {}
    for key, sets in configs.items():
        result = sim(hairball, root / key, *sets)
        assert result.returncode == 0, f"{key}: {result.stderr}"
        runs[key] = stats_of(root / key)
    return runs


def cycles(stats: dict[str, Any]) -> int:
    return stats["summary"]["cycles"]


def l1_misses(stats: dict[str, Any]) -> int:
    return sum(c["reads"] - c["read_hits"] - c["merged"] for c in stats["model"]["l1"].values())


def test_more_dram_bandwidth_never_slower(hairball_runs: dict) -> None:
    base, x2, x4 = (cycles(hairball_runs[k]) for k in ("base", "dram_x2", "dram_x4"))
    assert x2 <= base * NOISE
    assert x4 <= x2 * NOISE


def test_more_units_never_slower(hairball_runs: dict) -> None:
    u4, u8, u16 = (cycles(hairball_runs[k]) for k in ("units_4", "base", "units_16"))
    assert u8 <= u4 * NOISE
    assert u16 <= u8 * NOISE


def test_ideal_memory_is_fastest(hairball_runs: dict) -> None:
    ideal = cycles(hairball_runs["ideal"])
    for key, stats in hairball_runs.items():
        if key != "ideal":
            assert ideal < cycles(stats), key
    assert hairball_runs["ideal"]["summary"]["dram_bytes"] == 0


def test_bigger_l1_never_misses_more(hairball_runs: dict) -> None:
    # LRU with more sets and the same ways holds a superset of lines (Mattson et al. 1970); the
    # order of accesses shifts a little with timing, hence the noise allowance.
    m16, m32, m64 = (l1_misses(hairball_runs[k]) for k in ("base", "l1_32", "l1_64"))
    assert m16 > 0
    assert m32 <= m16 * NOISE
    assert m64 <= m32 * NOISE
    assert m64 < m16


# --- bad input -----------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("assignment", "named"),
    [
        ("l1.size_kib=0", "l1.size_kib"),
        ("box.sharing=maybe", "box.sharing"),
        ("nonsense.key=1", "nonsense.key"),
        ("traversal.units=1.5", "traversal.units"),
        ("l1.line_bytes=128", "l1.line_bytes"),
    ],
)
def test_invalid_config_rejected_with_field_name(
    cornell_small: Path, sim: Sim, tmp_path: Path, assignment: str, named: str
) -> None:
    result = sim(cornell_small, tmp_path / "run", assignment)
    assert result.returncode == 2, result.stderr
    assert named in result.stderr
    assert not (tmp_path / "run" / "stats.json").exists()


def test_config_file_with_misspelt_key(cornell_small: Path, sim: Sim, tmp_path: Path) -> None:
    config = tmp_path / "my_config.json"
    config.write_text(json.dumps({"l1": {"size_kb": 32}}))
    result = sim(cornell_small, tmp_path / "run", extra=("--config", str(config)))
    assert result.returncode == 2
    assert "my_config.json" in result.stderr and "l1.size_kb" in result.stderr


def test_truncated_trace_rejected_naming_the_file(
    cornell_small: Path, sim: Sim, tmp_path: Path
) -> None:
    data = (cornell_small / "trace.rtt").read_bytes()
    bad = tmp_path / "truncated.rtt"
    bad.write_bytes(data[: len(data) // 2])
    result = sim(bad, tmp_path / "run")
    assert result.returncode == 2
    assert "truncated.rtt" in result.stderr
    result = sim(tmp_path / "missing", tmp_path / "run")
    assert result.returncode == 2 and "missing" in result.stderr


def test_corrupt_reference_chunk_rejected(cornell_small: Path, sim: Sim, tmp_path: Path) -> None:
    # A flipped bit in the reference hits (read while the model runs) is bad input too: exit 2
    # naming the file and section, not a SystemC report.
    bad = tmp_path / "bad_hits.rtt"
    shutil.copy(cornell_small / "trace.rtt", bad)
    hits = next(s for s in rtsim.trace_sections(bad) if s["kind"].lower() == "hits")
    data = bytearray(bad.read_bytes())
    data[hits["offset"] + 8] ^= 1
    bad.write_bytes(bytes(data))
    result = sim(bad, tmp_path / "run")
    assert result.returncode == 2, result.stderr
    assert "bad_hits.rtt" in result.stderr and "HITS" in result.stderr


# --- a wrong reference is caught -----------------------------------------------------------


def doctor(trace: Path, out: Path, section: str, record: int, field: str, value: Any) -> None:
    """Copies `trace` to `out` with one field of one record changed and the chunk CRC fixed
    (docs/trace_format.md: CRC32 per chunk of chunk_bytes, table at crc_offset)."""
    shutil.copy(trace, out)
    info = next(s for s in rtsim.trace_sections(out) if s["kind"].lower() == section)
    dtype = rtsim.trace_file.SECTION_DTYPES[section]
    data = bytearray(out.read_bytes())
    records = np.frombuffer(
        data, dtype=dtype, count=info["record_count"], offset=info["offset"]
    ).copy()
    records[field][record] = value
    payload = records.tobytes()
    data[info["offset"] : info["offset"] + len(payload)] = payload
    chunk = record * info["record_bytes"] // info["chunk_bytes"]
    lo = info["offset"] + chunk * info["chunk_bytes"]
    hi = min(lo + info["chunk_bytes"], info["offset"] + info["bytes"])
    crc = zlib.crc32(bytes(data[lo:hi])) & 0xFFFFFFFF
    crc_at = info["crc_offset"] + 4 * chunk
    data[crc_at : crc_at + 4] = crc.to_bytes(4, "little")
    out.write_bytes(bytes(data))


def test_wrong_reference_is_detected(cornell_small: Path, sim: Sim, tmp_path: Path) -> None:
    trace = rtsim.open_trace(cornell_small)
    hit_ray = int(np.flatnonzero(trace.hits["prim"] >= 0)[0])
    work_ray = int(np.flatnonzero(trace.work["steps"] > 0)[-1])
    assert hit_ray != work_ray
    t = trace.hits["t"][hit_ray]
    step1 = tmp_path / "one.rtt"
    doctor(
        cornell_small / "trace.rtt",
        step1,
        "hits",
        hit_ray,
        "t",
        np.nextafter(t, np.float32(np.inf)),
    )
    doctored = tmp_path / "doctored.rtt"
    nodes = int(trace.work["steps"][work_ray])
    doctor(step1, doctored, "work", work_ray, "steps", nodes + 1)
    rtsim.verify_trace(doctored)  # the file itself is sound: only the reference is wrong

    result = sim(doctored, tmp_path / "run")
    assert result.returncode == 3, result.stderr
    validation = stats_of(tmp_path / "run")["validation"]
    assert validation["hit_mismatches"] == 1
    assert validation["work_mismatches"] == 1
    listed = {m["ray"]: m["difference"] for m in validation["first_mismatches"]}
    assert set(listed) == {hit_ray, work_ray}
    assert listed[hit_ray].startswith("hit:")
    # The work difference names the field that differs, model/reference.
    assert listed[work_ray].startswith("work") and f"steps {nodes}/{nodes + 1}" in listed[work_ray]
    # The functional level checks the same way.
    result = sim(doctored, tmp_path / "functional", "fidelity=functional")
    assert result.returncode == 3
    assert stats_of(tmp_path / "functional")["validation"]["hit_mismatches"] == 1


# --- outputs -------------------------------------------------------------------------------

SUMMARY_KEYS = {
    "cycles", "rays", "rays_per_second", "hit_mismatches", "work_mismatches", "unit_busy_fraction",
    "box_utilization", "triangle_utilization", "l1_hit_rate", "l2_hit_rate", "dram_bytes_per_ray",
    "dram_bandwidth_gbps", "avg_ray_latency_cycles",
}  # fmt: skip


def test_stats_and_resolved_config_round_trip(
    cornell_small: Path, sim: Sim, tmp_path: Path
) -> None:
    first = tmp_path / "first"
    result = sim(cornell_small, first, "traversal.units=2", "l1.size_kib=32", extra=("--timeline",))
    assert result.returncode == 0, result.stderr
    stats = stats_of(first)
    summary = stats["summary"]
    assert set(summary) >= SUMMARY_KEYS, SUMMARY_KEYS - set(summary)
    assert summary["cycles"] > 0 and summary["rays_per_second"] > 0
    assert 0 < summary["unit_busy_fraction"] <= 1
    assert 0 < summary["box_utilization"] <= 1
    assert 0 <= summary["l1_hit_rate"] <= 1 and 0 <= summary["l2_hit_rate"] <= 1
    assert summary["dram_bytes_per_ray"] > 0 and summary["dram_bandwidth_gbps"] > 0
    latency = stats["latency"]
    assert latency["rays"] == summary["rays"]
    assert sum(latency["histogram"]["rays"]) == summary["rays"]
    assert (
        latency["p50_cycles"]
        <= latency["p95_cycles"]
        <= latency["p99_cycles"]
        <= latency["max_cycles"]
    )
    assert len(stats["model"]["units"]) == 2
    for name in ("config.resolved.json", "provenance.json"):
        assert (first / name).is_file()

    resolved = json.loads((first / "config.resolved.json").read_text())
    assert resolved["traversal"]["units"] == 2 and resolved["l1"]["size_kib"] == 32
    second = tmp_path / "second"
    result = sim(cornell_small, second, extra=("--config", str(first / "config.resolved.json")))
    assert result.returncode == 0, result.stderr
    assert json.loads((second / "config.resolved.json").read_text()) == resolved
    # Same config, same trace: the same cycle count (deterministic).
    assert stats_of(second)["summary"]["cycles"] == summary["cycles"]

    timeline = json.loads((first / "timeline.json").read_text())
    events = timeline["traceEvents"]
    spans = [e for e in events if e.get("ph") == "X"]
    assert len(spans) == summary["rays"]
    assert all(e["dur"] >= 0 and e["pid"] in (0, 1) for e in spans)
    assert any(e.get("ph") == "C" for e in events), "DRAM bandwidth counter"

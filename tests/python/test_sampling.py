"""Statistical sampling (sampling.fraction / sampling.count) and `rtsim accuracy`, end to end:

- sampled runs check every simulated ray against the reference (zero mismatches) and report the
  estimate, its 95% interval and the sample in stats.json, every key documented in docs/stats.md;
- coverage: over 40 seeds the interval contains the full run's cycles at about the promised rate;
- bad sampling configs exit 2 naming the field;
- `rtsim accuracy` on a tiny scene writes its table and plot.
"""

from __future__ import annotations

import csv
import json
import re
import subprocess
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from conftest import REPO, rtsim_trace, run_rtsim, simulate
from rtsim.launcher import SimResult, find_sim

# Two units of four contexts: few rays in flight, so a small trace has many clusters.
SMALL_MACHINE = ["traversal.units=2", "traversal.ray_contexts=4"]


def sim(trace: Path, out: Path, *sets: str) -> SimResult:
    return simulate(find_sim(), trace, out, *sets)


def sim_levels() -> list[str]:
    schema = subprocess.run([str(find_sim()), "--dump-schema"], capture_output=True, text=True)
    return list(json.loads(schema.stdout)["fidelity"]["choices"])


def stats_of(run: Path) -> dict[str, Any]:
    return json.loads((run / "stats.json").read_text())


@pytest.fixture(scope="module")
def traces(tmp_path_factory: pytest.TempPathFactory) -> Callable[[str], Path]:
    """traces(scene): a 64x48 primary + diffuse trace of a built-in scene, made once."""
    root = tmp_path_factory.mktemp("sampling")
    made: dict[str, Path] = {}

    def trace(scene: str) -> Path:
        if scene not in made:
            out = root / scene
            rtsim_trace(
                scene, "-o", str(out), "--workload", "primary,diffuse",
                "--resolution", "64x48",
            )  # fmt: skip
            made[scene] = out
        return made[scene]

    return trace


@pytest.mark.parametrize("scene", ["cornell", "hairball"])
@pytest.mark.parametrize("fidelity", ["approx", "detailed"])
def test_sampled_run_checks_every_simulated_ray(
    traces: Callable[[str], Path], tmp_path: Path, scene: str, fidelity: str
) -> None:
    if fidelity not in sim_levels():
        pytest.skip(f"rtsim-sim has no {fidelity} level")
    trace = traces(scene)
    result = sim(
        trace, tmp_path / "run", f"fidelity={fidelity}", "sampling.fraction=0.3", *SMALL_MACHINE
    )
    assert result.returncode == 0, result.stderr
    stats = stats_of(tmp_path / "run")
    summary, sampling, validation = stats["summary"], stats["sampling"], stats["validation"]
    assert summary["sampled"] is True
    assert summary["hit_mismatches"] == summary["work_mismatches"] == 0
    assert validation["rays_checked"] == sampling["simulated_rays"] < summary["rays"]
    assert sampling["trace_rays"] == summary["rays"]
    per_cluster = sampling["warmup_rays"] + sampling["measured_rays"]
    assert sampling["simulated_rays"] == sampling["clusters"] * per_cluster
    assert sampling["measured_rays"] >= sampling["warmup_rays"] > 0
    lo, hi = summary["cycles_ci95"]
    assert 0 <= lo <= summary["cycles"] <= hi
    assert sampling["cycles_ci95"] == [lo, hi]
    # The strata tile the trace in order and each cluster lies inside its stratum.
    first = 0
    for s in sampling["strata"]:
        assert s["first_ray"] == first
        assert s["first_ray"] <= s["cluster_first_ray"]
        assert s["cluster_first_ray"] + per_cluster <= s["first_ray"] + s["rays"]
        assert s["cycles_per_ray"] > 0
        first += s["rays"]
    assert first == summary["rays"]


def test_full_run_says_not_sampled(traces: Callable[[str], Path], tmp_path: Path) -> None:
    assert sim(traces("cornell"), tmp_path / "run").returncode == 0
    stats = stats_of(tmp_path / "run")
    assert stats["summary"]["sampled"] is False and "sampling" not in stats


def test_sampling_is_deterministic_and_seeded(
    traces: Callable[[str], Path], tmp_path: Path
) -> None:
    sets = ["sampling.fraction=0.3", *SMALL_MACHINE]
    runs = {}
    for name, seed in (("a", 1), ("b", 1), ("c", 2)):
        assert (
            sim(traces("cornell"), tmp_path / name, *sets, f"sampling.seed={seed}").returncode == 0
        )
        runs[name] = stats_of(tmp_path / name)["sampling"]
    assert runs["a"]["strata"] == runs["b"]["strata"]
    assert runs["a"]["cycles"] == runs["b"]["cycles"]
    firsts = [[s["cluster_first_ray"] for s in runs[k]["strata"]] for k in ("a", "c")]
    assert firsts[0] != firsts[1]


def test_interval_covers_the_full_run(traces: Callable[[str], Path], tmp_path: Path) -> None:
    """Coverage (SMARTS-style): over 40 seeds (random cluster offsets) the 95% interval contains
    the full run's cycles in at least 85% of the runs. Thirty clusters of 16 warm-up rays on a
    small machine (8 rays in flight) keep each run to a few milliseconds."""
    trace = traces("cornell")
    assert sim(trace, tmp_path / "full", *SMALL_MACHINE).returncode == 0
    full = stats_of(tmp_path / "full")["summary"]["cycles"]
    sets = [*SMALL_MACHINE, "sampling.fraction=0.2", "sampling.warmup_rays=16"]
    inside, errors = 0, []
    for seed in range(40):
        result = sim(trace, tmp_path / "s", *sets, f"sampling.seed={seed}")
        assert result.returncode == 0, result.stderr
        summary = stats_of(tmp_path / "s")["summary"]
        lo, hi = summary["cycles_ci95"]
        inside += lo <= full <= hi
        errors.append(summary["cycles"] / full - 1)
    assert stats_of(tmp_path / "s")["sampling"]["clusters"] == 30
    assert inside >= 34, f"interval held the full run in {inside}/40 runs; errors {errors}"
    # The estimate is not wildly off on average either (its bias is documented, fidelity.md).
    assert abs(sum(errors) / len(errors)) < 0.2


def test_functional_warming_replays_the_rays_before_each_cluster(
    traces: Callable[[str], Path], tmp_path: Path
) -> None:
    """Up to sampling.warming_rays skipped rays before each cluster (never into the previous
    cluster) go through the caches without time; 0 turns it off and says so."""
    trace = traces("cornell")
    sets = [*SMALL_MACHINE, "sampling.fraction=0.3", "sampling.warmup_rays=16"]
    assert sim(trace, tmp_path / "w", *sets, "sampling.warming_rays=100").returncode == 0
    sampling = stats_of(tmp_path / "w")["sampling"]
    per_cluster = sampling["warmup_rays"] + sampling["measured_rays"]
    expected, previous_end = 0, 0
    for s in sampling["strata"]:
        expected += min(100, s["cluster_first_ray"] - previous_end)
        previous_end = s["cluster_first_ray"] + per_cluster
    warming = sampling["functional_warming"]
    assert warming["rays_per_cluster"] == 100
    assert warming["warmed_rays"] == expected > 0
    assert warming["warmed_reads"] > warming["warmed_rays"]  # a ray record and its nodes each
    assert not any("warming" in c for c in sampling["caveats"])
    assert sim(trace, tmp_path / "off", *sets, "sampling.warming_rays=0").returncode == 0
    off = stats_of(tmp_path / "off")["sampling"]
    assert off["functional_warming"]["warmed_rays"] == 0
    assert any("no functional warming" in c for c in off["caveats"])


def test_a_small_sample_says_it_is_too_small(traces: Callable[[str], Path], tmp_path: Path) -> None:
    # 30% of 5,986 rays on the default machine (128 rays in flight): 3 clusters of 2 x 256 rays.
    result = sim(traces("cornell"), tmp_path / "run", "sampling.fraction=0.3")
    assert result.returncode == 0, result.stderr
    sampling = stats_of(tmp_path / "run")["sampling"]
    assert sampling["clusters"] < 10
    assert any("clusters" in c for c in sampling["caveats"])
    assert "warning: sample too small to trust" in result.stderr


@pytest.mark.parametrize(
    ("sets", "message"),
    [
        (["fidelity=functional", "sampling.fraction=0.5"], "sampling"),
        (["sampling.fraction=0.5", "sampling.count=100"], "sampling.count"),
        (["sampling.fraction=1.5"], "sampling.fraction"),
        (["sampling.count=100"], "sampling.count"),  # too small for 2 clusters with warm-up
        (["sampling.count=100000000"], "sampling.count"),  # more than the trace
    ],
)
def test_bad_sampling_config_exits_2(
    traces: Callable[[str], Path], tmp_path: Path, sets: list[str], message: str
) -> None:
    result = sim(traces("cornell"), tmp_path / "run", *sets)
    assert result.returncode == 2, result.stderr
    assert message in result.stderr
    assert not (tmp_path / "run" / "stats.json").exists()


def test_sampling_keys_are_documented(traces: Callable[[str], Path], tmp_path: Path) -> None:
    from test_simulate_cli import PLACEHOLDER, stats_keys

    doc = (REPO / "docs" / "stats.md").read_text()
    documented = set()
    for token in re.findall(r"`([A-Za-z0-9_.<> ]+)`", doc):
        documented.update(token.split("."))
    assert (
        sim(traces("cornell"), tmp_path / "run", "sampling.fraction=0.3", *SMALL_MACHINE).returncode
        == 0
    )
    stats = stats_of(tmp_path / "run")
    missing = {
        ".".join(p)
        for p in stats_keys(stats)
        if not PLACEHOLDER.match(p[-1]) and p[-1] not in documented
    }
    strata = stats["sampling"]["strata"][0]
    missing |= {f"sampling.strata[].{k}" for k in strata if k not in documented}
    assert not missing, f"keys of stats.json not in docs/stats.md: {sorted(missing)}"


def test_accuracy_writes_table_and_plot(tmp_path: Path) -> None:
    out = tmp_path / "acc"
    small = ["--set", "traversal.units=2", "--set", "traversal.ray_contexts=4"]
    result = run_rtsim("accuracy", "cornell", "-o", str(out), "--resolution", "48x32",
                       "--repeat", "1", "--fractions", "0.5",
                       "--set", "sampling.warmup_rays=16", *small)  # fmt: skip
    assert result.returncode == 0, result.stdout + result.stderr
    for name in ("accuracy.csv", "accuracy.md", "accuracy.json", "accuracy.png"):
        assert (out / name).is_file() and (out / name).stat().st_size > 0, name
    with (out / "accuracy.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert {r["workload"] for r in rows} == {"primary", "diffuse"}
    levels = {r["level"] for r in rows if not r["fraction"]}
    assert {"functional", "approx"} <= levels
    reference = "detailed" if "detailed" in levels else "approx"
    ref_rows = [r for r in rows if r["level"] == reference and not r["fraction"]]
    assert all(float(r["error"]) == 0 for r in ref_rows)
    sampled = [r for r in rows if r["fraction"] and r["status"] == "ok"]
    assert sampled and all(r["sampling_error"] and r["ci_contains_full"] for r in sampled)
    assert all(r["hit_mismatches"] in ("", "0") for r in rows)
    assert (out / "accuracy.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_sampling_with_treelets_measures_completions(
    traces: Callable[[str], Path], tmp_path: Path
) -> None:
    """With treelet scheduling a cluster fills the ray buffer before it measures, and its
    throughput is measured from completions, not starts (the buffer admits rays long before the
    machine traces them): the run samples, and every sampled ray is checked."""
    small = (
        "treelets.enabled=true",
        "treelets.buffer_kib=8",
        "traversal.units=2",
        "traversal.ray_contexts=8",
    )
    result = sim(traces("cornell"), tmp_path / "run", *small, "sampling.fraction=0.6")
    assert result.returncode == 0, result.stderr
    stats = json.loads((tmp_path / "run" / "stats.json").read_text())
    sampling = stats["sampling"]
    assert stats["summary"]["sampled"] and sampling["measured_by"] == "completions"
    assert (
        stats["validation"]["hit_mismatches"] == 0 and stats["validation"]["work_mismatches"] == 0
    )
    # The warm-up fills the buffer (its rays) and the contexts twice over.
    buffer_rays = stats["model"]["ray_buffer"]["capacity_rays"]
    assert sampling["warmup_target_rays"] == 2 * 2 * 8 + buffer_rays

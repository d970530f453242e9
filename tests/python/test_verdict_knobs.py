"""The verdict weighs every knob, says where it cannot estimate, and is checked by re-running
(docs/verdict.md): every resource a candidate with its area, the top three, treelet runs
marked unestimated rather than answered wrongly, `--check-verdict` measuring the top knobs in
their own processes, and the roofline's MSHR ceilings by Little's law.

Each simulation is one `rtsim-sim` process on the small hairball trace (fixtures in test_model).
"""

from __future__ import annotations

import json
import subprocess
from pathlib import Path
from typing import Any

import pytest

from test_model import Sim, hairball, sim, trace_of  # noqa: F401  (fixtures)


def run_stats(
    sim: Sim, trace: Path, out: Path, *sets: str, extra: tuple[str, ...] = ()  # noqa: F811
) -> dict[str, Any]:  # fmt: skip
    result = sim(trace, out, *sets, extra=extra)
    assert result.returncode == 0, result.stderr
    return json.loads((out / "stats.json").read_text())


def test_every_knob_is_weighed(hairball: Path, sim: Sim, tmp_path: Path) -> None:  # noqa: F811
    v = run_stats(sim, hairball, tmp_path / "run")["verdict"]
    keys = {c["key"] for c in v["candidates"]}
    for key in ("traversal.units", "traversal.ray_contexts", "box.width", "l1.size_kib",
                "l2.size_kib", "l1.banks", "l2.banks", "l1.mshrs", "l2.mshrs", "dram.channels",
                "traversal.stack_entries"):  # fmt: skip
        assert key in keys, key
    assert len(v["top"]) == 3 and v["top"] == v["candidates"][:3]
    gains = [c["speedup"] for c in v["candidates"]]
    if "tie_break" in v["candidates"][0]:  # a near tie went to the knob that also removes traffic
        assert gains[0] >= gains[1] - 0.03 and v["candidates"][0]["dram_saved_fraction"] > 0
        gains[0], gains[1] = gains[1], gains[0]
    assert all(g is not None for g in gains) and gains == sorted(gains, reverse=True)
    assert v["relax"]["key"] == v["top"][0]["key"]
    # Area: SRAM and pipelines are priced, MSHRs are not.
    by_key = {c["key"]: c for c in v["candidates"]}
    assert by_key["l2.size_kib"]["added_mm2"] > 0 and by_key["l2.mshrs"]["gain_per_mm2"] is None
    for k in v["top_per_mm2"]:
        assert k["gain_per_mm2"] == pytest.approx((k["speedup"] - 1) / k["added_mm2"])
    assert v["coverage"]["estimated"] is True


def test_treelet_runs_estimate_resources_and_measure_treelet_knobs(
    hairball: Path, sim: Sim, tmp_path: Path  # noqa: F811
) -> None:  # fmt: skip
    """The analytic level steps its sample in treelet order, so a treelet design's resource knobs
    are estimated; the ray buffer's own knobs change the order itself and are left to measure."""
    v = run_stats(sim, hairball, tmp_path / "run", "treelets.enabled=true")["verdict"]
    assert v["coverage"]["estimated"] is True
    by_key = {c["key"]: c for c in v["candidates"]}
    assert {"treelets.admit_outstanding", "treelets.buffer_kib", "treelets.policy"} <= set(by_key)
    assert all(by_key[k]["speedup"] is None for k in ("treelets.buffer_kib", "treelets.policy"))
    assert (
        by_key["l2.size_kib"]["speedup"] is not None
        and by_key["traversal.units"]["speedup"] is not None
    )


def test_check_verdict_measures_the_top_knobs(hairball: Path, sim: Sim, tmp_path: Path) -> None:  # noqa: F811
    out = tmp_path / "run"
    stats = run_stats(sim, hairball, out, extra=("--check-verdict",))
    v = stats["verdict"]
    checks = v["check"]
    assert len(checks) >= 3
    base = stats["summary"]["rays_per_second"]
    for c in checks:
        run = json.loads((Path(c["run"]) / "stats.json").read_text())
        assert run["verdict"] is None  # the re-runs skip their own verdict
        resolved = json.loads((Path(c["run"]) / "config.resolved.json").read_text())
        for assignment in c["sets"]:
            key, value = assignment.split("=")
            section, field = key.split(".")
            got = resolved[section][field]
            assert (json.dumps(got) if isinstance(got, bool) else str(got)) == value
        assert c["measured"] == pytest.approx(run["summary"]["rays_per_second"] / base)
    # The best structural alternative a re-run can measure is among them (a switch flipped).
    alts = [k for k in v["structural"] if not k["trace"]]
    assert any(f"{k['key']}={json.dumps(k['to'])}" in c["sets"] for k in alts for c in checks)
    measured = [c["measured"] for c in checks]
    assert measured == sorted(measured, reverse=True)
    assert "re-run:" in v["text"] and "measured" in v["text"]


def test_roofline_has_mshr_ceilings_by_littles_law(
    hairball: Path, sim: Sim, tmp_path: Path  # noqa: F811
) -> None:  # fmt: skip
    stats = run_stats(sim, hairball, tmp_path / "run", "l2.mshrs=4")
    roof = stats["roofline"]
    assert {"l1_mshrs", "l2_mshrs", "l2_banks"} <= set(roof["ceilings"])
    l2 = roof["mshr_little"]["l2"]
    # Little's law: MSHRs x line bytes / mean hold time is the level's miss bandwidth bound.
    assert l2["bytes_per_second"] == pytest.approx(4 * 64 / l2["mean_hold_cycles"] * 1e9)
    assert roof["ceilings"]["l2_mshrs"] == pytest.approx(
        l2["bytes_per_second"] / l2["miss_bytes_per_ray"]
    )
    # Four L2 MSHRs: the lowest roofs are the MSHRs' (the L1s' hold their misses while they
    # queue at the L2's, so both bind), the DRAM roof far above, and the run close under them.
    assert roof["bound"] in ("l1_mshrs", "l2_mshrs")
    assert roof["ceilings"]["dram"] > 2 * roof["ceilings"]["l2_mshrs"]
    assert roof["rays_per_second"] >= 0.5 * roof["ceilings"]["l2_mshrs"]


def test_simulate_takes_a_preset_name(hairball: Path, tmp_path: Path) -> None:  # noqa: F811
    out = tmp_path / "run"
    cmd = [
        "rtsim",
        "simulate",
        str(hairball),
        "--config",
        "base+tu4",
        "-o",
        str(out),
        "--no-progress",
    ]
    result = subprocess.run(cmd, capture_output=True, text=True, check=False, timeout=300)
    assert result.returncode == 0, result.stderr
    resolved = json.loads((out / "config.resolved.json").read_text())
    assert resolved["traversal"]["units"] == 4
    bad = subprocess.run(
        ["rtsim", "simulate", str(hairball), "--config", "rtx9999", "-o", str(tmp_path / "bad")],
        capture_output=True, text=True, check=False, timeout=60,
    )  # fmt: skip
    assert bad.returncode == 2 and "rtx9999" in bad.stderr and "rtx2060" in bad.stderr

"""rtsim.simulate(): one rtsim-sim run from Python, its Stats, config conventions and errors."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

import rtsim
from rtsim.config import SimConfig

# A stand-in rtsim-sim that writes mismatching stats wherever -o points, and exits 3.
FAKE_MISMATCH_SIM = """#!/bin/sh
while [ $# -gt 0 ]; do [ "$1" = "-o" ] && run="$2"; shift; done
mkdir -p "$run"
cat > "$run/stats.json" <<'JSON'
{"fidelity": "functional",
 "summary": {"rays": 2, "cycles": null, "hit_mismatches": 1, "work_mismatches": 0},
 "validation": {"rays_checked": 2, "hit_mismatches": 1, "work_mismatches": 0,
   "first_mismatches": [{"ray": 1, "difference": "hit: model prim 3, reference prim 4"}]}}
JSON
exit 3
"""


@pytest.fixture(scope="module")
def trace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("api") / "trace"
    rtsim.trace_scene("cornell", out, workload="primary,shadow", width=32, height=24)
    return out


def test_stats_is_stats_json_with_attributes(trace: Path, tmp_path: Path) -> None:
    stats = rtsim.simulate(trace, out=tmp_path / "run")
    on_disk = json.loads((tmp_path / "run" / "stats.json").read_text())
    assert dict(stats) == on_disk  # a mapping over the whole file
    assert stats["summary"]["rays"] == len(rtsim.open_trace(trace).rays) > 0
    # Attributes: every summary key, then every top-level group.
    assert stats.mrays_per_second == on_disk["summary"]["mrays_per_second"] > 0
    assert stats.dram_bytes_per_ray == on_disk["summary"]["dram_bytes_per_ray"]
    assert stats.validation == on_disk["validation"]
    assert stats.validation["rays_checked"] == stats.rays
    assert stats.ok and stats.returncode == 0
    assert stats.run_dir == tmp_path / "run"
    assert stats.config == json.loads((tmp_path / "run" / "config.resolved.json").read_text())
    assert "mrays_per_second" in dir(stats)
    with pytest.raises(AttributeError, match="mrays_per_second"):
        _ = stats.mrays_per_sec  # a typo lists the summary keys
    reloaded = rtsim.Stats.load(tmp_path / "run")
    assert reloaded == stats and reloaded.config == stats.config


def test_both_override_conventions_reach_the_model(trace: Path) -> None:
    by_keyword = rtsim.simulate(trace, l1__size_kib=32, traversal__units=2)
    by_dict = rtsim.simulate(trace, {"l1.size_kib": 32, "traversal": {"units": 2}})
    for stats in (by_keyword, by_dict):
        assert stats.config["l1"]["size_kib"] == 32
        assert sorted(stats.model["units"]) == ["tu0", "tu1"]
    # Keyword overrides apply over the config argument, top-level keys as they are.
    functional = rtsim.simulate(trace, "base+tu4", fidelity="functional")
    assert functional.config["traversal"]["units"] == 4
    assert functional.fidelity == "functional" and functional.cycles is None
    typed = rtsim.simulate(trace, SimConfig().with_values({"l2.size_kib": 512}))
    assert typed.config["l2"]["size_kib"] == 512


def test_config_conventions_compose() -> None:
    """Nested sections, dotted keys and keyword overrides, later ones winning (no run needed)."""
    from rtsim.simulation import resolve_config

    config = resolve_config({"l1.size_kib": 32, "l1": {"ways": 8, "size_kib": 8}}, {"l1__ways": 2})
    assert (config.l1.size_kib, config.l1.ways) == (32, 2)
    assert resolve_config("base+tu16", {"fidelity": "analytic"}).traversal.units == 16
    with pytest.raises(rtsim.RtsimError, match="expected a SimConfig"):
        resolve_config(42)  # type: ignore[arg-type]


def test_temporary_run_folder_is_removed(trace: Path) -> None:
    stats = rtsim.simulate(trace)
    assert stats.run_dir is None
    command = stats.provenance["command_line"]
    run = Path(command.split(" -o ")[1].split()[0])
    assert run.name.startswith("rtsim-run-") and not run.exists()


@pytest.mark.parametrize(
    ("config", "overrides", "named"),
    [
        (None, {"l1__sise_kib": 32}, "l1.sise_kib"),  # unknown key (Python side)
        (None, {"l1__size_kib": "big"}, "l1.size_kib"),  # wrong type (Python side)
        (None, {"l1__size_kib": 3}, "l1.size_kib"),  # out of range (rtsim-sim validate)
        ("base+tu7", {}, "tu7"),  # unknown modifier
    ],
)
def test_bad_config_raises_naming_the_key(
    trace: Path, config: str | None, overrides: dict[str, object], named: str
) -> None:
    with pytest.raises(rtsim.RtsimError, match=named.replace(".", r"\.")):
        rtsim.simulate(trace, config, **overrides)


def test_bad_files_raise_naming_the_file(trace: Path, tmp_path: Path) -> None:
    with pytest.raises(rtsim.RtsimError, match="nothing-here"):
        rtsim.simulate(tmp_path / "nothing-here")
    bad_json = tmp_path / "cfg.json"
    bad_json.write_text("{not json")
    with pytest.raises(rtsim.RtsimError, match=r"cfg\.json"):
        rtsim.simulate(trace, bad_json)
    bad_key = tmp_path / "key.json"
    bad_key.write_text('{"l1": {"size_kb": 32}}')
    with pytest.raises(rtsim.RtsimError, match=r"key\.json.*l1\.size_kb"):
        rtsim.simulate(trace, bad_key)


def test_timeout_kills_and_raises(trace: Path) -> None:
    with pytest.raises(rtsim.RtsimError, match="timed out"):
        rtsim.simulate(trace, timeout=0.001)


def test_mismatch_raises_with_stats_unless_unchecked(
    trace: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    fake = tmp_path / "fake-sim"
    fake.write_text(FAKE_MISMATCH_SIM)
    fake.chmod(0o755)
    monkeypatch.setenv("RTSIM_SIM", str(fake))
    with pytest.raises(rtsim.HitMismatchError, match="1 simulated hits") as err:
        rtsim.simulate(trace)
    assert err.value.stats.validation["first_mismatches"][0]["ray"] == 1
    assert isinstance(err.value, rtsim.RtsimError)
    stats = rtsim.simulate(trace, check=False)
    assert stats.returncode == 3 and not stats.ok


def test_timeline_needs_a_run_folder(trace: Path, tmp_path: Path) -> None:
    with pytest.raises(rtsim.RtsimError, match="out="):
        rtsim.simulate(trace, timeline=True)
    rtsim.simulate(trace, out=tmp_path / "run", timeline=True)
    assert (tmp_path / "run" / "timeline.json").is_file()


def test_trace_object_is_accepted(trace: Path) -> None:
    stats = rtsim.simulate(rtsim.open_trace(trace), fidelity="functional")
    assert stats.rays == rtsim.open_trace(trace).ray_count
    assert os.fspath(trace) in stats.provenance["command_line"]

"""Structural knobs in the verdict (docs/verdict.md, "Structural estimates"): `rtsim trace
--alternatives` traces the other structures beside a trace, the verdict estimates them with the
analytic level on the same sample of rays, marks the rest "measure" with the command, refuses an
alternative that holds other rays, and `--check-verdict` re-runs the best one on its own trace.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest

from conftest import rtsim_trace
from rtsim import _core
from test_model import Sim, hairball, sim, trace_of  # noqa: F401  (fixtures)

SMALL = ("--workload", "diffuse", "--resolution", "48x32", "--bounces", "1")


@pytest.fixture(scope="module")
def with_alternatives(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("alternatives") / "hairball"
    rtsim_trace("hairball", "-o", str(out), *SMALL, "--alternatives")
    return out


def structural(
    sim: Sim, trace: Path, out: Path, *sets: str, extra: tuple[str, ...] = ()  # noqa: F811
) -> dict[str, Any]:  # fmt: skip
    result = sim(trace, out, *sets, extra=extra)
    assert result.returncode == 0, result.stderr
    return json.loads((out / "stats.json").read_text())["verdict"]


def by_setting(verdict: dict[str, Any]) -> dict[str, dict[str, Any]]:
    def text(value: Any) -> str:
        return value if isinstance(value, str) else json.dumps(value)

    return {f"{k['key']}={text(k['to'])}": k for k in verdict["structural"]}


def test_alternatives_are_the_seams_own_list() -> None:
    folders = {value: folder for _, value, folder in _core.structure_alternatives("bvh2")}
    assert folders == {
        "bvh8": "alternatives/accel=bvh8",
        "cwbvh8": "alternatives/accel=cwbvh8",
        "true": "alternatives/compressed_leaves=true",
    }
    assert [v for _, v, _ in _core.structure_alternatives("bvh8", compressed_leaves=True)] == [
        "cwbvh8"
    ]
    assert _core.structure_alternatives("cwbvh8", compressed_leaves=True) == []


def test_trace_writes_each_alternative_with_the_same_rays(with_alternatives: Path) -> None:
    import numpy as np

    import rtsim

    rays = rtsim.open_trace(with_alternatives).rays
    for _, value, folder in _core.structure_alternatives("bvh2"):
        alt = with_alternatives / folder
        manifest = json.loads((alt / "manifest.json").read_text())
        assert value in json.dumps(manifest)
        assert np.array_equal(rtsim.open_trace(alt).rays, rays), folder


def test_structural_knobs_are_estimated_from_the_alternatives(
    with_alternatives: Path, sim: Sim, tmp_path: Path  # noqa: F811
) -> None:  # fmt: skip
    v = structural(sim, with_alternatives, tmp_path / "run")
    knobs = by_setting(v)
    for setting in ("accel=cwbvh8", "accel=bvh8", "compressed_leaves=true",
                    "traversal.model=simt", "treelets.enabled=true"):  # fmt: skip
        k = knobs[setting]
        assert k["speedup"] > 0 and k["estimated_by"].startswith("the analytic level"), setting
    # The compressed wide BVH cuts the hairball's node traffic: the estimate says it pays.
    assert knobs["accel=cwbvh8"]["speedup"] > 1.2
    assert "alternative trace" in knobs["accel=cwbvh8"]["estimated_by"]
    assert knobs["accel=cwbvh8"]["gain_per_mm2"] is not None
    # Its command simulates the alternative beside the trace with the run's config.
    measure = knobs["accel=cwbvh8"]["measure"]
    assert measure.startswith("rtsim simulate ")
    assert "alternatives/accel=cwbvh8/trace.rtt" in measure
    assert str(tmp_path / "run" / "config.given.json") in measure  # resolved afresh there
    given = json.loads((tmp_path / "run" / "config.given.json").read_text())
    assert "traversal" in given
    # Best first among the estimated; the unestimated say why once and give the command.
    gains = [k["speedup"] for k in v["structural"] if k.get("speedup")]
    assert gains == sorted(gains, reverse=True)
    for k in v["structural"]:
        if k.get("speedup") is None:
            why = k["why_not"]
            assert why.count("not estimated") == 1 and why.count("measure it") == 1, why
            assert k["measure"] in why
    assert "other designs, estimated:" in v["text"]


def test_without_alternatives_the_verdict_says_how_to_trace_them(
    hairball: Path, sim: Sim, tmp_path: Path  # noqa: F811
) -> None:  # fmt: skip
    knobs = by_setting(structural(sim, hairball, tmp_path / "run"))
    assert knobs["accel=cwbvh8"]["speedup"] is None
    assert "rtsim trace --alternatives" in knobs["accel=cwbvh8"]["why_not"]
    # Knobs the run's own trace can answer are estimated all the same.
    assert knobs["traversal.model=simt"]["speedup"] > 0


def test_an_alternative_with_other_rays_is_refused(sim: Sim, tmp_path: Path) -> None:  # noqa: F811
    # Primary rays, one per pixel: from another camera the alternative holds as many rays as the
    # run's, other ones. The rays themselves are compared, not their count.
    primary = ("--workload", "primary", "--resolution", "32x24")
    trace = tmp_path / "trace"
    rtsim_trace(
        "hairball", "-o", str(trace), *primary, "--camera", "0,0,3,0,0,0,45", "--alternatives"
    )
    other = trace / "alternatives" / "accel=cwbvh8"
    shutil.rmtree(other)
    rtsim_trace(
        "hairball", "-o", str(other), *primary, "--camera", "0,0,3.1,0,0,0,45", "--accel", "cwbvh8"
    )
    import rtsim

    assert len(rtsim.open_trace(other).rays) == len(rtsim.open_trace(trace).rays)
    knobs = by_setting(structural(sim, trace, tmp_path / "run"))
    assert knobs["accel=cwbvh8"]["speedup"] is None
    assert "holds other rays" in knobs["accel=cwbvh8"]["why_not"]
    assert knobs["accel=bvh8"]["speedup"] > 0  # the others still answer


def test_check_verdict_reruns_the_best_structure_on_its_trace(
    with_alternatives: Path, sim: Sim, tmp_path: Path  # noqa: F811
) -> None:  # fmt: skip
    out = tmp_path / "run"
    v = structural(sim, with_alternatives, out, extra=("--check-verdict",))
    on_traces = [c for c in v["check"] if "trace" in c]
    assert len(on_traces) == 1
    c = on_traces[0]
    assert c["sets"] == ["accel=cwbvh8"] and c["measured"] is not None and c["measured"] > 1.2
    assert Path(c["trace"]).name == "accel=cwbvh8"
    summary = json.loads((Path(c["run"]) / "stats.json").read_text())["summary"]
    assert summary["hit_mismatches"] == 0 and summary["work_mismatches"] == 0


def test_alternatives_keep_the_builder(tmp_path: Path) -> None:
    """One step away is the structure alone: an lbvh-built bvh2's alternatives are lbvh-built."""
    out = tmp_path / "lbvh"
    rtsim_trace("cornell", "-o", str(out), "--workload", "primary", "--resolution", "16x12",
                "--builder", "lbvh", "--alternatives")  # fmt: skip
    for _, _, folder in _core.structure_alternatives("bvh2"):
        accel = json.loads((out / folder / "manifest.json").read_text())["accel"]
        assert accel["builder"] == "lbvh", folder


def test_a_failed_alternative_is_left_out_and_old_ones_cleared(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:  # fmt: skip
    """The main trace stands when an alternative cannot be traced; alternatives an earlier trace
    left in the folder (of other rays) are removed first."""
    import io

    from rich.console import Console

    from rtsim import cli

    stale = tmp_path / "alternatives" / "accel=bvh4"
    stale.mkdir(parents=True)

    def refuse(job: cli.TraceJob, progress: Any = None) -> dict:
        raise ValueError("no room")

    monkeypatch.setattr(cli, "_trace_job", refuse)
    text = io.StringIO()
    manifest = {"accel": {"kind": "bvh2"}, "scene": {}}
    job = cli.TraceJob(scene="cornell", out_dir=tmp_path, alternatives=True)
    assert cli.trace_alternatives(job, manifest, Console(file=text, width=200)) == []
    assert not stale.exists()
    assert "alternative alternatives/accel=cwbvh8: not traced (no room)" in text.getvalue()

"""Every structure and builder through every way of making a trace: `rtsim.trace_scene`,
`rtsim.write_trace` (a loaded scene and your rays) and a sweep's trace task (the `rtsim trace`
command line a sweep runs). They share one set of defaults (the tracer's, declared in C++:
rtsim.tracing.trace_defaults), so the same choice gives the same structure, and trace_scene
and the command line write byte-identical traces."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

import rtsim
from rtsim import _core
from rtsim.sweep.tasks import TraceTask, make_trace
from rtsim.tracing import trace_defaults

#: (kind, builder) for every registered kind and each builder it accepts; "" is the default.
PAIRS = [(k["name"], b) for k in _core.accel_kinds() for b in ["", *k["builders"]]]
WIDTH, HEIGHT = 12, 9


def pair_id(pair: tuple[str, str]) -> str:
    return f"{pair[0]}-{pair[1] or 'default'}"


def default_builder(kind: str) -> str:
    return next(k["builders"][0] for k in _core.accel_kinds() if k["name"] == kind)


def test_the_defaults_are_the_tracers() -> None:
    d = trace_defaults()
    assert d["width"] > 0 and d["height"] > 0 and d["bounces"] >= 0
    assert d["accel"] in {k["name"] for k in _core.accel_kinds()}
    assert d["builder"] == "" and d["workload"] is None and d["camera"] is None
    with pytest.raises(TypeError, match="unknown option 'widht'"):
        _core.trace_scene("cornell", "/nonexistent", widht=3)


@pytest.fixture(scope="module")
def via_trace_scene(tmp_path_factory: pytest.TempPathFactory) -> Callable[[str, str], Path]:
    root = tmp_path_factory.mktemp("via_api")

    def make(kind: str, builder: str) -> Path:
        out = root / f"{kind}-{builder or 'default'}"
        if not out.exists():
            rtsim.trace_scene(
                "cornell", out, workload="primary", width=WIDTH, height=HEIGHT, accel=kind,
                builder=builder or None,
            )  # fmt: skip
        return out

    return make


@pytest.mark.parametrize("pair", PAIRS, ids=pair_id)
def test_trace_scene_and_the_command_line_agree(
    via_trace_scene: Callable[[str, str], Path], tmp_path: Path, pair: tuple[str, str]
) -> None:
    kind, builder = pair
    api = via_trace_scene(kind, builder)
    accel = rtsim.open_trace(api).manifest["accel"]
    assert accel["kind"] == kind and accel["builder"] == (builder or default_builder(kind))
    task = TraceTask(
        trace_dir=str(tmp_path / "sweep"), scene="cornell", rays=["primary"], width=WIDTH,
        height=HEIGHT, bounces=trace_defaults()["bounces"], seed=trace_defaults()["seed"],
        hairball_triangles=trace_defaults()["hairball_triangles"], accel=kind, builder=builder,
    )  # fmt: skip
    outcome = make_trace(task, timeout=120)
    assert outcome["ok"], outcome
    sweep = Path(outcome["trace_dir"])
    assert (sweep / "trace.rtt").read_bytes() == (api / "trace.rtt").read_bytes()


@pytest.mark.parametrize("pair", PAIRS, ids=pair_id)
def test_write_trace_builds_the_same_structure(
    via_trace_scene: Callable[[str, str], Path], tmp_path: Path, pair: tuple[str, str]
) -> None:
    kind, builder = pair
    reference = rtsim.open_trace(via_trace_scene(kind, builder))
    scene = rtsim.load_scene("cornell")
    rays = reference.rays
    manifest = rtsim.write_trace(
        scene, rays["origin"], rays["direction"], rays["tmin"], rays["tmax"],
        out=tmp_path / "mine", accel=kind, builder=builder or None,
    )  # fmt: skip
    assert manifest["accel"]["kind"] == kind
    mine = rtsim.open_trace(tmp_path / "mine")
    assert np.array_equal(mine.hits["prim"], reference.hits["prim"])
    assert np.array_equal(mine.work, reference.work)

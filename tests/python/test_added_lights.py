"""--lights sun: a scene without lights gets a sun and shadow rays, recorded in the manifest,
deterministically; a scene with lights of its own gets nothing."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from rtsim.errors import ArgumentValueError
from rtsim.tracing import trace_scene

SPONZA = Path(os.environ.get("RTSIM_SCENES", "/nonexistent")) / "sponza" / "Sponza.gltf"
needs_sponza = pytest.mark.skipif(
    not SPONZA.is_file(), reason="shared Sponza not found ($RTSIM_SCENES)"
)


@needs_sponza
def test_sun_adds_shadow_rays_deterministically(tmp_path: Path) -> None:
    runs = []
    for name in ("a", "b"):
        m = trace_scene(SPONZA, tmp_path / name, width=16, height=12, lights="sun")
        runs.append(m)
        added = m["workload"]["lights_added"]
        assert added["requested"] == "sun" and len(added["added"]) == 1
        shadow = next(e for e in m["workload"]["effects"] if e["name"] == "shadow")
        assert shadow["simulated"] and "--lights sun" in shadow["why"]
        assert m["counts"]["by_kind"]["shadow"]["traced"] > 0
    trace = [(tmp_path / n / "trace.rtt").read_bytes() for n in ("a", "b")]
    assert trace[0] == trace[1]


def test_own_lights_kept_and_bad_choice_is_refused(tmp_path: Path) -> None:
    m = trace_scene("teapot_stadium", tmp_path / "own", width=16, height=12, lights="sun")
    assert m["workload"]["lights_added"]["added"] == []
    assert "own" in m["workload"]["lights_added"]["why"]
    with pytest.raises(ArgumentValueError, match="lights"):
        trace_scene("teapot_stadium", tmp_path / "bad", width=16, height=12, lights="moon")

"""Compressed leaves (docs/accel.md, "Compressed leaves") through the whole chain: `rtsim trace
--build-set compressed_leaves=true` gives an image whose triangles the model fetches as
compressed blocks, with the plain trace's hits and work (0 mismatches at every timed level) and,
for structures whose leaves are runs of triangles, a smaller image and fewer triangle bytes
moved; the setting is a sweep axis and bad values are refused by name."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

import rtsim
from conftest import rtsim_trace, run_rtsim, sim_stats
from rtsim.sweep.spec import SpecError, parse_spec

SCENE, RESOLUTION, WORKLOAD = "cornell", "32x24", "primary,shadow,diffuse"
KINDS = ["bvh2", "cwbvh8", "grid"]
#: Structures whose leaves are runs of triangles: their blocks share vertices. The grid fetches
#: single triangles from one-line blocks, mostly one triangle each (docs/accel.md).
SHARING = {"bvh2", "cwbvh8"}


@pytest.fixture(scope="module")
def trace_of(tmp_path_factory: pytest.TempPathFactory) -> Callable[[str, bool], Path]:
    root = tmp_path_factory.mktemp("leaves_traces")
    made: dict[tuple[str, bool], Path] = {}

    def trace(kind: str, compressed: bool) -> Path:
        if (kind, compressed) not in made:
            out = root / f"{kind}-{int(compressed)}"
            extra = ["--build-set", "compressed_leaves=true"] if compressed else []
            rtsim_trace(
                SCENE, "-o", str(out), "--accel", kind, "--workload", WORKLOAD,
                "--resolution", RESOLUTION, "--bounces", "1", *extra,
            )  # fmt: skip
            made[kind, compressed] = out
        return made[kind, compressed]

    return trace


def l1_triangle_read_bytes(stats: dict) -> int:
    """Triangle bytes the units requested from their L1s (what the plans fetched)."""
    l1s = stats["model"]["l1"].values()
    return sum(c["by_kind"]["triangle"]["read_bytes"] for c in l1s if "triangle" in c["by_kind"])


@pytest.mark.parametrize("kind", KINDS)
def test_compressed_leaves_trace_the_same_and_move_fewer_bytes(
    trace_of: Callable[[str, bool], Path], sim_exe: Path, tmp_path: Path, kind: str
) -> None:
    plain, packed = trace_of(kind, False), trace_of(kind, True)
    mp = json.loads((plain / "manifest.json").read_text())["accel"]
    mq = json.loads((packed / "manifest.json").read_text())["accel"]
    assert mq["build_settings"]["compressed_leaves"] is True
    if kind in SHARING:
        assert mq["footprint_bytes"] < mp["footprint_bytes"]
        assert mq["leaf_blocks"]["bytes"] < mq["leaf_blocks"]["plain_bytes"]
    assert "leaf_blocks" not in mp
    tp, tq = rtsim.open_trace(plain), rtsim.open_trace(packed)
    np.testing.assert_array_equal(tp.hits, tq.hits)  # the reference hits, bit for bit
    for name in tp.work.dtype.names:
        np.testing.assert_array_equal(tp.work[name], tq.work[name])
    for fidelity in ("approx", "detailed"):
        sp = sim_stats(sim_exe, plain, tmp_path / f"p-{fidelity}", f"fidelity={fidelity}")
        sq = sim_stats(sim_exe, packed, tmp_path / f"q-{fidelity}", f"fidelity={fidelity}")
        for s in (sp, sq):
            assert s["summary"]["hit_mismatches"] == 0 and s["summary"]["work_mismatches"] == 0
        # The L1 sees every triangle request: the compressed blocks are fewer bytes.
        if kind in SHARING:
            assert l1_triangle_read_bytes(sq) < l1_triangle_read_bytes(sp), fidelity


def test_compressed_leaves_are_a_sweep_axis() -> None:
    spec = parse_spec(
        "scenes: [cornell]\nworkloads: [{name: primary, rays: [primary], resolution: 16x12}]\n"
        "accel: [{kind: cwbvh8, build: {compressed_leaves: [false, true]}}]\n",
        source="s.yaml",
    )
    assert [a.label for a in spec.accels] == [
        "cwbvh8 compressed_leaves=False",
        "cwbvh8 compressed_leaves=True",
    ]
    assert len({t.trace_id for t in spec.traces()}) == 2  # one trace each


@pytest.mark.parametrize(
    ("setting", "message"),
    [
        ("leaf_block_bytes=8", "'leaf_block_bytes' = 8 is out of range [64, 1020]"),
        ("compressed_leaves=maybe", "compressed_leaves"),
    ],
)
def test_bad_leaf_settings_are_named(tmp_path: Path, setting: str, message: str) -> None:
    result = run_rtsim(
        "trace", SCENE, "-o", str(tmp_path / "t"), "--resolution", "8x6", "--build-set", setting
    )
    assert result.returncode == 2 and message in result.stderr, result.stderr
    with pytest.raises(SpecError):
        parse_spec(
            "scenes: [cornell]\nworkloads: [{name: p, rays: [primary], resolution: 8x6}]\n"
            f"accel: [{{kind: bvh2, build: {{{setting.replace('=', ': ')}}}}}]\n",
            source="s.yaml",
        )

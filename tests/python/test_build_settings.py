"""Builder settings as data (docs/accel.md, "Builder settings"): the docs' tables are generated
from the builders' Configs and current; the sweep's accel axis expands lists of settings into
structures, keys the trace cache on them and refuses bad ones by name."""

from __future__ import annotations

import importlib.util
import sys
import textwrap
from types import ModuleType

import pytest

from conftest import REPO
from rtsim.sweep.runner import trace_task
from rtsim.sweep.spec import SpecError, parse_spec

BASE = """\
scenes: [cornell]
workloads: [{name: primary, rays: [primary], resolution: 16x12}]
grid:
  traversal.units: [2, 4]
"""


def load_generator() -> ModuleType:
    path = REPO / "scripts" / "gen_build_settings_doc.py"
    spec = importlib.util.spec_from_file_location("gen_build_settings_doc", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_build_settings_doc_is_up_to_date() -> None:
    gen = load_generator()
    from rtsim.doc_markers import replace_between

    current = (REPO / "docs" / "accel.md").read_text()
    expected = replace_between(current, gen.MARKERS, gen.render(gen.load_kinds()))
    assert current == expected, (
        "docs/accel.md's builder settings are out of date: "
        f"run `{sys.executable} scripts/gen_build_settings_doc.py`"
    )
    text = gen.render(gen.load_kinds())
    for name in ("empty_bonus", "morton_bits", "alpha", "density", "max_depth", "bins"):
        assert f"| `{name}` |" in text


def test_accel_axis_sweeps_builder_settings() -> None:
    s = parse_spec(
        BASE + "accel: [bvh2, {kind: kdtree, build: {empty_bonus: [0, 0.5], max_depth: 20}},"
        " {kind: bvh2, builder: lbvh, label: fast, build: {max_leaf_size: 2}}]\n",
        source="s.yaml",
    )
    assert [a.label for a in s.accels] == [
        "bvh2",
        "kdtree empty_bonus=0",
        "kdtree empty_bonus=0.5",
        "fast",
    ]
    traces = s.traces()
    assert len({t.trace_id for t in traces}) == 4
    kd = [t for t in traces if t.accel.kind == "kdtree"][1]
    assert kd.accel.key(1)["build"] == {"empty_bonus": 0.5, "max_depth": 20}
    command = trace_task(kd, REPO / "out").command("x")
    assert command[command.index("--build-set") + 1] in ("empty_bonus=0.5", "max_depth=20")
    assert command.count("--build-set") == 2
    # No settings: the trace cache key of earlier sweeps is unchanged.
    assert "build" not in s.accels[0].key(1)


@pytest.mark.parametrize(
    ("entry", "message"),
    [
        (
            "{kind: kdtree, build: {bins: 8}}",
            "setting 'bins': unknown setting; the builder takes: clip, compressed_leaves, "
            "empty_bonus",
        ),
        (
            "{kind: bvh2, build: {max_leaf_size: [1, 0]}}",
            "'max_leaf_size': 0 is out of range [1, 64]",
        ),
        ("{kind: octree, build: {clip: 1}}", "expected true or false"),
        ("{kind: grid, build: 3}", "expected a mapping of setting"),
    ],
)
def test_accel_axis_refuses_bad_settings_by_name(entry: str, message: str) -> None:
    with pytest.raises(SpecError) as info:
        parse_spec(BASE + textwrap.dedent(f"accel: [{entry}]\n"), source="s.yaml")
    assert message in str(info.value) and "accel[0].build" in str(info.value)

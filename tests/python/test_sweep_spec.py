"""Sweep specs: errors name the file, line and key; grids, sampling and run ids."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

from rtsim.sweep.runner import trace_task
from rtsim.sweep.spec import SpecError, parse_spec

GOOD = """\
name: t
scenes:
  - cornell
  - {name: hairball, hairball_triangles: 1000}
workloads:
  - {name: primary, rays: [primary], resolution: 32x24}
  - name: diffuse
    rays: primary,diffuse
    resolution: 32x24
config:
  preset: base+l2-4m
  set: {dram.latency: 150}
grid:
  traversal.units: [4, 8]
  l1.size_kib: [16, 64]
"""


def spec_error(text: str) -> str:
    with pytest.raises(SpecError) as info:
        parse_spec(textwrap.dedent(text), source="s.yaml")
    return str(info.value)


def test_good_spec_expands() -> None:
    spec = parse_spec(GOOD, "s.yaml")
    assert [s.label for s in spec.scenes] == ["cornell", "hairball"]
    assert spec.workloads[1].rays == ("primary", "diffuse")
    runs = spec.runs()
    assert len(runs) == 2 * 2 * 4
    assert len({r.run_id for r in runs}) == len(runs)
    r = runs[0]
    assert (r.config.l2.size_kib, r.config.dram.latency) == (4096, 150)
    assert {(r.config.traversal.units, r.config.l1.size_kib) for r in runs} == {
        (4, 16), (4, 64), (8, 16), (8, 64)}  # fmt: skip
    # the run id depends on the resolved config and the trace, not on labels or order
    again = parse_spec(GOOD.replace("name: t", "name: other"), "s.yaml").runs()
    assert [x.run_id for x in again] == [x.run_id for x in runs]


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        (
            "scenes: [cornell]\nworkloads: [{rays: [primary]}]\ngrdi: {}\n",
            "s.yaml:3: grdi: unknown key",
        ),
        (
            "scenes: [cornell]\nworkloads: [{rays: [primary]}]\ngrid:\n  traversal.units: [4]\n"
            "  l1.size_kb: [16]\n",
            "s.yaml:5: grid.l1.size_kb: unknown key 'l1.size_kb'",
        ),
        (
            "scenes: [cornell]\nworkloads: [{rays: [primary]}]\ngrid:\n  l1.size_kib:\n    - 16\n"
            "    - big\n",
            "s.yaml:6: grid.l1.size_kib: 'l1.size_kib' must be a non-negative integer",
        ),
        (
            "scenes: [cornell]\nworkloads:\n  - rays: [primary]\n  - rays: [laser]\n",
            "s.yaml:4: workloads[1].rays: unknown ray kind",
        ),
        (
            "scenes: [cornell]\nworkloads:\n  - {rays: [primary], resolution: 32by24}\n",
            "s.yaml:3: workloads[0].resolution: expected WxH",
        ),
        ("scenes: []\nworkloads: [{rays: [primary]}]\n", "s.yaml:1: scenes: missing or empty"),
        (
            "scenes: [cornell]\nworkloads: [{rays: [primary]}]\nconfig:\n  preset: base+tu99\n",
            "s.yaml:4: config.preset: config: unknown preset or modifier 'tu99'",
        ),
        (
            "scenes: [cornell]\nworkloads: [{rays: [primary]}]\nsampling:\n  method: sobol\n"
            "  n: 4\n"
            "  ranges: {clock_ghz: [0.5, 2]}\n",
            "s.yaml:4: sampling.method: 'sobol' is not one of",
        ),
        (
            "scenes: [cornell]\nworkloads: [{rays: [primary]}]\nsampling:\n  n: 4\n  ranges:\n"
            "    traversal.units: [1.5, 8]\n",
            "s.yaml:6: sampling.ranges.traversal.units: 'traversal.units' must be a non-negative",
        ),
        (
            "scenes: [cornell]\nworkloads: [{rays: [primary]}]\ngrid:\n  traversal.units: 4\n",
            "s.yaml:4: grid.traversal.units: expected a non-empty list",
        ),
        ("scenes: [cornell]\nworkloads: [{rays: [primary]\n", "s.yaml:3: not valid YAML"),
        (
            "scenes: [cornell, cornell]\nworkloads: [{rays: [primary]}]\n",
            "s.yaml:1: scenes: two entries named 'cornell'",
        ),
    ],
)
def test_errors_name_line_and_key(text: str, expected: str) -> None:
    assert expected in spec_error(text)


def test_sampling_latin_hypercube() -> None:
    text = """\
    scenes: [cornell]
    workloads: [{rays: [primary]}]
    grid: {l1.size_kib: [16, 64]}
    sampling:
      method: latin_hypercube
      n: 8
      seed: 3
      ranges:
        clock_ghz: [0.5, 2.5]
        traversal.units: [1, 8]
        box.sharing: {values: [private, shared]}
    """
    spec = parse_spec(textwrap.dedent(text), "s.yaml")
    points = spec.points()
    assert len(points) == 2 * 8
    samples = points[:8]
    # one sample per stratum in every dimension
    assert sorted(int((p["clock_ghz"] - 0.5) / 2.0 * 8) for p in samples) == list(range(8))
    assert sorted(p["traversal.units"] for p in samples) == list(range(1, 9))
    assert {p["box.sharing"] for p in samples} == {"private", "shared"}
    assert parse_spec(textwrap.dedent(text), "s.yaml").points() == points  # seeded
    assert spec.swept_keys == ["l1.size_kib", "clock_ghz", "traversal.units", "box.sharing"]


def test_preset_grid_key() -> None:
    text = "scenes: [cornell]\nworkloads: [{rays: [primary]}]\ngrid:\n  preset: [base, base+tu16]\n"
    runs = parse_spec(text, "s.yaml").runs()
    assert [r.config.traversal.units for r in runs] == [8, 16]
    assert [r.preset for r in runs] == ["base", "base+tu16"]


def test_switched_off_sections_are_simulated_once() -> None:
    # Ray-buffer sizes with treelets off are one machine: one run, not one per size.
    text = """\
    name: t
    scenes: [cornell]
    workloads:
      - {name: primary, rays: [primary], resolution: 32x24}
    grid:
      treelets.enabled: [false, true]
      treelets.buffer_kib: [128, 512, 2048]
    """
    runs = parse_spec(textwrap.dedent(text), "s.yaml").runs()
    off = [r for r in runs if not r.config.treelets.enabled]
    on = [r for r in runs if r.config.treelets.enabled]
    assert len(off) == 1 and len(on) == 3
    assert len({r.run_id for r in runs}) == 4
    # A treelets-off run with default treelet fields keeps the id it always had.
    from rtsim.sweep.spec import stable_hash

    plain = parse_spec(textwrap.dedent(text).replace("[128, 512, 2048]", "[512]"), "s.yaml")
    [base] = [r for r in plain.runs() if not r.config.treelets.enabled]
    expected = {"trace": base.trace.trace_id, "config": base.config.to_dict()}
    assert base.run_id == stable_hash(expected)


def test_treelet_prefetching_counts_without_treelet_queues() -> None:
    # Prefetching also runs without treelet queues, so it is not folded into the treelets-off
    # run, while a prefetch setting beside it still is not a second machine when both are off.
    text = """\
    name: t
    scenes: [cornell]
    workloads:
      - {name: primary, rays: [primary], resolution: 32x24}
    grid:
      treelets.prefetch: [false, true]
      treelets.buffer_kib: [128, 2048]
    """
    runs = parse_spec(textwrap.dedent(text), "s.yaml").runs()
    assert len({r.run_id for r in runs}) == 2
    assert {r.config.treelets.prefetch for r in runs} == {False, True}


def test_scene_lights_are_a_trace_of_their_own() -> None:
    text = "scenes:\n  - cornell\n  - {name: cornell, label: sun, lights: sun}\n"
    spec = parse_spec(text + "workloads: [{rays: [primary, shadow]}]\n", "s.yaml")
    plain, sun = spec.traces()
    assert (plain.scene.lights, sun.scene.lights) == ("", "sun")
    assert "lights" not in plain.scene.key() and plain.trace_id != sun.trace_id
    command = trace_task(sun, Path("out")).command("t")
    assert command[command.index("--lights") + 1] == "sun"
    assert "--lights" not in trace_task(plain, Path("out")).command("t")
    bad = "scenes: [{name: cornell, lights: moon}]\nworkloads: [{rays: [primary]}]\n"
    assert "s.yaml:1: scenes[0].lights: expected one of none, sun" in spec_error(bad)


def test_frame_policy_is_a_trace_of_its_own() -> None:
    text = (
        "scenes: [cloth]\nworkloads:\n  - {name: rebuild, frames: 3}\n"
        "  - {name: adaptive, frames: 3, frame_policy: adaptive, rebuild_threshold: 1.5}\n"
    )
    plain, adaptive = parse_spec(text, "s.yaml").traces()
    assert "frame_policy" not in plain.workload.key() and plain.trace_id != adaptive.trace_id
    command = trace_task(adaptive, Path("out")).command("t")
    assert command[command.index("--frame-policy") + 1] == "adaptive"
    assert command[command.index("--rebuild-threshold") + 1] == "1.5"
    assert "--frame-policy" not in trace_task(plain, Path("out")).command("t")
    bad = "scenes: [cloth]\nworkloads: [{frames: 2, frame_policy: sometimes}]\n"
    assert "workloads[0].frame_policy: expected one of rebuild, refit, adaptive" in spec_error(bad)
    low = "scenes: [cloth]\nworkloads: [{frames: 2, rebuild_threshold: 0.5}]\n"
    assert "workloads[0].rebuild_threshold" in spec_error(low)


def test_alternatives_are_a_trace_of_their_own() -> None:
    text = "scenes: [cornell]\nworkloads:\n  - {name: a, rays: [diffuse]}\n"
    text += "  - {name: b, rays: [diffuse], alternatives: true}\n"
    plain, weighed = parse_spec(text, "s.yaml").traces()
    assert "alternatives" not in plain.workload.key() and plain.trace_id != weighed.trace_id
    assert "--alternatives" in trace_task(weighed, Path("out")).command("t")
    assert "--alternatives" not in trace_task(plain, Path("out")).command("t")
    bad = "scenes: [cornell]\nworkloads: [{rays: [diffuse], alternatives: 2}]\n"
    assert "s.yaml:2: workloads[0].alternatives: expected true or false" in spec_error(bad)
    moving = "scenes: [cloth]\nworkloads: [{frames: 3, alternatives: true}]\n"
    assert "an animated trace has no structural alternatives" in spec_error(moving)


def test_check_runs_false_leaves_refusals_to_the_runs() -> None:
    # A study counting refusals (rtsim study composition) needs the refused runs as failed runs.
    text = "scenes: [cornell]\nworkloads: [{rays: [primary], resolution: 8x8}]\naccel: [grid]\n"
    text += "grid:\n  traversal.stack_overflow: [spill, restart_trail]\n"
    with pytest.raises(SpecError, match="would be refused by the simulator"):
        parse_spec(text, source="s.yaml")
    spec = parse_spec(text + "check_runs: false\n", source="s.yaml")
    overflow = [p.params["traversal.stack_overflow"] for p in spec.plans()]
    assert overflow == ["spill", "restart_trail"]
    with pytest.raises(SpecError, match=r"s\.yaml:6: check_runs: expected true or false"):
        parse_spec(text + "check_runs: 1\n", source="s.yaml")


@pytest.mark.parametrize(
    "path",
    sorted((Path(__file__).parents[2] / "python" / "rtsim" / "specs").glob("*.yaml")),
    ids=lambda p: p.stem,
)
def test_the_shipped_specs_parse(path: Path) -> None:
    """The specs the docs run (accuracy grids, studies, the demo) stay valid as the config grows."""
    spec = parse_spec(path.read_text(), source=str(path))
    assert spec.runs()

"""The verdict study (docs/verdict.md): is the knob the verdict names the one that pays?

A two-stage study. First, each design (a config over a small trace: Sponza's diffuse rays, and
the same scene under another structure) runs once with its verdict; then, chosen from each
verdict (`follow_up`), one run per knob relaxed one step: the verdict's top five candidates, a
fixed core set (units, ray contexts, pipelines, L1/L2 size, MSHRs, DRAM channels, the treelet
knobs where treelets are on) and its first co-limit (both knobs at once). The table gives the
verdict's knob, its estimated and measured gain, and the best single knob's measured gain
(between the `verdict-study` markers).

The `unseen` designs are the check on designs the verdict was not tuned on: the hairball (a scene
no tuned design uses), under three structures, SIMT, treelets and DRAM-bound points, with every
structural alternative measured too (another structure and compressed leaves on their own
traces, treelets flipped, the other execution model, sorting, prefetching); their traces are
made with the alternatives beside them, so the verdict estimates the structural knobs as well;
between the `verdict-unseen` markers, and each structural estimate against its measurement between
the `structural-estimates` markers. Table code: rtsim/studies/_verdict_table.py."""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from rtsim.studies._verdict_table import Outcome, knob_str, note, structural_table, table
from rtsim.study import Study, StudyRun, Table
from rtsim.study.core import StudyError
from rtsim.sweep.spec import SpecError, spec_from_dict

#: Knobs measured in every design besides the verdict's top candidates (prefixes of keys).
CORE = [
    "traversal.units",
    "traversal.ray_contexts",
    "box.",
    "triangle.",
    "l1.size_kib",
    "l2.size_kib",
    "l1.mshrs",
    "l2.mshrs",
    "dram.channels",
    "treelets.admit_outstanding",
    "treelets.buffer_kib",
]


@dataclass(frozen=True)
class Design:
    name: str
    trace: str  # "SCENE-KIND" or "SCENE-KIND-cl" (compressed leaves): a key of traces()
    sets: dict[str, Any] = field(default_factory=dict)
    preset: str | None = None  # a preset the design's config is composed from


def _d(name: str, trace: str, preset: str | None = None, **sets: Any) -> Design:
    return Design(name, trace, {k.replace("__", "."): v for k, v in sets.items()}, preset)


DESIGNS = [
    _d("default", "sponza-bvh2"),
    _d("16 units", "sponza-bvh2", traversal__units=16),
    _d("32 units", "sponza-bvh2", traversal__units=32),
    _d("8 L2 MSHRs", "sponza-bvh2", l2__mshrs=8),
    _d("4 L1 MSHRs", "sponza-bvh2", l1__mshrs=4),
    _d("1 DRAM channel", "sponza-bvh2", dram__channels=1),
    _d("256 KiB L2", "sponza-bvh2", l2__size_kib=256),
    _d("box pipeline II=4", "sponza-bvh2", box__initiation_interval=4),
    _d("4 ray contexts", "sponza-bvh2", traversal__ray_contexts=4),
    _d("32 units, 1 channel", "sponza-bvh2", traversal__units=32, dram__channels=1),
    _d("treelets", "sponza-bvh2", treelets__enabled=True),
    _d(
        "treelets, 2 admission reads",
        "sponza-bvh2",
        treelets__enabled=True,
        treelets__admit_outstanding=2,
    ),
    _d("rtx2060 preset", "sponza-bvh2", "rtx2060"),
    _d("other structure", "sponza-ALT"),
]

#: Designs the verdict was not tuned on (chosen before any of them was run, by the categories the
#: verdict had failed on: structures, execution models, treelets, DRAM-bound points), on the
#: hairball's diffuse rays: no design of DESIGNS uses the hairball.
UNSEEN = [
    _d("hairball, bvh2", "hairball-bvh2"),
    _d("hairball, cwbvh8", "hairball-cwbvh8"),
    _d("hairball, cwbvh8 + compressed leaves", "hairball-cwbvh8-cl"),
    _d("hairball, 16 units", "hairball-bvh2", traversal__units=16),
    _d("hairball, 1 DRAM channel", "hairball-bvh2", dram__channels=1),
    _d("hairball, 256 KiB L2", "hairball-bvh2", l2__size_kib=256),
    _d("hairball, treelets 512 KiB", "hairball-bvh2", treelets__enabled=True),
    _d("hairball, cwbvh8 + treelets", "hairball-cwbvh8", treelets__enabled=True),
    _d("hairball, SIMT", "hairball-bvh2", traversal__model="simt"),
    _d("hairball, SIMT, 16 units", "hairball-bvh2", traversal__model="simt", traversal__units=16),
    _d("hairball, 4 L1 + 8 L2 MSHRs", "hairball-bvh2", l1__mshrs=4, l2__mshrs=8),
    _d(
        "hairball, 32 units, 1 channel",
        "hairball-bvh2",
        traversal__units=32,
        dram__channels=1,
    ),
    _d("hairball, cwbvh8, 16 units", "hairball-cwbvh8", traversal__units=16),
]
SETS = {"tuned": DESIGNS, "unseen": UNSEEN}
#: The unseen designs' other traces: every structure a structural knob may name.
UNSEEN_TRACES = ["bvh2", "bvh8", "cwbvh8", "bvh2-cl", "cwbvh8-cl"]


def designs(o: dict[str, Any]) -> list[tuple[str, Design]]:
    """(set, design) of both sets; `sponza-ALT` is the alt_accel structure."""
    return [
        (kind, Design(d.name, d.trace.replace("ALT", o["alt_accel"]), d.sets, d.preset))
        for kind, ds in SETS.items()
        for d in ds
    ]


def slug(text: str) -> str:
    return "".join(c if c.isalnum() else "-" for c in text).strip("-")


def spec(
    o: dict[str, Any], kind: str, d: Design, trace: str, points: list[dict[str, Any]], name: str
) -> dict[str, Any]:
    """A spec of `points` on `trace` ("SCENE-KIND[-cl]") at the set's resolution."""
    scene, accel, *leaves = trace.split("-")
    entry: Any = {"kind": accel, "build": {"compressed_leaves": True}} if leaves else accel
    res = o["resolution"] if kind == "tuned" else o["unseen_resolution"]
    workload: dict[str, Any] = {"name": "diffuse", "rays": ["diffuse"], "resolution": res}
    if kind == "unseen":  # the other structures beside each trace: the verdict estimates them
        workload["alternatives"] = True
    sc: dict[str, Any] = {"name": scene}
    if scene == "hairball":
        sc["hairball_triangles"] = o["hairball_triangles"]
    if d.preset:
        points = [{**p, "preset": d.preset} for p in points]
    return {
        "name": name,
        "scenes": [sc],
        "workloads": [workload],
        "accel": [entry],
        "points": points,
    }


def part(kind: str, d: Design) -> str:
    return f"verdict-{kind}-{slug(d.name)}"


def specs(o: dict[str, Any]) -> list[dict[str, Any]]:
    """The first stage: each design once, with its verdict."""
    return [
        spec(o, kind, d, d.trace, [{"label": "base", "set": dict(d.sets)}], part(kind, d))
        for kind, d in designs(o)
    ]


def knobs_to_measure(verdict: dict[str, Any], structural: bool = False) -> list[str]:
    """The verdict's top five candidates and the core knobs, as `key=to`, its first co-limit
    (both knobs, joined by a space) and, with `structural`, every structural alternative."""
    cands = verdict.get("candidates") or []
    chosen = list(cands[:5])
    chosen += [c for c in cands if any(c["key"].startswith(k) for k in CORE) and c not in chosen]
    out = [knob_str(c) for c in chosen]
    out += [" ".join(co["sets"]) for co in (verdict.get("co_limits") or [])[:1]]
    relax = verdict.get("relax") or {}
    if relax.get("structural") and knob_str(relax) not in out:  # a named structural knob
        out.append(knob_str(relax))
    if structural:
        out += [
            knob_str(k)
            for k in verdict.get("structural") or []
            if not k.get("refused") and knob_str(k) not in out
        ]
    return out


def _value(text: str) -> Any:
    """A `--set` value as the spec's typed value (numbers and true/false; else the text)."""
    try:
        return json.loads(text)
    except ValueError:
        return text


def knob_specs(o: dict[str, Any], kind: str, d: Design, knobs: list[str]) -> list[dict[str, Any]]:
    """The design's knob runs: a spec of the knobs on its own trace, and one per other trace a
    structural knob names (another structure, compressed leaves), if the set has that trace."""
    same, other = [], []
    for knob in knobs:
        key, _, to = knob.partition("=")
        if key in ("accel", "compressed_leaves"):
            scene, accel, *leaves = d.trace.split("-")
            cl = "-cl" if leaves or key == "compressed_leaves" else ""
            trace = f"{scene}-{to if key == 'accel' else accel}{cl}"
            if kind == "unseen" and trace.split("-", 1)[1] in UNSEEN_TRACES:
                points = [{"label": knob, "set": dict(d.sets)}]
                other.append(spec(o, kind, d, trace, points, f"{part(kind, d)}/{slug(knob)}"))
            continue
        sets = dict(d.sets)
        for assignment in knob.split(" "):
            k, _, v = assignment.partition("=")
            sets[k] = _value(v)
        same.append({"label": knob, "set": sets})
    out = [spec(o, kind, d, d.trace, same, f"{part(kind, d)}/knobs")] if same else []
    return out + other


def _runnable(spec_dict: dict[str, Any]) -> list[dict[str, Any]]:
    """The spec if the sweep's check takes it, else its points one by one, leaving out those the
    simulator refuses (a refused knob is not measured, like a knob whose run failed: nan)."""
    try:
        spec_from_dict(spec_dict, "study verdict")
        return [spec_dict]
    except SpecError:
        pass
    out = []
    for i, p in enumerate(spec_dict["points"]):
        one = {**spec_dict, "name": f"{spec_dict['name']}/{i}", "points": [p]}
        try:
            spec_from_dict(one, "study verdict")
        except SpecError:
            continue
        out.append(one)
    return out


def follow_up(run: StudyRun) -> list[dict[str, Any]]:
    """The second stage: the knobs each design's verdict names."""
    o, out = run.options, []
    for kind, d in designs(o):
        base = run.row(part=part(kind, d), point="base")
        if base["status"] != "ok":
            raise StudyError(f"study verdict: design '{d.name}' did not run: {base['error']}")
        verdict = run.stats(base)["verdict"]
        for s in knob_specs(o, kind, d, knobs_to_measure(verdict, kind == "unseen")):
            out += _runnable(s)
    return out


def outcomes(run: StudyRun, kind: str) -> list[Outcome]:
    """Each design of the set with its base run's stats and each knob's measured speed-up (nan:
    not measured: refused, failed, or a structure the set has no trace of)."""
    found = []
    for k, d in designs(run.options):
        if k != kind:
            continue
        stats = run.stats(run.row(part=part(kind, d), point="base"))
        o = Outcome(d.name, stats)
        base = float(stats["summary"]["rays_per_second"])
        for knob in knobs_to_measure(stats["verdict"], kind == "unseen"):
            rows = [
                r
                for r in run.rows(point=knob)
                if r["part"].startswith(part(kind, d) + "/") and r["status"] == "ok"
            ]
            o.measured[knob] = rows[0]["rays_per_second"] / base if rows else float("nan")
        found.append(o)
    return found


def render(kind: str) -> Callable[[StudyRun], str]:
    def text(run: StudyRun) -> str:
        found = outcomes(run, kind)
        return table(found) + note(run, kind, found)

    return text


STUDY = Study(
    name="verdict",
    about="is the knob the verdict names the one that pays? (every knob measured; verdict.md)",
    specs=specs,
    follow_up=follow_up,
    tables=[
        Table("verdict.md", "verdict-study", render("tuned")),
        Table("verdict.md", "verdict-unseen", render("unseen")),
        Table(
            "verdict.md",
            "structural-estimates",
            lambda run: structural_table(outcomes(run, "unseen")),
        ),
    ],
    options={
        "resolution": "128x96",
        "unseen_resolution": "160x120",
        "alt_accel": "cwbvh8",
        "hairball_triangles": 200_000,
    },
    quick={"resolution": "32x24", "unseen_resolution": "32x24", "hairball_triangles": 20_000},
    # A knob run that fails is not measured (nan); a design that fails stops the study.
    allow_failed=True,
)

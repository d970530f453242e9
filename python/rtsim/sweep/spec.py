"""The sweep spec (YAML): scenes x workloads x config points, parsed with line numbers.

Every error names the spec file, the line and the key (``demo.yaml:12: grid.l1.size_kb: ...``).
The format is documented in docs/sweeps.md; python/rtsim/specs/demo.yaml is an example.
"""

from __future__ import annotations

import functools
import hashlib
import itertools
import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from rtsim.config import (
    ConfigError,
    SimConfig,
    apply_patch,
    compose,
    effective_dict,
    field_info,
    unflatten,
)
from rtsim.errors import RtsimError
from rtsim.kinds import RAY_KINDS
from rtsim.scenes import procedural_scene_names, resolve_scene
from rtsim.sweep.accel_axis import (
    AccelSpec,
    default_accel,
    folder_label,
    parse_accel_entries,
    registered_kinds,
    trace_format_version,
)
from rtsim.sweep.run_check import CheckedRun, config_patch, describe, first_refusal
from rtsim.sweep.yaml_lines import LineDict, LineList, line_of, load_yaml
from rtsim.tracing import REFLECTIONS

SAMPLING_METHODS = ("random", "latin_hypercube")
#: rtsim trace --frame-policy: how a moving scene's structures are made per frame.
FRAME_POLICIES = ("rebuild", "refit", "adaptive")
#: What `lights` on a scene may add (rtsim trace --lights): a sun gives a lightless scene shadows.
SCENE_LIGHTS = ("none", "sun")
PRESET_KEY = "preset"  # a grid key whose values are preset+modifier names
POINT_KEY = "point"  # the swept key under which a `points` entry's label is recorded
TOP_KEYS = (
    "name",
    "scenes",
    "workloads",
    "accel",
    "config",
    "grid",
    "points",
    "sampling",
    "timeout",
    "baseline",
    "check_runs",
)
#: The swept key (a store column, a report axis) under which the `accel` axis is recorded.
ACCEL_KEY = "accel"
#: Most runs one sweep may have (each is an rtsim-sim process and a row of the store); checked
#: from the grid's and sample's sizes before any point is enumerated.
MAX_RUNS = 100_000
#: The tracer's limits (traces/tracer/tracer.cpp): pixels of a workload, bounces.
MAX_PIXELS = 1 << 28
MAX_BOUNCES = 64


class SpecError(RtsimError, ValueError):
    """A spec that cannot be run; the message names the file, line and key."""


def stable_hash(data: Any, length: int = 16) -> str:
    text = json.dumps(data, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:length]


@dataclass(frozen=True)
class SceneSpec:
    label: str
    source: str  # built-in name, shared scene name or glTF path (resolved at trace time)
    hairball_triangles: int = 200_000
    seed: int = 1
    flatten: bool = False  # instanced scenes: one world-space structure (rtsim trace --flatten)
    lights: str = ""  # lights added to a scene without any (rtsim trace --lights); "": none

    def key(self) -> dict[str, Any]:
        key: dict[str, Any] = {
            "source": self.source,
            "hairball_triangles": self.hairball_triangles,
            "seed": self.seed,
        }
        if self.flatten:  # (absent when off: the keys of earlier sweeps stay valid)
            key["flatten"] = True
        if self.lights:
            key["lights"] = self.lights
        return key


@dataclass(frozen=True)
class WorkloadSpec:
    label: str
    rays: tuple[str, ...]  # empty: every kind the scene calls for (the tracer's default)
    width: int
    height: int
    bounces: int = 1
    seed: int = 1
    frames: int = 1  # an animated trace of N frames (rtsim trace --frames N)
    # How each frame's deforming BLASes and TLAS are made (rtsim trace --frame-policy, and
    # --rebuild-threshold for adaptive); defaults as the tracer's.
    frame_policy: str = "rebuild"
    rebuild_threshold: float = 1.25
    reflections: str = "mirror"  # rtsim trace --reflections (mirror or glossy)
    roulette_after: int = 0  # rtsim trace --roulette-after (0: off)
    # rtsim trace --alternatives: the structures one step away traced beside the trace, so each
    # run's verdict estimates them (docs/verdict.md, "Structural estimates").
    alternatives: bool = False

    def key(self) -> dict[str, Any]:
        key: dict[str, Any] = {
            "rays": list(self.rays) or "scene",
            "width": self.width,
            "height": self.height,
            "bounces": self.bounces,
            "seed": self.seed,
        }
        if self.frames != 1:  # (absent for one frame: the keys of earlier sweeps stay valid)
            key["frames"] = self.frames
        if self.frame_policy != "rebuild":  # (absent at the default, likewise)
            key["frame_policy"] = self.frame_policy
        if self.rebuild_threshold != 1.25:
            key["rebuild_threshold"] = self.rebuild_threshold
        if self.reflections != "mirror":
            key["reflections"] = self.reflections
        if self.roulette_after:
            key["roulette_after"] = self.roulette_after
        if self.alternatives:
            key["alternatives"] = True
        return key


@dataclass(frozen=True)
class TracePlan:
    """One trace: a scene under a workload through one acceleration structure, shared by every
    config point. Its id keys the trace cache: scene, workload, structure, builder and trace
    format version (a trace of another structure or format is never reused)."""

    scene: SceneSpec
    workload: WorkloadSpec
    accel: AccelSpec
    trace_version: int

    @property
    def trace_id(self) -> str:
        key = {
            "scene": self.scene.key(),
            "workload": self.workload.key(),
            "accel": self.accel.key(self.trace_version),
        }
        return stable_hash(key, 12)

    @property
    def folder_name(self) -> str:
        parts = (self.scene.label, self.workload.label, folder_label(self.accel))
        return f"{'-'.join(parts)}-{self.trace_id[:8]}"


@dataclass
class RunPlan:
    """One simulation: a trace and a resolved config; run_id hashes both."""

    trace: TracePlan
    preset: str
    params: dict[str, Any]  # the swept values of this point
    config: SimConfig

    @functools.cached_property
    def run_id(self) -> str:
        # The effective config: points that differ only in a switched-off section's fields
        # (ray-buffer sizes with treelets off) are one simulation.
        return stable_hash({"trace": self.trace.trace_id, "config": effective_dict(self.config)})


@dataclass
class SamplingSpec:
    method: str
    n: int
    seed: int
    ranges: dict[str, dict[str, Any]]  # key -> {"min", "max"} or {"values"}


@dataclass
class SweepSpec:
    name: str
    scenes: list[SceneSpec]
    workloads: list[WorkloadSpec]
    # The structures to trace with; None: the spec has no `accel` key (the default structure,
    # not recorded as a swept key).
    accels: list[AccelSpec] | None = None
    trace_version: int = 0  # the trace format version of this build (a trace cache key)
    preset: str = "base"
    sets: dict[str, Any] = field(default_factory=dict)
    grid: dict[str, list[Any]] = field(default_factory=dict)
    # Named config points (`points`: label, preset, set), crossed with the grid; each is a dict
    # of swept values ({"point": label, "preset": name, "l1.size_kib": 64}).
    named_points: list[dict[str, Any]] = field(default_factory=list)
    sampling: SamplingSpec | None = None
    timeout: float | None = None
    text: str = ""
    # The configuration the report's speed-ups are measured against: a value per swept grid key
    # (keys left out take their first grid value). Empty: the first value of every grid key.
    baseline: dict[str, Any] = field(default_factory=dict)

    @property
    def swept_keys(self) -> list[str]:
        keys = ([ACCEL_KEY] if self.accels is not None else []) + list(self.grid)
        for point in self.named_points:
            keys += [k for k in point if k not in keys]
        if self.sampling:
            keys += [k for k in self.sampling.ranges if k not in keys]
        return keys

    def points(self) -> list[dict[str, Any]]:
        """Grid points x named points x sampled points (each may be absent: one empty point)."""
        grid = [
            dict(zip(self.grid, v, strict=True)) for v in itertools.product(*self.grid.values())
        ]
        named = self.named_points or [{}]
        samples = sample_points(self.sampling) if self.sampling else [{}]
        return [{**g, **n, **s} for g in grid for n in named for s in samples]

    def traces(self) -> list[TracePlan]:
        accels = self.accels if self.accels is not None else [default_accel()]
        return [
            TracePlan(s, w, a, self.trace_version)
            for s in self.scenes
            for w in self.workloads
            for a in accels
        ]

    def plans(self) -> list[RunPlan]:
        """Every (trace, point) of the spec, traces outermost, duplicates included: two points
        that resolve to one config on one trace are two plans of one run (a study's table has
        a row for each)."""
        base_sets = unflatten(self.sets)
        bases: dict[str, SimConfig] = {}  # each preset with the spec's sets, composed once
        plans = []
        for trace in self.traces():
            for point in self.points():
                preset = str(point.get(PRESET_KEY, self.preset))
                values = {k: v for k, v in point.items() if k not in (PRESET_KEY, POINT_KEY)}
                if preset not in bases:
                    bases[preset] = apply_patch(compose(preset), base_sets)
                config = apply_patch(bases[preset], unflatten(values))
                params = dict(point)
                if self.accels is not None:
                    params = {ACCEL_KEY: trace.accel.label, **params}
                plans.append(RunPlan(trace, preset, params, config))
        return plans

    def runs(self) -> list[RunPlan]:
        """Every run, traces outermost, without duplicates (same trace and resolved config)."""
        runs, seen = [], set()
        for run in self.plans():
            if run.run_id not in seen:
                seen.add(run.run_id)
                runs.append(run)
        return runs


def sample_points(s: SamplingSpec) -> list[dict[str, Any]]:
    """n points over the ranges: uniform random, or Latin hypercube (one sample per stratum
    in every dimension; McKay, Beckman & Conover 1979)."""
    rng = np.random.default_rng(s.seed)
    keys = list(s.ranges)
    if s.method == "random":
        u = rng.random((s.n, len(keys)))
    else:
        strata = np.stack([rng.permutation(s.n) for _ in keys], axis=1)
        u = (strata + rng.random((s.n, len(keys)))) / s.n
    points = []
    for row in u:
        point = {}
        for key, x in zip(keys, row, strict=True):
            r = s.ranges[key]
            if "values" in r:
                point[key] = r["values"][min(int(x * len(r["values"])), len(r["values"]) - 1)]
            elif r["int"]:
                point[key] = int(min(r["min"] + int(x * (r["max"] - r["min"] + 1)), r["max"]))
            else:
                point[key] = float(r["min"] + x * (r["max"] - r["min"]))
        points.append(point)
    return points


class _Reader:
    """Parses one spec document, raising SpecError with file:line: key."""

    def __init__(self, source: str) -> None:
        self.source = source

    def fail(self, container: Any, key: Any, path: str, message: str) -> SpecError:
        return SpecError(f"{self.source}:{line_of(container, key)}: {path}: {message}")

    def mapping(self, parent: Any, key: Any, path: str, allowed: tuple[str, ...] = ()) -> LineDict:
        value = parent[key]
        if not isinstance(value, dict):
            raise self.fail(parent, key, path, f"expected a mapping, got {value!r}")
        for k in value:
            if allowed and k not in allowed:
                raise self.fail(
                    value,
                    k,
                    f"{path}.{k}" if path else str(k),
                    f"unknown key (expected one of: {', '.join(allowed)})",
                )
        return value

    def choice(
        self, parent: Any, key: str, path: str, choices: tuple[str, ...], default: str
    ) -> str:
        """parent[key] (default when absent), one of `choices`."""
        value = parent.get(key, default)
        if value not in choices:
            raise self.fail(
                parent, key, path, f"expected one of {', '.join(choices)}, got {value!r}"
            )
        return str(value)

    def number(
        self,
        parent: Any,
        key: Any,
        path: str,
        integer: bool,
        minimum: float = 0,
        maximum: float = math.inf,
        above: bool = False,
    ) -> Any:
        """A number in [minimum, maximum] (above: > minimum); never NaN or infinite."""
        value = parent[key]
        ok = isinstance(value, int) if integer else isinstance(value, (int, float))
        ok = ok and not isinstance(value, bool) and math.isfinite(value)
        if not ok or value < minimum or value > maximum or (above and value == minimum):
            what = "an integer" if integer else "a finite number"
            bound = f"> {minimum}" if above else f">= {minimum}"
            if maximum != math.inf:
                bound += f" and <= {maximum}"
            raise self.fail(parent, key, path, f"expected {what} {bound}, got {value!r}")
        return value

    def scene(self, items: LineList, i: int, base: Path | None) -> SceneSpec:
        if isinstance(items[i], str):
            d = LineDict({"name": items[i]})
            d.line = items.item_line(i)
        else:
            allowed = ("name", "label", "hairball_triangles", "seed", "flatten", "lights")
            d = self.mapping(items, i, f"scenes[{i}]", allowed)
        if not isinstance(d.get("name"), str) or not d["name"]:
            raise self.fail(items, i, f"scenes[{i}].name", "a scene needs a name or path")
        source = d["name"]
        if base is not None and ("/" in source or source.endswith((".gltf", ".glb"))):
            candidate = base / source
            source = str(candidate.resolve()) if candidate.exists() else source
        try:
            resolved = resolve_scene(source)
        except ValueError as err:
            raise self.fail(d, "name", f"scenes[{i}].name", str(err)) from None
        if resolved not in procedural_scene_names() and not Path(resolved).is_file():
            what = "a folder without a .gltf/.glb" if Path(resolved).is_dir() else "no such file"
            raise self.fail(d, "name", f"scenes[{i}].name", f"{resolved}: {what}")
        label = str(d.get("label") or Path(d["name"]).stem)
        tris = (
            self.number(d, "hairball_triangles", f"scenes[{i}].hairball_triangles", True, 1)
            if "hairball_triangles" in d
            else 200_000
        )
        seed = self.number(d, "seed", f"scenes[{i}].seed", True) if "seed" in d else 1
        flat = d.get("flatten", False)
        if not isinstance(flat, bool):
            raise self.fail(
                d, "flatten", f"scenes[{i}].flatten", f"expected true or false, got {flat!r}"
            )
        lights = self.choice(d, "lights", f"scenes[{i}].lights", SCENE_LIGHTS, "none")
        return SceneSpec(label, source, tris, seed, flat, "" if lights == "none" else lights)

    def workload(self, items: LineList, i: int) -> WorkloadSpec:
        allowed = ("name", "rays", "resolution", "bounces", "seed", "frames", "frame_policy",
                   "rebuild_threshold", "reflections", "roulette_after",
                   "alternatives")  # fmt: skip
        d = self.mapping(items, i, f"workloads[{i}]", allowed)
        path = f"workloads[{i}]"
        rays = d.get("rays", [])  # absent: what the scene calls for
        explicit = "rays" in d
        if isinstance(rays, str):
            rays = [r.strip() for r in rays.split(",") if r.strip()]
        bad = [r for r in rays if r not in RAY_KINDS] if isinstance(rays, list) else [rays]
        if bad or (explicit and not rays):
            raise self.fail(
                d,
                "rays",
                f"{path}.rays",
                f"unknown ray kind(s) {bad}; choose from {', '.join(RAY_KINDS)}",
            )
        res = d.get("resolution", "128x96")
        w, _, h = str(res).lower().partition("x")
        if not (w.isdigit() and h.isdigit() and int(w) > 0 and int(h) > 0):
            raise self.fail(d, "resolution", f"{path}.resolution", f"expected WxH, got {res!r}")
        if int(w) * int(h) > MAX_PIXELS:
            raise self.fail(
                d, "resolution", f"{path}.resolution", f"{res}: more than {MAX_PIXELS} pixels"
            )
        bounces = (
            self.number(d, "bounces", f"{path}.bounces", True, 0, MAX_BOUNCES)
            if "bounces" in d
            else 1
        )
        seed = self.number(d, "seed", f"{path}.seed", True) if "seed" in d else 1
        frames = self.number(d, "frames", f"{path}.frames", True, 1) if "frames" in d else 1
        policy = self.choice(d, "frame_policy", f"{path}.frame_policy", FRAME_POLICIES, "rebuild")
        threshold = (
            self.number(d, "rebuild_threshold", f"{path}.rebuild_threshold", False, 1.0)
            if "rebuild_threshold" in d
            else 1.25
        )
        reflections = self.choice(d, "reflections", f"{path}.reflections", REFLECTIONS, "mirror")
        roulette = (
            self.number(d, "roulette_after", f"{path}.roulette_after", True, 0, MAX_BOUNCES)
            if "roulette_after" in d
            else 0
        )
        alternatives = d.get("alternatives", False)
        if not isinstance(alternatives, bool):
            raise self.fail(
                d, "alternatives", f"{path}.alternatives",
                f"expected true or false, got {alternatives!r}",
            )  # fmt: skip
        if alternatives and int(frames) > 1:
            raise self.fail(
                d, "alternatives", f"{path}.alternatives",
                "an animated trace has no structural alternatives (the verdict measures them)",
            )  # fmt: skip
        label = str(d.get("name") or "-".join(rays) or "scene")
        return WorkloadSpec(
            label, tuple(rays), int(w), int(h), bounces, seed, frames, policy, float(threshold),
            reflections, int(roulette), alternatives,
        )  # fmt: skip

    def accels(self, doc: LineDict) -> list[AccelSpec]:
        """The `accel` axis: a list (or one entry) of KIND, KIND:BUILDER or {kind, builder,
        label, build}, checked against the structures this build registers; lists in `build`
        expand into one structure per value (builder settings as an axis)."""
        items = doc["accel"]
        if isinstance(items, (str, dict)):
            items = LineList([items])
            items.line = line_of(doc, "accel")
        if not isinstance(items, list) or not items:
            raise self.fail(doc, "accel", "accel", "expected a non-empty list of structures")
        kinds = registered_kinds()
        out = []
        for i, entry in enumerate(items):

            def fail(sub: str, message: str, i: int = i, entry: Any = entry) -> SpecError:
                if sub and isinstance(entry, dict):
                    where = entry if sub in entry else items
                    key = sub if sub in entry else i
                    return self.fail(where, key, f"accel[{i}].{sub}", message)
                return self.fail(items, i, f"accel[{i}]", message)

            # Every structure is at least one run: the axis is held to the run limit as it
            # expands, each entry's settings product counted before it is made.
            out.extend(parse_accel_entries(entry, kinds, fail, MAX_RUNS - len(out)))
        seen: set[str] = set()
        for a in out:
            if a.label in seen:
                raise self.fail(
                    doc, "accel", "accel", f"two entries named '{a.label}' (give one a label)"
                )
            seen.add(a.label)
        return out

    def config_value(self, parent: Any, key: Any, path: str, config_key: str, value: Any) -> None:
        """Checks that config_key exists and value has its type (ranges: rtsim-sim validate())."""
        try:
            field_info(config_key)
            SimConfig().with_values({config_key: value})
        except ConfigError as err:
            raise self.fail(parent, key, path, str(err).removeprefix("config: ")) from None

    def grid(self, doc: LineDict) -> dict[str, list[Any]]:
        g = self.mapping(doc, "grid", "grid")
        out: dict[str, list[Any]] = {}
        for key, values in g.items():
            path = f"grid.{key}"
            if not isinstance(values, list) or not values:
                raise self.fail(g, key, path, "expected a non-empty list of values")
            for j, v in enumerate(values):
                if key == PRESET_KEY:
                    try:
                        compose(str(v))
                    except ConfigError as err:
                        raise self.fail(values, j, path, str(err)) from None
                else:
                    self.config_value(values, j, path, str(key), v)
            out[str(key)] = list(values)
        return out

    def named_points(self, doc: LineDict, grid: dict[str, list[Any]]) -> list[dict[str, Any]]:
        """`points`: a list of named configs ({label, preset, set}), each a swept point."""
        items = doc["points"]
        if not isinstance(items, list) or not items:
            raise self.fail(doc, "points", "points", "expected a non-empty list of points")
        out = []
        for i, _ in enumerate(items):
            path = f"points[{i}]"
            p = self.mapping(items, i, path, ("label", "preset", "set"))
            point: dict[str, Any] = {}
            if "label" in p:
                point[POINT_KEY] = str(p["label"])
            if "preset" in p:
                try:
                    compose(str(p["preset"]))
                except ConfigError as err:
                    raise self.fail(p, "preset", f"{path}.preset", str(err)) from None
                point[PRESET_KEY] = str(p["preset"])
            for key, value in (self.mapping(p, "set", f"{path}.set") if "set" in p else {}).items():
                if key in grid:
                    raise self.fail(p["set"], key, f"{path}.set.{key}", "already swept by the grid")
                self.config_value(p["set"], key, f"{path}.set.{key}", str(key), value)
                point[str(key)] = value
            out.append(point)
        return out

    def baseline(
        self, doc: LineDict, grid: dict[str, list[Any]], accels: list[str] | None = None
    ) -> dict[str, Any]:
        """The report's baseline point: each key swept by the grid, each value one of its grid's;
        `accel` names one of the accel axis's labels (docs/sweeps.md)."""
        b = self.mapping(doc, "baseline", "baseline")
        for key, value in b.items():
            path = f"baseline.{key}"
            if key == ACCEL_KEY:
                if accels is None:
                    raise self.fail(b, key, path, "the spec has no accel axis")
                if str(value) not in accels:
                    raise self.fail(
                        b, key, path, f"{value!r} is not one of the accel axis's {accels}"
                    )
                continue
            if key not in grid:
                known = ", ".join(grid) or "(no grid)"
                raise self.fail(b, key, path, f"not a grid key (grid keys: {known})")
            if value not in grid[key]:
                raise self.fail(b, key, path, f"{value!r} is not one of the grid's {grid[key]}")
        return {str(k): v for k, v in b.items()}

    def sampling(self, doc: LineDict) -> SamplingSpec:
        s = self.mapping(doc, "sampling", "sampling", ("method", "n", "seed", "ranges"))
        method = s.get("method", "latin_hypercube")
        if method not in SAMPLING_METHODS:
            raise self.fail(
                s,
                "method",
                "sampling.method",
                f"{method!r} is not one of: {', '.join(SAMPLING_METHODS)}",
            )
        if "n" not in s:
            raise self.fail(doc, "sampling", "sampling.n", "missing (how many points to sample)")
        n = self.number(s, "n", "sampling.n", True, 1)
        seed = self.number(s, "seed", "sampling.seed", True) if "seed" in s else 1
        if "ranges" not in s:
            raise self.fail(doc, "sampling", "sampling.ranges", "missing (key: [min, max])")
        ranges = {}
        for key in self.mapping(s, "ranges", "sampling.ranges"):
            ranges[str(key)] = self.range(s["ranges"], key, f"sampling.ranges.{key}")
        return SamplingSpec(method, n, seed, ranges)

    def range(self, parent: LineDict, key: str, path: str) -> dict[str, Any]:
        r = parent[key]
        if isinstance(r, dict) and set(r) == {"values"} and isinstance(r["values"], list):
            if not r["values"]:
                raise self.fail(parent, key, path, "values: an empty list (give one or more)")
            for v in r["values"]:
                self.config_value(parent, key, path, key, v)
            return {"values": list(r["values"])}
        ok = (
            isinstance(r, list)
            and len(r) == 2
            and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in r)
        )
        if not ok or r[0] > r[1]:
            raise self.fail(
                parent, key, path, f"expected [min, max] or {{values: [...]}}, got {r!r}"
            )
        self.config_value(parent, key, path, key, r[0])
        self.config_value(parent, key, path, key, r[1])
        is_int = field_info(key).type in ("int", int)
        if is_int and not all(isinstance(x, int) for x in r):
            raise self.fail(parent, key, path, "an integer field needs integer bounds")
        return {"min": r[0], "max": r[1], "int": is_int}


def parse_spec(text: str, source: str = "<spec>", base: Path | None = None) -> SweepSpec:
    """A SweepSpec from YAML text; SpecError names source:line: key on any problem."""
    rd = _Reader(source)
    try:
        doc = load_yaml(text)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        line = mark.line + 1 if mark is not None else 0
        raise SpecError(f"{source}:{line}: not valid YAML: {err}") from None
    except RecursionError:
        raise SpecError(
            f"{source}: nested too deeply to parse (a spec needs a few levels)"
        ) from None
    if not isinstance(doc, LineDict):
        raise SpecError(f"{source}:1: (root): expected a mapping with scenes, workloads, grid")
    holder = LineDict({"(root)": doc})
    rd.mapping(holder, "(root)", "", TOP_KEYS)
    for key in ("scenes", "workloads"):
        if not isinstance(doc.get(key), list) or not doc[key]:
            raise rd.fail(doc, key, key, "missing or empty (a list is needed)")
    scenes = [rd.scene(doc["scenes"], i, base) for i in range(len(doc["scenes"]))]
    workloads = [rd.workload(doc["workloads"], i) for i in range(len(doc["workloads"]))]
    for what, items in (("scenes", scenes), ("workloads", workloads)):
        labels = [x.label for x in items]
        dup = next((x for x in labels if labels.count(x) > 1), None)
        if dup:
            raise rd.fail(doc, what, what, f"two entries named '{dup}' (give one a label/name)")
    spec = SweepSpec(str(doc.get("name") or Path(source).stem), scenes, workloads, text=text)
    spec.trace_version = trace_format_version()
    if "accel" in doc:
        spec.accels = rd.accels(doc)
    if "config" in doc:
        c = rd.mapping(doc, "config", "config", ("preset", "set"))
        if "preset" in c:
            spec.preset = str(c["preset"])
            try:
                compose(spec.preset)
            except ConfigError as err:
                raise rd.fail(c, "preset", "config.preset", str(err)) from None
        if "set" in c:
            for key, value in rd.mapping(c, "set", "config.set").items():
                rd.config_value(c["set"], key, f"config.set.{key}", str(key), value)
                spec.sets[str(key)] = value
    if "grid" in doc:
        spec.grid = rd.grid(doc)
    if "points" in doc:
        spec.named_points = rd.named_points(doc, spec.grid)
    if "sampling" in doc:
        spec.sampling = rd.sampling(doc)
        both = (set(spec.grid) | {k for p in spec.named_points for k in p}) & set(
            spec.sampling.ranges
        )
        if both:
            key = sorted(both)[0]
            raise rd.fail(
                doc["sampling"]["ranges"],
                key,
                f"sampling.ranges.{key}",
                "already swept by the grid or the points",
            )
    _check_size(rd, doc, spec)
    if "timeout" in doc:
        spec.timeout = float(rd.number(doc, "timeout", "timeout", False, 0, above=True))
    if "baseline" in doc:
        labels = [a.label for a in spec.accels] if spec.accels is not None else None
        spec.baseline = rd.baseline(doc, spec.grid, labels)
    if "check_runs" in doc and not isinstance(doc["check_runs"], bool):
        raise rd.fail(doc, "check_runs", "check_runs", "expected true or false")
    # false: a run the simulator refuses is a failed run with its message (a study counting
    # refusals), not a refused spec.
    if doc.get("check_runs", True):
        _check_runs(rd, doc, spec)
    return spec


def _check_runs(rd: _Reader, doc: LineDict, spec: SweepSpec) -> None:
    """Refuses a spec any of whose runs the simulator would refuse (its resolution step and
    memory estimate, asked once for every distinct structure and config), naming the swept key
    that made the run, before any trace is made."""
    runs, seen = [], set()
    base_sets = unflatten(spec.sets)
    accels = spec.accels if spec.accels is not None else [default_accel()]
    for point in spec.points():
        preset = str(point.get(PRESET_KEY, spec.preset))
        values = {k: v for k, v in point.items() if k not in (PRESET_KEY, POINT_KEY)}
        patch = config_patch(
            apply_patch(apply_patch(compose(preset), base_sets), unflatten(values))
        )
        for a in accels:
            compressed = bool(dict(a.settings).get("compressed_leaves", False))
            key = (a.kind, compressed, json.dumps(patch, sort_keys=True))
            if key in seen:
                continue
            seen.add(key)
            label = a.label if spec.accels is not None else None
            runs.append(CheckedRun(a.kind, compressed, patch, label, dict(point)))
    refused = first_refusal(runs)
    if refused is None:
        return
    run, message = refused
    container, key, path = _blame(doc, spec, run, message)
    raise rd.fail(
        container,
        key,
        path,
        f"the run with {describe(run)} would be refused by the simulator: {message}",
    )


def _blame(doc: LineDict, spec: SweepSpec, run: CheckedRun, message: str) -> tuple[Any, Any, str]:
    """Where in the spec a refused run comes from: the swept or set key its message names, else
    the accel axis, else the first swept key, else the config."""
    places: list[tuple[str, Any, Any, str]] = []  # (config key, container, key, path)
    if "grid" in doc:
        places += [(k, doc["grid"], k, f"grid.{k}") for k in doc["grid"]]
    if spec.sampling is not None:
        ranges = doc["sampling"]["ranges"]
        places += [(k, ranges, k, f"sampling.ranges.{k}") for k in ranges]
    if "points" in doc:
        places += [(k, doc, "points", "points") for p in spec.named_points for k in p]
    config = doc.get("config")
    if isinstance(config, dict) and isinstance(config.get("set"), dict):
        places += [(k, config["set"], k, f"config.set.{k}") for k in config["set"]]
    for name, container, key, path in places:
        if str(name) in message:
            return container, key, path
    if "accel" in doc:
        return doc, "accel", "accel"
    if places:
        return places[0][1:]
    return (doc, "config", "config") if "config" in doc else (doc, "scenes", "scenes")


def _check_size(rd: _Reader, doc: LineDict, spec: SweepSpec) -> None:
    """Refuses a sweep of more than MAX_RUNS runs before anything is enumerated."""
    points = math.prod(len(v) for v in spec.grid.values())
    points *= spec.sampling.n if spec.sampling else 1
    points *= len(spec.named_points) or 1
    accels = len(spec.accels) if spec.accels else 1
    runs = points * len(spec.scenes) * len(spec.workloads) * accels
    if runs <= MAX_RUNS:
        return
    key = "grid" if "grid" in doc else "sampling"
    raise rd.fail(
        doc,
        key,
        key,
        f"{runs:,} runs ({len(spec.scenes)} scenes x {len(spec.workloads)} workloads x "
        f"{accels} structures x {points:,} config points) exceed the limit of {MAX_RUNS:,} "
        "runs per sweep (docs/sweeps.md); split the sweep, or sample points (sampling.n) "
        "instead of a grid",
    )


def spec_from_dict(data: dict[str, Any], source: str = "<dict>") -> SweepSpec:
    """A SweepSpec from a dict of the YAML's shape (what `rtsim.sweep` takes in a notebook):
    written out as YAML and parsed like a file, so it is checked the same way and the store
    records the same text; errors name the key (and the line of that YAML). Relative scene
    paths are relative to the working folder."""
    if not isinstance(data, dict):
        raise SpecError(f"{source}: a spec is a mapping (scenes, workloads, grid, ...), got "
                        f"{type(data).__name__}")  # fmt: skip
    try:
        text = yaml.safe_dump(_plain(data), sort_keys=False, allow_unicode=True)
    except yaml.YAMLError as err:
        raise SpecError(f"{source}: cannot be written as YAML: {err}") from None
    return parse_spec(text, source=source, base=Path.cwd())


def _plain(value: Any) -> Any:
    """Numpy scalars and tuples as the plain values YAML writes."""
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if hasattr(value, "item") and type(value).__module__ == "numpy":
        return value.item()
    return value


def load_spec(path: Path) -> SweepSpec:
    """Reads and parses a spec file (relative scene paths are relative to it)."""
    try:
        if Path(path).exists() and not Path(path).is_file():
            raise SpecError(f"{path}: not a regular file (a folder, FIFO or device)")
        text = Path(path).read_text()
    except OSError as err:
        raise SpecError(f"{path}: cannot read the spec ({err.strerror})") from None
    except UnicodeDecodeError as err:
        raise SpecError(f"{path}: not UTF-8 text ({err})") from None
    return parse_spec(text, source=str(path), base=Path(path).resolve().parent)

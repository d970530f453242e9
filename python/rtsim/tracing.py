"""The reference tracer from Python, with scene names resolved as the command line resolves
them (rtsim/scenes.py: a .gltf/.glb path, a built-in scene, or a shared scene's name such as
"sponza").

- ``load_scene(scene)``: a Scene (triangles, materials, lights, BVH statistics);
- ``trace_scene(scene, out_dir, ...)``: a trace folder of the workload the scene calls for;
- ``write_trace(scene, origins, directions, ..., out=...)``: a trace folder of your own rays.

Every trace folder holds trace.rtt and manifest.json, and ``rtsim.simulate`` replays it.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

from rtsim.args import (
    UINT32_MAX,
    UINT64_MAX,
    ArgumentTypeError,
    ArgumentValueError,
    bool_arg,
    float_arg,
    int_arg,
    path_arg,
)
from rtsim.errors import RtsimError
from rtsim.kinds import ANYHIT_ORDERS, RAY_KINDS
from rtsim.scenes import resolve_scene

if TYPE_CHECKING:
    import numpy as np

    from rtsim._core import Scene

SceneLike = Any  # a Scene, or a name or path that resolve_scene understands
SHADOW = RAY_KINDS.index("shadow")


def load_scene(
    scene: str | os.PathLike[str], hairball_triangles: int = 200_000, seed: int = 1
) -> Scene:
    """Loads a .gltf/.glb file, a built-in scene ("cornell", "hairball", ...) or a shared scene
    by its name ("sponza"). hairball_triangles and seed shape the procedural scenes."""
    from rtsim import _core

    return _core.load_scene(
        resolve_scene(path_arg(scene, "scene")),
        hairball_triangles=int_arg(hairball_triangles, "hairball_triangles", 1, UINT32_MAX),
        seed=int_arg(seed, "seed", 0, UINT64_MAX),
    )


def parse_setting_value(text: str) -> Any:
    """A builder setting's value as given on the command line or in a spec: '32' -> 32,
    '1e-5' -> 1e-05, 'true'/'false' -> a bool; other text stays text (the builder then names the
    setting and what it takes)."""
    lowered = text.strip().lower()
    if lowered in ("true", "false"):
        return lowered == "true"
    try:
        value = json.loads(text)
    except ValueError:
        return text
    return value if isinstance(value, (int, float)) and not isinstance(value, bool) else text


def _scene_arg(scene: SceneLike) -> Any:
    from rtsim import _core

    return scene if isinstance(scene, _core.Scene) else resolve_scene(path_arg(scene, "scene"))


#: The tracer's limits (traces/tracer/tracer.cpp): pixels, frames of an animated trace, bounces.
MAX_PIXELS = 1 << 28
MAX_FRAMES = 1024
MAX_BOUNCES = 64


def _camera_arg(camera: Any) -> tuple[list[float], list[float], float] | None:
    """(eye, target, fov) checked: 3 + 3 finite numbers, fov in (0, 180) degrees."""
    if camera is None:
        return None
    if isinstance(camera, (str, bytes)) or not isinstance(camera, Sequence) or len(camera) != 3:
        raise ArgumentTypeError(
            f"camera: expected (eye, target, fov_degrees), e.g. ((0, 1, 5), (0, 1, 0), 60), "
            f"got {camera!r}"
        )
    points = []
    for name, point in (("eye", camera[0]), ("target", camera[1])):
        if isinstance(point, (str, bytes)) or not isinstance(point, Sequence) or len(point) != 3:
            try:
                point = list(point)  # a numpy array
            except TypeError:
                point = None
            if point is None or len(point) != 3:
                raise ArgumentTypeError(f"camera {name}: expected 3 coordinates, got {camera!r}")
        values = [float_arg(v, f"camera {name}", finite=False) for v in point]
        if not all(math.isfinite(v) for v in values):
            raise ArgumentValueError(
                f"camera eye and target must be finite numbers (camera {name}: {values})"
            )
        points.append(values)
    fov = float_arg(camera[2], "camera fov_degrees")
    if not 0.0 < fov < 180.0:
        raise ArgumentValueError(f"camera: field of view must be in (0, 180) degrees, got {fov:g}")
    return points[0], points[1], fov


def _workload_arg(workload: Sequence[str] | str | None) -> list[str] | None:
    if workload is None:
        return None
    if isinstance(workload, str):
        kinds = [k.strip() for k in workload.split(",") if k.strip()]
    elif isinstance(workload, Sequence) and all(isinstance(k, str) for k in workload):
        kinds = list(workload)
    else:
        raise ArgumentTypeError(
            f"workload: expected ray kind names ('primary,diffuse' or a list), got {workload!r}"
        )
    unknown = sorted({k.lower() for k in kinds} - set(RAY_KINDS))
    if unknown or not kinds:
        raise ArgumentValueError(
            f"workload: unknown ray kind(s) {unknown or '(none given)'}; "
            f"choose from {', '.join(RAY_KINDS)} (None: what the scene calls for)"
        )
    return [k.lower() for k in kinds]


def trace_defaults() -> dict[str, Any]:
    """The tracer's option defaults, as C++ declares them once (TraceOptions in
    traces/tracer/tracer.h): width, height, bounces, seed, accel, builder, ..."""
    from rtsim import _core

    return dict(_core.trace_defaults())


FRAME_POLICIES = ("rebuild", "refit", "adaptive")


def _frame_policy_arg(value: Any) -> str:
    if value not in FRAME_POLICIES:
        raise ArgumentValueError(
            f"frame_policy: {value!r} is not one of {', '.join(FRAME_POLICIES)}"
        )
    return str(value)


def _rebuild_threshold_arg(value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not value >= 1.0:
        raise ArgumentValueError(
            f"rebuild_threshold: {value!r} must be a number of at least 1 (a refitted tree's "
            "SAH cost over its rebuilt cost)"
        )
    return float(value)


def trace_scene(
    scene: SceneLike,
    out_dir: str | os.PathLike[str],
    workload: Sequence[str] | str | None = None,
    width: int | None = None,
    height: int | None = None,
    bounces: int | None = None,
    seed: int | None = None,
    camera: tuple[Sequence[float], Sequence[float], float] | None = None,
    threads: int | None = None,
    hairball_triangles: int | None = None,
    progress: Callable[[int, int, str], None] | None = None,
    accel: str | None = None,
    builder: str | None = None,
    flatten: bool | None = None,
    frames: int | None = None,
    build_settings: dict[str, Any] | None = None,
    lights: str | None = None,
    frame_policy: str | None = None,
    rebuild_threshold: float | None = None,
    reflections: str | None = None,
    roulette_after: int | None = None,
    anyhit_order: str | None = None,
) -> dict[str, Any]:
    """Runs the reference tracer like `rtsim trace`: writes OUT/trace.rtt, manifest.json and
    render.png, and returns the manifest. Every option left None takes the tracer's default
    (trace_defaults(): 320x240, one bounce, seed 1, bvh2 with its default builder, ...).
    workload: ray kinds ("primary,diffuse" or a list); None traces every kind the scene calls
    for (manifest["workload"]["effects"] says which and why). camera: (eye, target, vertical
    field of view in degrees). accel and builder choose the acceleration structure
    (rtsim._core.accel_kinds(), docs/accel.md); build_settings overrides the builder's
    documented settings ({"bins": 32}; docs/accel.md, "Builder settings";
    manifest["accel"]["build_settings"] records them all). Instanced scenes are traced through
    two levels (a BLAS of that kind per mesh, a TLAS over the instances) unless flatten is true.
    frames > 1
    animates an instanced scene by the documented motion (docs/accel.md, "Frames"): the BLASes
    are built once, a TLAS per frame, and the workload is traced once per frame;
    manifest["frames"] lists each frame's rays and TLAS build time. Deforming meshes (skins,
    morph targets, the procedural moving scenes) get a BLAS per frame: frame_policy "rebuild",
    "refit" or "adaptive" (rebuild once the refitted SAH cost exceeds rebuild_threshold times
    the rebuilt one; docs/accel.md, "Moving scenes"). lights="sun" adds a
    directional light to a scene without lights (so it gets shadow rays; the manifest's
    workload.lights_added says what was added). reflections="glossy" samples reflection rays
    from the GGX lobe of each material's roughness instead of the mirror direction;
    roulette_after=N plays Russian roulette on path rays past N bounces (survival: the surface's
    albedo; docs/ray_generation.md). anyhit_order traces any-hit rays in that child order
    ("nearest", "largest_box", "fixed"; the structure must offer it): a run in the same
    traversal.anyhit_order then checks their work exactly."""
    from rtsim import _core

    checks: dict[str, Callable[[Any], Any]] = {
        "workload": _workload_arg,
        "width": lambda v: int_arg(v, "width", 1, MAX_PIXELS),
        "height": lambda v: int_arg(v, "height", 1, MAX_PIXELS),
        "bounces": lambda v: int_arg(v, "bounces", 0, MAX_BOUNCES),
        "seed": lambda v: int_arg(v, "seed", 0, UINT64_MAX),
        "camera": _camera_arg,
        "threads": lambda v: int_arg(v, "threads", 0, UINT32_MAX),
        "hairball_triangles": lambda v: int_arg(v, "hairball_triangles", 1, UINT32_MAX),
        "accel": lambda v: _name_arg(v, "accel"),
        "builder": lambda v: _name_arg(v, "builder"),
        "flatten": lambda v: bool_arg(v, "flatten"),
        "frames": lambda v: int_arg(v, "frames", 1, MAX_FRAMES),
        "build_settings": _settings_arg,
        "lights": _lights_arg,
        "frame_policy": _frame_policy_arg,
        "rebuild_threshold": _rebuild_threshold_arg,
        "reflections": _reflections_arg,
        "roulette_after": lambda v: int_arg(v, "roulette_after", 0, MAX_BOUNCES),
        "anyhit_order": _anyhit_order_arg,
    }
    values = {
        "workload": workload, "width": width, "height": height, "bounces": bounces, "seed": seed,
        "camera": camera, "threads": threads, "hairball_triangles": hairball_triangles,
        "accel": accel, "builder": builder, "flatten": flatten, "frames": frames,
        "build_settings": build_settings, "lights": lights, "frame_policy": frame_policy,
        "rebuild_threshold": rebuild_threshold, "reflections": reflections,
        "roulette_after": roulette_after, "anyhit_order": anyhit_order,
    }  # fmt: skip
    # Only the options given are passed: the others take the tracer's defaults (trace_defaults).
    given = {k: checks[k](v) for k, v in values.items() if v is not None}
    pixels = given.get("width", 1) * given.get("height", 1)
    if "width" in given and "height" in given and pixels > MAX_PIXELS:
        raise ArgumentValueError(
            f"width x height: {given['width']}x{given['height']} is more than {MAX_PIXELS} pixels"
        )
    if progress is not None and not callable(progress):
        raise ArgumentTypeError(
            f"progress: expected a callable (done, total, stage), got {progress!r}"
        )
    return _core.trace_scene(
        _scene_arg(scene), path_arg(out_dir, "out_dir"), progress=progress, **given
    )


def _anyhit_order_arg(order: str) -> str:
    if order not in ANYHIT_ORDERS:
        raise ArgumentValueError(
            f"anyhit_order: {order!r} is not one of {', '.join(ANYHIT_ORDERS)}"
        )
    return order


#: The choices of reflections= (traces/tracer/tracer.h, TraceOptions::reflections).
REFLECTIONS = ("mirror", "glossy")


def _reflections_arg(reflections: str) -> str:
    if reflections not in REFLECTIONS:
        raise ArgumentValueError(
            f"reflections: {reflections!r} is not one of {', '.join(REFLECTIONS)}"
        )
    return reflections


#: The choices of lights= (traces/raygen/added_lights.h).
ADDED_LIGHTS = ("none", "sun")


def _lights_arg(lights: str) -> str:
    if lights not in ADDED_LIGHTS:
        raise ArgumentValueError(f"lights: {lights!r} is not one of {', '.join(ADDED_LIGHTS)}")
    return lights


def _settings_arg(settings: dict[str, Any] | None) -> dict[str, Any] | None:
    """Builder settings {name: number, bool or text}; the builder checks names and ranges."""
    if settings is None:
        return None
    if not isinstance(settings, dict) or not all(isinstance(k, str) for k in settings):
        raise ArgumentTypeError(
            f"build_settings: expected a dict of setting name: value, got {settings!r}"
        )
    for name, value in settings.items():
        if not isinstance(value, (bool, int, float, str)):
            raise ArgumentTypeError(
                f"build_settings: '{name}' must be a number, a bool or text, got {value!r}"
            )
        if isinstance(value, float) and not math.isfinite(value):
            # As `--build-set` and sweep specs refuse it (the builder never sees NaN or inf).
            raise ArgumentValueError(
                f"build_settings: '{name}' must be a finite number, got {value!r}"
            )
    return dict(settings)


def _name_arg(value: Any, name: str) -> str:
    if not isinstance(value, str):
        raise ArgumentTypeError(f"{name}: expected a name (str), got {type(value).__name__}")
    return value


def _kind_codes(kind: str | Sequence[str] | Any, n: int) -> np.ndarray:
    """One RayKind number per ray from a kind name, or from one name or number per ray."""
    import numpy as np

    if isinstance(kind, str):
        kind = [kind] * n
    values = np.asarray(kind)
    if values.shape != (n,):
        raise RtsimError(f"kind: expected a ray kind name or {n} of them, got shape {values.shape}")
    if values.dtype.kind in "iu":
        bad = values[(values < 0) | (values >= len(RAY_KINDS))]
        if bad.size:
            raise RtsimError(
                f"kind: {int(bad[0])} is not a ray kind number (0..{len(RAY_KINDS) - 1})"
            )
        return values.astype(np.uint8)
    names = [str(v).lower() for v in values]
    unknown = sorted(set(names) - set(RAY_KINDS))
    if unknown:
        raise RtsimError(f"kind: unknown ray kind(s) {unknown}; choose from {', '.join(RAY_KINDS)}")
    return np.fromiter((RAY_KINDS.index(k) for k in names), dtype=np.uint8, count=n)


def write_trace(
    scene: SceneLike,
    origins: Any,
    directions: Any,
    tmin: Any = 0.0,
    tmax: Any = math.inf,
    *,
    out: str | os.PathLike[str],
    kind: str | Sequence[str] | Any = "primary",
    any_hit: bool | Sequence[bool] | Any | None = None,
    threads: int = 0,
    accel: str | None = None,
    builder: str | None = None,
    build_settings: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """Traces your rays with the reference tracer and writes a trace folder (OUT/trace.rtt and
    manifest.json, exactly as trace_scene writes one) that rtsim.simulate replays.

    origins, directions: (N, 3) arrays; tmin, tmax: scalars or (N,) arrays. kind: the ray kind
    of every ray ("primary", "shadow", "reflection", "diffuse", "refraction") or one per ray.
    any_hit: None makes shadow rays any-hit (occlusion) rays and the others closest-hit, as the
    tracer does; or a bool for every ray, or one per ray. accel, builder and build_settings
    choose the acceleration structure, built as trace_scene builds it (None: the tracer's
    defaults, trace_defaults()). Returns the manifest; rays are
    written in order, each with its index as `pixel`."""
    import numpy as np

    from rtsim import _core

    loaded = scene if isinstance(scene, _core.Scene) else load_scene(scene)
    out = path_arg(out, "out")
    n = int(np.shape(origins)[0]) if np.ndim(origins) >= 1 else 0
    kinds = _kind_codes(kind, n)
    if any_hit is None:
        flags = kinds == SHADOW
    else:
        flags = np.asarray(any_hit)
        if flags.dtype != bool:
            raise ArgumentTypeError(
                f"any_hit: expected True, False or one bool per ray, got {any_hit!r}"
            )
        if flags.ndim == 0:
            flags = np.full(n, bool(flags))
    return _core.write_trace(
        loaded,
        origins,
        directions,
        tmin,
        tmax,
        kinds,
        flags,
        out,
        threads=int_arg(threads, "threads", 0, UINT32_MAX),
        **{k: _name_arg(v, k) for k, v in {"accel": accel, "builder": builder}.items() if v},
        build_settings=_settings_arg(build_settings),
    )


def trace_rays(
    scene: Scene,
    origins: Any,
    directions: Any,
    tmin: Any = 0.0,
    tmax: Any = math.inf,
    any_hit: bool = False,
) -> np.ndarray:
    """Traces rays (origins and directions: (N, 3)) through the scene's reference BVH. Returns a
    structured array: prim (-1: miss), inst, t, u, v, valid (False for rays rejected as invalid:
    NaN, zero direction, tmin > tmax) and work, the traversal's work counts."""
    from rtsim import _core

    if not isinstance(scene, _core.Scene):
        raise ArgumentTypeError(
            f"scene: expected a Scene (rtsim.load_scene(...)), got {type(scene).__name__}"
        )
    return _core.trace_rays(
        scene, origins, directions, tmin, tmax, any_hit=bool_arg(any_hit, "any_hit")
    )


def write_procedural_scene(
    name: str, dir: str | os.PathLike[str], hairball_triangles: int = 200_000, seed: int = 1
) -> str:
    """Writes a built-in scene as DIR/NAME.gltf; returns the path."""
    from rtsim import _core

    return _core.write_procedural_scene(
        _name_arg(name, "name"),
        path_arg(dir, "dir"),
        hairball_triangles=int_arg(hairball_triangles, "hairball_triangles", 1, UINT32_MAX),
        seed=int_arg(seed, "seed", 0, UINT64_MAX),
    )

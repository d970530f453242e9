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

from rtsim.errors import RtsimError
from rtsim.kinds import RAY_KINDS
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

    return _core.load_scene(resolve_scene(scene), hairball_triangles=hairball_triangles, seed=seed)


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

    return scene if isinstance(scene, _core.Scene) else resolve_scene(scene)


def trace_scene(
    scene: SceneLike,
    out_dir: str | os.PathLike[str],
    workload: Sequence[str] | str | None = None,
    width: int = 320,
    height: int = 240,
    bounces: int = 1,
    seed: int = 1,
    camera: tuple[Sequence[float], Sequence[float], float] | None = None,
    threads: int = 0,
    hairball_triangles: int = 200_000,
    progress: Callable[[int, int, str], None] | None = None,
    accel: str = "bvh2",
    builder: str = "",
    flatten: bool = False,
    frames: int = 1,
    build_settings: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """Runs the reference tracer like `rtsim trace`: writes OUT/trace.rtt, manifest.json and
    render.png, and returns the manifest. workload: ray kinds ("primary,diffuse" or a list);
    None (the default) traces every kind the scene calls for (manifest["workload"]["effects"]
    says which and why). camera: (eye, target, vertical field of view in degrees). accel and
    builder choose the acceleration structure (rtsim._core.accel_kinds(), docs/accel.md; ""
    is the kind's default builder); build_settings overrides the builder's documented settings
    ({"bins": 32}; docs/accel.md, "Builder settings"; manifest["accel"]["build_settings"]
    records them all). Instanced scenes are traced through two levels (a BLAS of that kind per
    mesh, a TLAS over the instances) unless flatten is true. frames > 1 animates an instanced
    scene by the documented motion (docs/accel.md, "Frames"): the BLASes are built once, a TLAS
    per frame, and the workload is traced once per frame; manifest["frames"] lists each frame's
    rays and TLAS build time."""
    from rtsim import _core

    kinds = (
        [k.strip() for k in workload.split(",") if k.strip()]
        if isinstance(workload, str)
        else workload
    )
    return _core.trace_scene(
        _scene_arg(scene),
        os.fspath(out_dir),
        workload=None if kinds is None else list(kinds),
        width=width,
        height=height,
        bounces=bounces,
        seed=seed,
        camera=camera,
        threads=threads,
        hairball_triangles=hairball_triangles,
        progress=progress,
        accel=accel,
        builder=builder,
        flatten=flatten,
        frames=frames,
        build_settings=dict(build_settings or {}),
    )


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
    accel: str = "bvh2",
    builder: str = "",
    build_settings: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """Traces your rays with the reference tracer and writes a trace folder (OUT/trace.rtt and
    manifest.json, exactly as trace_scene writes one) that rtsim.simulate replays.

    origins, directions: (N, 3) arrays; tmin, tmax: scalars or (N,) arrays. kind: the ray kind
    of every ray ("primary", "shadow", "reflection", "diffuse", "refraction") or one per ray.
    any_hit: None makes shadow rays any-hit (occlusion) rays and the others closest-hit, as the
    tracer does; or a bool for every ray, or one per ray. accel, builder and build_settings
    choose the acceleration structure, built as trace_scene builds it. Returns the manifest;
    rays are written in order, each with its index as `pixel`."""
    import numpy as np

    from rtsim import _core

    loaded = scene if isinstance(scene, _core.Scene) else load_scene(scene)
    n = int(np.shape(origins)[0]) if np.ndim(origins) >= 1 else 0
    kinds = _kind_codes(kind, n)
    if any_hit is None:
        flags = kinds == SHADOW
    else:
        flags = np.asarray(any_hit, dtype=bool)
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
        os.fspath(out),
        threads=threads,
        accel=accel,
        builder=builder,
        build_settings=dict(build_settings or {}),
    )

"""The ``rtsim`` command line.

rtsim trace SCENE -o OUT [--workload ...] [--resolution WxH] ...   trace a scene
rtsim scene NAME -o DIR                                              write a built-in scene
rtsim scenes                                                         list scenes
rtsim demo [-o OUT]                                                  the main job: sweep + report
rtsim simulate TRACE [--config CFG] [--set k=v ...] -o RUN [--timeline]  replay on the model
rtsim config --defaults | --schema                                   the simulator's config
rtsim accuracy SCENE... [-o DIR] [--fractions 0.01,0.05]            fidelity: time against error
rtsim bench [SCENE] [--json FILE] [--repeat N]                       rtsim against Embree
rtsim bench --model TRACE [--levels L,...] [--verdict] [--json FILE] the simulator's own speed
rtsim sweep SPEC.yaml -o SWEEP [--scheduler tcp://HOST:PORT]        a design-space sweep
rtsim results SWEEP [--csv [FILE]]                                  its tidy table
rtsim report SWEEP [-o report.html]                                 its HTML report
"""

from __future__ import annotations

import argparse
import math
import os
import shutil
import subprocess
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rtsim import __version__
from rtsim.accuracy import add_parser as add_accuracy_parser
from rtsim.cli_help import HelpFormatter, LazyHelpStore
from rtsim.errors import RtsimError
from rtsim.kinds import ANYHIT_ORDERS, RAY_KINDS
from rtsim.sim_cli import add_parsers as add_simulate_parsers
from rtsim.study.cli import add_parser as add_study_parser
from rtsim.sweep.cli import add_parsers as add_sweep_parsers
from rtsim.tracing import REFLECTIONS, parse_setting_value

# Start-up matters (`rtsim simulate` runs once per simulation): modules above import only the
# standard library; rich, numpy, the C++ extension and Dask are imported by the commands.
if TYPE_CHECKING:
    from rich.console import Console

WORKLOAD_DEFAULT = (
    "every kind the scene calls for: primary and diffuse always, shadow with lights, reflection "
    "with metallic or smooth materials, refraction with transmissive ones"
)


def tracer_default(name: str) -> Any:
    """A `rtsim trace` option's default, as the tracer declares it (trace_defaults())."""
    from rtsim.tracing import trace_defaults

    return trace_defaults()[name]


def accel_kinds() -> list[dict[str, Any]]:
    """The acceleration structures of this build (name, description, builders)."""
    from rtsim import _core

    return list(_core.accel_kinds())


@dataclass
class TraceJob:
    """Everything `rtsim trace` needs; the CLI arguments, parsed and checked."""

    scene: str
    out_dir: Path
    # None: the tracer's default (rtsim.tracing.trace_defaults(), declared once in C++).
    workload: list[str] | None = None  # None: every kind the scene calls for
    width: int | None = None
    height: int | None = None
    bounces: int | None = None
    seed: int | None = None
    camera: tuple[tuple[float, float, float], tuple[float, float, float], float] | None = None
    threads: int | None = None
    hairball_triangles: int | None = None
    accel: str | None = None
    builder: str | None = None  # None: the structure's default builder (its first)
    build_settings: dict[str, Any] | None = None  # --build-set overrides
    flatten: bool | None = None  # instanced scenes: one world-space structure instead of two levels
    frames: int | None = None  # animated frames of an instanced scene (docs/accel.md, "Frames")
    frame_policy: str | None = None  # each frame's structures: rebuild, refit, adaptive
    rebuild_threshold: float | None = None  # adaptive: the SAH ratio that triggers a rebuild
    lights: str | None = None  # lights added to a scene without any (none, sun)
    reflections: str | None = None  # reflection rays: mirror or glossy (a GGX lobe)
    roulette_after: int | None = None  # Russian roulette past this many bounces (0: off)
    anyhit_order: str | None = None  # any-hit rays' child order (traversal.anyhit_order's names)
    alternatives: bool = False  # also trace the structures one step away, beside it


def parse_workload(text: str) -> list[str]:
    kinds = [k.strip().lower() for k in text.split(",") if k.strip()]
    unknown = [k for k in kinds if k not in RAY_KINDS]
    if unknown or not kinds:
        raise argparse.ArgumentTypeError(
            f"unknown ray kind(s) {', '.join(unknown) or '(none)'}; "
            f"choose from {', '.join(RAY_KINDS)}"
        )
    return kinds


MAX_PIXELS = 1 << 28  # the tracer's limit (traces/tracer/tracer.cpp)


def parse_resolution(text: str) -> tuple[int, int]:
    w, sep, h = text.lower().partition("x")
    if not sep or not w.isdigit() or not h.isdigit() or int(w) == 0 or int(h) == 0:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT like 320x240, got '{text}'")
    if int(w) * int(h) > MAX_PIXELS:
        raise argparse.ArgumentTypeError(f"{text}: more than {MAX_PIXELS} pixels")
    return int(w), int(h)


def parse_camera(text: str) -> tuple[tuple[float, float, float], tuple[float, float, float], float]:
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        values = []
    if len(values) != 7:
        raise argparse.ArgumentTypeError(
            "expected 7 numbers EX,EY,EZ,TX,TY,TZ,FOV (eye, target, field of view in degrees), "
            f"got '{text}'"
        )
    if not all(math.isfinite(v) and abs(v) <= FLOAT_MAX for v in values):
        raise argparse.ArgumentTypeError(
            f"camera numbers must be finite single-precision, got '{text}'"
        )
    ex, ey, ez, tx, ty, tz, fov = values
    if (ex, ey, ez) == (tx, ty, tz):
        raise argparse.ArgumentTypeError(
            f"camera eye equals the target (no view direction): '{text}'"
        )
    if not 0.0 < fov < 180.0:
        raise argparse.ArgumentTypeError(f"field of view must be in (0, 180) degrees, got {fov}")
    return (ex, ey, ez), (tx, ty, tz), fov


def parse_build_setting(text: str) -> tuple[str, Any]:
    """KEY=VALUE of --build-set: the value as a number or true/false when it reads as one (the
    builder checks the name, type and range, naming the setting)."""
    key, sep, value = text.partition("=")
    if not sep or not key.strip():
        raise argparse.ArgumentTypeError(f"expected KEY=VALUE, got '{text}'")
    return key.strip(), parse_setting_value(value.strip())


def positive_int(text: str) -> int:
    if not text.isdigit():
        raise argparse.ArgumentTypeError(f"expected a non-negative integer, got '{text}'")
    return int(text)


def bounded_int(low: int, high: int) -> Callable[[str], int]:
    """An argparse type: an integer in [low, high] (the C++ field's range), named in errors."""

    def parse(text: str) -> int:
        value = positive_int(text)
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"{text} is out of range ({low}..{high})")
        return value

    return parse


FLOAT_MAX = 3.4028234663852886e38
UINT32_MAX, UINT64_MAX = (1 << 32) - 1, (1 << 64) - 1
seed_int = bounded_int(0, UINT64_MAX)
hairball_int = bounded_int(1, UINT32_MAX)


def run_trace(job: TraceJob, console: Console) -> dict:
    """Traces, draws the heatmaps and prints the summary; returns the manifest."""
    from rich.console import Console

    from rtsim.heatmaps import write_heatmaps
    from rtsim.progress import TraceProgress
    from rtsim.summary import print_summary
    from rtsim.trace_file import open_trace

    with TraceProgress(console=Console(stderr=True)) as progress:
        manifest = _trace_job(job, progress)
    trace = open_trace(job.out_dir)
    width, height = manifest["workload"]["resolution"]
    heatmaps = write_heatmaps(trace, size=(width, height))
    print_summary(manifest, console)
    console.print(f"trace:    {trace.path}")
    render = job.out_dir / "render.png"
    if render.exists():
        console.print(f"render:   {render}")
    for path in heatmaps:
        console.print(f"heatmap:  {path}")
    if job.alternatives:
        trace_alternatives(job, manifest, console)
    return manifest


def _trace_job(job: TraceJob, progress: Any = None) -> dict:
    """trace_scene with the job's options: TraceJob's fields are its keyword arguments (declared
    once), less the folder's and --alternatives, which trace_scene does not take."""
    from dataclasses import fields

    from rtsim.tracing import trace_scene

    options = {f.name: getattr(job, f.name) for f in fields(job)}
    scene, out_dir = options.pop("scene"), options.pop("out_dir")
    del options["alternatives"]
    return trace_scene(scene, out_dir, progress=progress, **options)


def trace_alternatives(job: TraceJob, manifest: dict, console: Console) -> list[Path]:
    """Traces the structures one step from the trace's (rtsim._core.structure_alternatives: a
    wide BVH, compressed nodes, compressed leaves) beside it, at OUT/alternatives/KEY=VALUE:
    the same scene, workload and rays, so the verdict of every run of the trace estimates them
    with the analytic level (docs/verdict.md, "Structural estimates"). Each keeps the trace's
    leaves (compressed or not) where the other structure can store them."""
    import shutil
    from dataclasses import replace

    from rtsim import _core

    accel = manifest["accel"]
    if (manifest.get("frames") or {}).get("count", 1) > 1 or accel["kind"] == "two_level":
        console.print(
            "alternatives: none for an animated or two-level trace (the verdict measures them)"
        )
        return []
    compressed = bool(accel.get("build_settings", {}).get("compressed_leaves", False))
    scene = manifest["scene"]
    curved = scene.get("spheres", 0) + scene.get("capsules", 0) > 0
    # Alternatives of an earlier trace in this folder would be of other rays: start afresh.
    shutil.rmtree(job.out_dir / "alternatives", ignore_errors=True)
    out = []
    kinds = {k["name"]: k for k in _core.accel_kinds()}
    for key, value, folder in _core.structure_alternatives(accel["kind"], compressed, curved):
        if key == "accel":
            # The same builder and settings where the other structure takes them: one step away
            # is the structure alone (an lbvh-built bvh2 against an lbvh-built bvh8).
            other = kinds[value]
            builder = job.builder if job.builder in other["builders"] else None
            schema = other["settings"].get(builder or other["builders"][0], {})
            settings = {k: v for k, v in (job.build_settings or {}).items() if k in schema}
            if compressed:
                settings["compressed_leaves"] = True
            alt = replace(job, accel=value, builder=builder, build_settings=settings or None)
        else:
            alt = replace(job, build_settings={**(job.build_settings or {}), key: True})
        alt = replace(alt, out_dir=job.out_dir / folder, alternatives=False)
        try:
            _trace_job(alt)
        except Exception as err:  # the main trace stands; this alternative is left out
            console.print(f"alternative {folder}: not traced ({err}); the verdict measures it")
            continue
        console.print(f"alternative: {alt.out_dir / 'trace.rtt'}")
        out.append(alt.out_dir)
    return out


def cmd_trace(args: argparse.Namespace, console: Console) -> int:
    width, height = args.resolution or (None, None)
    job = TraceJob(
        scene=args.scene,
        out_dir=Path(args.output),
        workload=args.workload,
        width=width,
        height=height,
        bounces=args.bounces,
        seed=args.seed,
        camera=args.camera,
        threads=args.threads,
        hairball_triangles=args.hairball_triangles,
        accel=args.accel,
        builder=args.builder,
        build_settings=dict(args.build_set) if args.build_set else None,
        flatten=args.flatten or None,
        frames=args.frames,
        frame_policy=args.frame_policy,
        rebuild_threshold=args.rebuild_threshold,
        lights=args.lights,
        reflections=args.reflections,
        roulette_after=args.roulette_after,
        anyhit_order=args.anyhit_order,
        alternatives=args.alternatives,
    )
    run_trace(job, console)
    return 0


def cmd_scene(args: argparse.Namespace, console: Console) -> int:
    from rtsim import _core

    path = _core.write_procedural_scene(
        args.name, Path(args.output), hairball_triangles=args.hairball_triangles, seed=args.seed
    )
    console.print(f"wrote {path}")
    return 0


def cmd_scenes(args: argparse.Namespace, console: Console) -> int:
    from rtsim.scenes import list_scenes, shared_scenes_dir

    for entry in list_scenes():
        where = f"  {entry.path}" if entry.path else ""
        console.print(f"{entry.name:<28} {entry.kind}{where}", highlight=False)
    if shared_scenes_dir() is None:
        console.print("(no shared scene folder: set RTSIM_SCENES to list glTF scenes)")
    return 0


def cmd_demo(args: argparse.Namespace, console: Console) -> int:
    from rtsim.sweep.demo import run_demo

    return run_demo(Path(args.output), console, workers=args.workers, scheduler=args.scheduler)


def find_bench() -> Path | None:
    """The rtsim-bench executable: $RTSIM_BENCH, else the one installed in the package
    (rtsim/bin), else one on PATH."""
    env = os.environ.get("RTSIM_BENCH")
    if env:
        return Path(env)
    installed = Path(__file__).resolve().parent / "bin" / "rtsim-bench"
    if installed.is_file():
        return installed
    found = shutil.which("rtsim-bench")
    return Path(found) if found else None


def cmd_bench(args: argparse.Namespace, console: Console) -> int:
    if args.model:
        from rtsim.model_bench import run_model_bench

        return run_model_bench(
            [Path(t) for t in args.model],
            [lvl for lvl in args.levels.split(",") if lvl],
            args.repeat,
            args.set or [],
            Path(args.json) if args.json else None,
            console,
            Path(args.against) if args.against else None,
            verdict=args.verdict,
        )
    exe = find_bench()
    if exe is None or not exe.is_file():
        print(
            "rtsim: error: rtsim-bench is not built (it needs Embree: install libembree-dev and "
            "rebuild with RTSIM_WITH_EMBREE=ON, e.g. `bash scripts/setup.sh`)",
            file=sys.stderr,
        )
        return 2
    cmd = [str(exe)]
    if args.scene:
        from rtsim.scenes import resolve_scene

        cmd.append(resolve_scene(args.scene))
    cmd += ["--repeat", str(args.repeat)]
    if args.json:
        cmd += ["--json", str(args.json)]
    if args.resolution:
        cmd += ["--resolution", f"{args.resolution[0]}x{args.resolution[1]}"]
    if args.hairball_triangles:
        cmd += ["--hairball-triangles", str(args.hairball_triangles)]
    if args.accel:
        cmd += ["--accel", args.accel]
    if args.build_threads:
        cmd += ["--build-threads", str(args.build_threads)]
    return subprocess.run(cmd, check=False).returncode


def add_trace_parser(sub: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    p = sub.add_parser(
        "trace",
        formatter_class=HelpFormatter,
        help="trace a scene into a trace folder",
        description="Traces SCENE with the reference tracer into OUT: trace.rtt (rays, reference "
        "hits, per-ray work, the BVH image), manifest.json (scene, BVH, the effects traced and "
        "why, counts), render.png and work heatmaps.",
    )
    p.add_argument("scene", metavar="SCENE", help="glTF file, built-in or shared scene name")
    p.add_argument("-o", "--output", required=True, metavar="OUT", help="trace folder")
    p.add_argument(
        "--workload",
        type=parse_workload,
        default=None,
        metavar="KINDS",
        help=f"comma-separated ray kinds ({','.join(RAY_KINDS)}) narrowing what is traced "
        f"(default: {WORKLOAD_DEFAULT})",
    )
    p.add_argument(
        "--resolution",
        type=parse_resolution,
        action=LazyHelpStore,
        metavar="WxH",
        help_text=lambda: (
            "camera image size: one primary ray per pixel (default: "
            f"{tracer_default('width')}x{tracer_default('height')})"
        ),
    )
    p.add_argument(
        "--bounces",
        type=bounded_int(0, 64),
        action=LazyHelpStore,
        metavar="N",
        help_text=lambda: (
            "depth of diffuse, reflection and refraction bounces (default: "
            f"{tracer_default('bounces')})"
        ),
    )
    p.add_argument(
        "--seed",
        type=seed_int,
        action=LazyHelpStore,
        metavar="S",
        help_text=lambda: f"seed of the random numbers (default: {tracer_default('seed')})",
    )
    p.add_argument(
        "--camera",
        type=parse_camera,
        default=None,
        metavar="EYE,TARGET,FOV",
        help="ex,ey,ez,tx,ty,tz,fov_degrees (default: the scene's camera or a framing)",
    )
    p.add_argument(
        "--threads",
        type=bounded_int(0, 4096),
        action=LazyHelpStore,
        metavar="N",
        help_text=lambda: (
            "tracing threads, 0 for all cores (the trace is the same for any N) "
            f"(default: {tracer_default('threads')})"
        ),
    )
    p.add_argument(
        "--hairball-triangles",
        type=hairball_int,
        action=LazyHelpStore,
        metavar="N",
        help_text=lambda: (
            "triangles of the built-in hairball scene (default: "
            f"{tracer_default('hairball_triangles')})"
        ),
    )
    p.add_argument(
        "--accel",
        action=LazyHelpStore,
        metavar="KIND",
        help_text=lambda: (
            f"acceleration structure (default: {tracer_default('accel')}): "
            + "; ".join(f"{k['name']}: {k['description']}" for k in accel_kinds())
        ),
    )
    p.add_argument(
        "--builder",
        action=LazyHelpStore,
        metavar="NAME",
        help_text=lambda: (
            "builder (default: the structure's first); the structures take: "
            + "; ".join(f"{k['name']}: {', '.join(k['builders'])}" for k in accel_kinds())
        ),
    )
    p.add_argument(
        "--build-set",
        type=parse_build_setting,
        action="append",
        metavar="KEY=VALUE",
        help="override one of the builder's documented settings, e.g. --build-set bins=32 "
        "--build-set max_leaf_size=2 (repeatable; each structure's and builder's settings, "
        "defaults and ranges: docs/accel.md, Builder settings); recorded in the manifest's "
        "accel.build_settings",
    )
    p.add_argument(
        "--lights",
        choices=("none", "sun"),
        default=None,
        help="lights added to a scene without any: sun (a directional light, so shadow rays "
        "are traced; the manifest lists it) or none (default)",
    )
    p.add_argument(
        "--reflections",
        choices=REFLECTIONS,
        default=None,
        help="reflection rays off metallic and smooth surfaces: mirror (the ideal direction, "
        "default) or glossy (sampled from the GGX lobe of the material's glTF roughness; "
        "docs/ray_generation.md)",
    )
    p.add_argument(
        "--roulette-after",
        type=int,
        default=None,
        metavar="N",
        help="Russian roulette: each path ray past the first N bounces continues with the "
        "surface's albedo as probability (0, the default: off; --bounces still caps the depth)",
    )
    p.add_argument(
        "--anyhit-order",
        choices=ANYHIT_ORDERS,
        default=None,
        help="the child order any-hit (shadow) rays are traced in: nearest (default), "
        "largest_box or fixed, as traversal.anyhit_order names them; a run in the trace's order "
        "checks those rays' work exactly, and the analytic level's statistical caches take it "
        '(docs/accel.md, "Any-hit child order")',
    )
    p.add_argument(
        "--alternatives",
        action="store_true",
        help="also trace the structures one step from this one (a wide BVH, compressed nodes, "
        "compressed leaves) beside it, in OUT/alternatives/KEY=VALUE, over the same rays: every "
        "run's verdict then estimates them with the analytic level (docs/verdict.md)",
    )
    p.add_argument(
        "--flatten",
        action="store_true",
        help="instanced scenes: one world-space structure of --accel over the flattened "
        "triangles, instead of the default two levels (a BLAS of --accel per mesh, a TLAS "
        "over the instances; docs/accel.md)",
    )
    p.add_argument(
        "--frames",
        type=bounded_int(1, 1024),
        action=LazyHelpStore,
        metavar="N",
        help_text=lambda: (
            "animate an instanced or deforming scene over N frames: instances of shared "
            "geometry spin about their up axis and bob (docs/accel.md, Frames), skinned, "
            "morphed and procedural meshes deform (Moving scenes); a deforming mesh's BLAS "
            "and the TLAS follow --frame-policy and the workload is traced per frame; rtsim "
            "simulate replays the frames in order with caches warm and prices each frame's "
            f"build on the build unit (default: {tracer_default('frames')})"
        ),
    )
    p.add_argument(
        "--frame-policy",
        choices=["rebuild", "refit", "adaptive"],
        action=LazyHelpStore,
        help_text=lambda: (
            "with --frames: each frame's structures built afresh (rebuild), the first "
            "frame's refitted to the moved geometry (refit), or refitted until the refitted "
            "SAH cost exceeds --rebuild-threshold times the rebuilt one (adaptive) "
            f"(default: {tracer_default('frame_policy')})"
        ),
    )
    p.add_argument(
        "--rebuild-threshold",
        type=float,
        action=LazyHelpStore,
        metavar="RATIO",
        help_text=lambda: (
            "--frame-policy adaptive: rebuild once a refitted tree's SAH cost exceeds this "
            "ratio of its cost after the last rebuild "
            f"(default: {tracer_default('rebuild_threshold')})"
        ),
    )
    p.set_defaults(func=cmd_trace)


def add_scene_parsers(sub: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    p = sub.add_parser(
        "scene",
        formatter_class=HelpFormatter,
        help="write a built-in scene as glTF",
        description="Writes the built-in scene NAME as DIR/NAME.gltf (see rtsim scenes).",
    )
    p.add_argument("name", metavar="NAME", help="built-in scene name (cornell, hairball, ...)")
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="folder to write into")
    p.add_argument(
        "--hairball-triangles",
        type=hairball_int,
        default=200_000,
        metavar="N",
        help="triangles of the hairball scene",
    )
    p.add_argument(
        "--seed", type=seed_int, default=1, metavar="S", help="seed of the procedural scenes"
    )
    p.set_defaults(func=cmd_scene)

    p = sub.add_parser(
        "scenes",
        formatter_class=HelpFormatter,
        help="list built-in and shared scenes",
        description="Lists the built-in scenes and the glTF scenes of the shared folder "
        "($RTSIM_SCENES, else ../shared/scenes), by the names SCENE arguments accept.",
    )
    p.set_defaults(func=cmd_scenes)


def add_demo_parser(sub: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    p = sub.add_parser(
        "demo",
        formatter_class=HelpFormatter,
        help="run the main job: a small design-space sweep on two built-in scenes and its "
        "HTML report (OUT/report.html)",
        description="Sweeps python/rtsim/specs/demo.yaml into OUT and writes OUT/report.html. "
        "Running it again resumes: finished runs are kept.",
    )
    p.add_argument("-o", "--output", default="out/demo", metavar="OUT", help="sweep folder")
    p.add_argument(
        "--workers",
        type=int,
        default=0,
        metavar="N",
        help="local Dask worker processes (default: one per core)",
    )
    p.add_argument(
        "--scheduler",
        default=None,
        metavar="tcp://HOST:PORT",
        help="an existing Dask cluster (default: a local cluster)",
    )
    p.set_defaults(func=cmd_demo)


def add_bench_parser(sub: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    p = sub.add_parser(
        "bench",
        formatter_class=HelpFormatter,
        help="benchmark the reference tracer against Embree (BVH build, rays/s, one thread)",
        description="Runs rtsim-bench: BVH build time and closest-hit and any-hit rays/s of "
        "rtsim and Embree on one thread (docs/benchmarks.md).",
    )
    p.add_argument(
        "scene",
        metavar="SCENE",
        nargs="?",
        default=None,
        help="glTF file, built-in or shared scene name (default: the shared Sponza)",
    )
    p.add_argument(
        "--json", metavar="FILE", default=None, help="also write the figures as JSON (default: no)"
    )
    p.add_argument(
        "--repeat", type=positive_int, default=5, metavar="N", help="runs per figure (median)"
    )
    p.add_argument(
        "--resolution",
        type=parse_resolution,
        default=None,
        metavar="WxH",
        help="primary ray image size (default: rtsim-bench's, 640x480)",
    )
    p.add_argument(
        "--hairball-triangles",
        type=hairball_int,
        default=None,
        metavar="N",
        help="triangles of the hairball scene (default: rtsim-bench's)",
    )
    p.add_argument(
        "--accel",
        default=None,
        metavar="KIND,...",
        help="structures to benchmark, KIND or KIND:BUILDER (bvh8:sbvh); the first is 'rtsim' in "
        "the summary (default: bvh8,bvh2)",
    )
    p.add_argument(
        "--build-threads",
        type=positive_int,
        default=None,
        metavar="N",
        help="also time each structure's build on N threads: wall time and speed-up over one "
        "thread in the same run (default: one thread only)",
    )
    p.add_argument(
        "--model",
        action="append",
        metavar="TRACE",
        default=None,
        help="instead: benchmark the simulator on this trace folder (repeatable): simulated rays "
        "per second per fidelity level and their ratios (docs/benchmarks.md; default: none, the "
        "Embree comparison)",
    )
    p.add_argument(
        "--levels",
        default="functional,analytic,approx,detailed,treelets",
        metavar="LEVEL,...",
        help="with --model: levels to run (treelets: approx with treelets.enabled=true)",
    )
    p.add_argument(
        "--set",
        action="append",
        metavar="KEY=VALUE",
        default=None,
        help="with --model: config field for every run (repeatable; default: none)",
    )
    p.add_argument(
        "--against",
        metavar="RTSIM_SIM",
        default=None,
        help="with --model: also run this other rtsim-sim binary after every run (same settings) "
        "and report its CPU time, the speed-up and whether the cycles agree (default: none)",
    )
    p.add_argument(
        "--verdict",
        action="store_true",
        help="with --model: time default runs, the bottleneck verdict included (default: every "
        "run has --no-verdict, the simulation alone; the report says which)",
    )
    p.set_defaults(func=cmd_bench)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="rtsim",
        description="rtsim: a simulator of ray-tracing hardware. Trace a glTF scene with the "
        "reference tracer, replay the trace on the SystemC accelerator model (every hit checked), "
        "sweep accelerator configurations and report on them.",
        formatter_class=HelpFormatter,
        epilog="`rtsim COMMAND --help` describes each command's options and their defaults.",
    )
    parser.add_argument("--version", action="version", version=f"rtsim {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    add_trace_parser(sub)
    add_scene_parsers(sub)
    add_demo_parser(sub)
    add_simulate_parsers(sub)
    add_accuracy_parser(sub, parse_resolution)
    add_sweep_parsers(sub)
    add_study_parser(sub)
    add_bench_parser(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    from rich.console import Console

    console = Console()
    try:
        return int(args.func(args, console))
    except (RtsimError, ValueError, OSError) as err:
        print(f"rtsim: error: {err}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("rtsim: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())

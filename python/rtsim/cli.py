"""The ``rtsim`` command line.

rtsim trace SCENE -o OUT [--workload ...] [--resolution WxH] ...   trace a scene
rtsim scene NAME -o DIR                                              write a built-in scene
rtsim scenes                                                         list scenes
rtsim demo [-o OUT]                                                  the main job
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

from rich.console import Console

from rtsim import _core
from rtsim._core import RtsimError
from rtsim.heatmaps import write_heatmaps
from rtsim.progress import TraceProgress
from rtsim.scenes import list_scenes, resolve_scene, shared_scenes_dir
from rtsim.summary import print_summary
from rtsim.trace_file import open_trace

RAY_KINDS = ("primary", "shadow", "reflection", "diffuse", "refraction")
DEMO_WORKLOAD = ("primary", "shadow", "reflection", "diffuse")


@dataclass
class TraceJob:
    """Everything `rtsim trace` needs; the CLI arguments, parsed and checked."""

    scene: str
    out_dir: Path
    workload: list[str] = field(default_factory=lambda: ["primary"])
    width: int = 320
    height: int = 240
    bounces: int = 1
    seed: int = 1
    camera: tuple[tuple[float, float, float], tuple[float, float, float], float] | None = None
    threads: int = 0
    hairball_triangles: int = 200_000


def parse_workload(text: str) -> list[str]:
    kinds = [k.strip().lower() for k in text.split(",") if k.strip()]
    unknown = [k for k in kinds if k not in RAY_KINDS]
    if unknown or not kinds:
        raise argparse.ArgumentTypeError(
            f"unknown ray kind(s) {', '.join(unknown) or '(none)'}; "
            f"choose from {', '.join(RAY_KINDS)}"
        )
    return kinds


def parse_resolution(text: str) -> tuple[int, int]:
    w, sep, h = text.lower().partition("x")
    if not sep or not w.isdigit() or not h.isdigit() or int(w) == 0 or int(h) == 0:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT like 320x240, got '{text}'")
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
    ex, ey, ez, tx, ty, tz, fov = values
    if not 0.0 < fov < 180.0:
        raise argparse.ArgumentTypeError(f"field of view must be in (0, 180) degrees, got {fov}")
    return (ex, ey, ez), (tx, ty, tz), fov


def positive_int(text: str) -> int:
    if not text.isdigit():
        raise argparse.ArgumentTypeError(f"expected a non-negative integer, got '{text}'")
    return int(text)


def run_trace(job: TraceJob, console: Console) -> dict:
    """Traces, draws the heatmaps and prints the summary; returns the manifest."""
    with TraceProgress(console=Console(stderr=True)) as progress:
        manifest = _core.trace_scene(
            resolve_scene(job.scene),
            job.out_dir,
            workload=job.workload,
            width=job.width,
            height=job.height,
            bounces=job.bounces,
            seed=job.seed,
            camera=job.camera,
            threads=job.threads,
            hairball_triangles=job.hairball_triangles,
            progress=progress,
        )
    trace = open_trace(job.out_dir)
    heatmaps = write_heatmaps(trace, size=(job.width, job.height))
    print_summary(manifest, console)
    console.print(f"trace:    {trace.path}")
    render = job.out_dir / "render.png"
    if render.exists():
        console.print(f"render:   {render}")
    for path in heatmaps:
        console.print(f"heatmap:  {path}")
    return manifest


def cmd_trace(args: argparse.Namespace, console: Console) -> int:
    width, height = args.resolution
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
    )
    run_trace(job, console)
    return 0


def cmd_scene(args: argparse.Namespace, console: Console) -> int:
    path = _core.write_procedural_scene(
        args.name, Path(args.output), hairball_triangles=args.hairball_triangles, seed=args.seed
    )
    console.print(f"wrote {path}")
    return 0


def cmd_scenes(args: argparse.Namespace, console: Console) -> int:
    for entry in list_scenes():
        where = f"  {entry.path}" if entry.path else ""
        console.print(f"{entry.name:<28} {entry.kind}{where}", highlight=False)
    if shared_scenes_dir() is None:
        console.print("(no shared scene folder: set RTSIM_SCENES to list glTF scenes)")
    return 0


def cmd_demo(args: argparse.Namespace, console: Console) -> int:
    out = Path(args.output)
    console.print(f"[bold]rtsim demo[/]: tracing the built-in cornell scene into {out}")
    job = TraceJob(
        scene="cornell", out_dir=out, workload=list(DEMO_WORKLOAD), width=320, height=240
    )
    run_trace(job, console)
    console.print(
        f"\nImages are in {out.resolve()}: render.png, heatmap_nodes.png, heatmap_tris.png"
    )
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="rtsim", description=__doc__.split("\n\n")[0].strip())
    parser.add_argument("--version", action="version", version=f"rtsim {_core.__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    p = sub.add_parser("trace", help="trace a scene into a trace folder")
    p.add_argument("scene", metavar="SCENE", help="glTF file, built-in or shared scene name")
    p.add_argument("-o", "--output", required=True, metavar="OUT", help="trace folder")
    p.add_argument(
        "--workload",
        type=parse_workload,
        default=["primary"],
        help="comma-separated ray kinds: " + ",".join(RAY_KINDS),
    )
    p.add_argument("--resolution", type=parse_resolution, default=(320, 240), metavar="WxH")
    p.add_argument("--bounces", type=positive_int, default=1, metavar="N")
    p.add_argument("--seed", type=positive_int, default=1, metavar="S")
    p.add_argument(
        "--camera",
        type=parse_camera,
        default=None,
        metavar="EYE,TARGET,FOV",
        help="ex,ey,ez,tx,ty,tz,fov_degrees (default: the scene's camera or a framing)",
    )
    p.add_argument("--threads", type=positive_int, default=0, metavar="N", help="0: all cores")
    p.add_argument("--hairball-triangles", type=positive_int, default=200_000, metavar="N")
    p.set_defaults(func=cmd_trace)

    p = sub.add_parser("scene", help="write a built-in scene as glTF")
    p.add_argument("name", metavar="NAME")
    p.add_argument("-o", "--output", required=True, metavar="DIR")
    p.add_argument("--hairball-triangles", type=positive_int, default=200_000, metavar="N")
    p.add_argument("--seed", type=positive_int, default=1, metavar="S")
    p.set_defaults(func=cmd_scene)

    p = sub.add_parser("scenes", help="list built-in and shared scenes")
    p.set_defaults(func=cmd_scenes)

    p = sub.add_parser("demo", help="run the main job (trace the cornell box, draw heatmaps)")
    p.add_argument("-o", "--output", default="out/demo", metavar="OUT")
    p.set_defaults(func=cmd_demo)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
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

"""Compares acceleration structures per scene and ray kind (docs/accel.md, "Comparison").

For every scene and every structure (any registered kind: `rtsim trace --help` lists them):

- build side, from `rtsim-accel-study` (one thread, median of --repeat builds): build time,
  footprint, nodes, SAH cost, and for the wide kinds the SAH cost of the greedy collapse;
- per ray, from `rtsim trace --accel KIND` (primary and diffuse rays, shadow rays where the scene
  has lights): steps (node fetches), box tests and triangle tests, mean and p99;
- on the model at the default configuration (`rtsim-sim`): Mrays/s, DRAM bytes per ray, L1 and
  L2 hit rates, and the hit and work mismatches (must be 0);
- derived: each compressed kind's extra work over its fp32 twin of the same width (same tree:
  the difference is quantisation's), and the octant order's extra work over front-to-back.

Writes OUT/accel_study.json and OUT/accel_study.md. Usage:

    python scripts/accel_study.py --out out/accel_study \
        [--scenes sponza,bunny,hairball,teapot_stadium,rotated_walls,cornell] \
        [--accel bvh2,bvh4,bvh6,bvh8,cwbvh6,cwbvh8,bvh8_octant,cwbvh8_octant] \
        [--resolution 256x192] [--repeat 3] [--no-model]

Needs the rtsim package and `rtsim-accel-study` (installed next to `rtsim-bench`, or
$RTSIM_ACCEL_STUDY).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np

import rtsim
from rtsim.launcher import find_sim
from rtsim.scenes import resolve_scene

DEFAULT_SCENES = "sponza,bunny,hairball,teapot_stadium,rotated_walls,cornell"
DEFAULT_ACCEL = "bvh2,bvh4,bvh6,bvh8,cwbvh6,cwbvh8,bvh8_octant,cwbvh8_octant"
WORK = ("steps", "box_tests", "tri_tests")
TWINS = {"cwbvh6": "bvh6", "cwbvh8": "bvh8", "bvh8_octant": "bvh8", "cwbvh8_octant": "cwbvh8"}


def find_study() -> Path:
    env = os.environ.get("RTSIM_ACCEL_STUDY")
    if env:
        return Path(env)
    installed = Path(rtsim.__file__).resolve().parent / "bin" / "rtsim-accel-study"
    if installed.is_file():
        return installed
    found = shutil.which("rtsim-accel-study")
    if not found:
        sys.exit("accel_study: rtsim-accel-study not found (build it, or set RTSIM_ACCEL_STUDY)")
    return Path(found)


def run(cmd: list[str]) -> None:
    result = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if result.returncode != 0:
        sys.exit(f"accel_study: {' '.join(cmd)} failed:\n{result.stderr}")


def per_ray(trace_dir: Path) -> dict[str, dict[str, float]]:
    """Mean and p99 of each work count, per ray kind present in the trace."""
    trace = rtsim.open_trace(trace_dir)
    kinds = np.asarray(trace.rays["kind"])
    out: dict[str, dict[str, float]] = {}
    for code, name in enumerate(rtsim.trace_file.RAY_KINDS):
        mask = kinds == code
        if not mask.any():
            continue
        figures: dict[str, float] = {"rays": int(mask.sum())}
        for key in WORK:
            values = np.asarray(trace.work[key])[mask].astype(np.float64)
            figures[f"{key}_mean"] = float(values.mean())
            figures[f"{key}_p99"] = float(np.percentile(values, 99))
            figures[f"{key}_sum"] = float(values.sum())
        out[name] = figures
    return out


def model(trace_dir: Path, out: Path) -> dict[str, Any]:
    run([str(find_sim()), str(trace_dir), "-o", str(out)])
    s = json.loads((out / "stats.json").read_text())["summary"]
    keys = ("mrays_per_second", "dram_bytes_per_ray", "l1_hit_rate", "l2_hit_rate", "cycles")
    figures = {k: s.get(k) for k in keys}
    figures["mismatches"] = int(s["hit_mismatches"]) + int(s["work_mismatches"])
    return figures


def study_scene(scene: str, args: argparse.Namespace, out: Path) -> dict[str, Any]:
    path = resolve_scene(scene)
    build_json = out / f"{scene}_build.json"
    run(
        [
            str(find_study()),
            path,
            "--accel",
            args.accel,
            "--repeat",
            str(args.repeat),
            "--json",
            str(build_json),
        ]
    )
    result: dict[str, Any] = {"build": json.loads(build_json.read_text()), "structures": {}}
    for kind in args.accel.split(","):
        trace_dir = out / scene / kind
        run(
            [sys.executable, "-m", "rtsim", "trace", path, "-o", str(trace_dir), "--accel", kind,
             "--workload", "primary,diffuse,shadow", "--resolution", args.resolution,
             "--bounces", "1"]
        )  # fmt: skip
        entry: dict[str, Any] = {"rays": per_ray(trace_dir)}
        if not args.no_model:
            entry["model"] = model(trace_dir, out / scene / f"{kind}_run")
        result["structures"][kind] = entry
        if not args.keep_traces:
            (trace_dir / "trace.rtt").unlink(missing_ok=True)
    return result


def extra_work(result: dict[str, Any]) -> dict[str, dict[str, dict[str, float]]]:
    """Per derived kind, per ray kind: percent more steps/box/triangle tests than its twin."""
    out: dict[str, dict[str, dict[str, float]]] = {}
    s = result["structures"]
    for kind, twin in TWINS.items():
        if kind not in s or twin not in s:
            continue
        out[kind] = {}
        for ray_kind, ours in s[kind]["rays"].items():
            theirs = s[twin]["rays"][ray_kind]
            out[kind][ray_kind] = {
                key: 100.0 * (ours[f"{key}_sum"] / theirs[f"{key}_sum"] - 1.0)
                if theirs[f"{key}_sum"]
                else 0.0
                for key in WORK
            }
    return out


def fmt(x: Any, digits: int = 1) -> str:
    if x is None:
        return "-"
    if isinstance(x, float):
        return f"{x:,.{digits}f}"
    return f"{x:,}"


def markdown(scene: str, result: dict[str, Any]) -> str:
    b = result["build"]
    lines = [f"### {scene} ({b['triangles']:,} triangles)", ""]
    bvh2 = b["structures"].get("bvh2", {}).get("footprint_bytes")
    bvh2_nodes = b["structures"].get("bvh2", {}).get("node_region_bytes")
    lines += [
        "| structure | build ms | footprint MB | vs bvh2 | node region MB | vs bvh2 | nodes "
        "| node B | SAH | SAH greedy |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for kind, s in b["structures"].items():
        ratio = f"{s['footprint_bytes'] / bvh2:.2f}" if bvh2 else "-"
        node_ratio = f"{s['node_region_bytes'] / bvh2_nodes:.2f}" if bvh2_nodes else "-"
        lines.append(
            f"| {kind} | {fmt(s['build_ms_cpu'])} | {s['footprint_bytes'] / 1e6:.2f} | {ratio} "
            f"| {s['node_region_bytes'] / 1e6:.2f} | {node_ratio} "
            f"| {s['nodes']:,} | {s['node_bytes']} | {s['sah_cost']:.2f} "
            f"| {fmt(s.get('sah_cost_greedy'), 2)} |"
        )
    lines += [
        "",
        "| structure | rays | steps mean / p99 | box tests mean / p99 | tri tests mean / p99 "
        "| model Mrays/s | DRAM B/ray | L1 hit | L2 hit |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for kind, s in result["structures"].items():
        m = s.get("model", {})
        first = True
        for ray_kind, r in s["rays"].items():
            work = " | ".join(f"{r[f'{k}_mean']:.1f} / {r[f'{k}_p99']:.0f}" for k in WORK)
            model_cols = (
                f"{fmt(m.get('mrays_per_second'), 1)} | {fmt(m.get('dram_bytes_per_ray'), 0)} | "
                f"{fmt(m.get('l1_hit_rate'), 3)} | {fmt(m.get('l2_hit_rate'), 3)}"
                if first and m
                else " | | | "
            )
            lines.append(f"| {kind if first else ''} | {ray_kind} | {work} | {model_cols} |")
            first = False
    extra = extra_work(result)
    if extra:
        lines += [
            "",
            "| structure | vs | rays | steps | box tests | tri tests |",
            "|---|---|---|---:|---:|---:|",
        ]
        for kind, per in extra.items():
            for ray_kind, e in per.items():
                cols = " | ".join(f"{e[k]:+.1f}%" for k in WORK)
                lines.append(f"| {kind} | {TWINS[kind]} | {ray_kind} | {cols} |")
    return "\n".join(lines) + "\n"


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--out", required=True, type=Path)
    p.add_argument("--scenes", default=DEFAULT_SCENES)
    p.add_argument("--accel", default=DEFAULT_ACCEL)
    p.add_argument("--resolution", default="256x192")
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--no-model", action="store_true", help="skip the rtsim-sim runs")
    p.add_argument("--keep-traces", action="store_true", help="keep the trace files")
    p.add_argument("--render", action="store_true", help="only rewrite the tables from OUT's JSON")
    args = p.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    results: dict[str, Any] = {}
    md = [
        "## Comparison",
        "",
        f"Command: `python scripts/accel_study.py {' '.join(sys.argv[1:])}`",
        "",
    ]
    if args.render:
        results = json.loads((args.out / "accel_study.json").read_text())
        md += [markdown(scene, result) for scene, result in results.items()]
        (args.out / "accel_study.md").write_text("\n".join(md))
        print("\n".join(md))
        return 0
    for scene in args.scenes.split(","):
        print(f"accel_study: {scene}", file=sys.stderr)
        results[scene] = study_scene(scene, args, args.out)
        results[scene]["extra_work_percent"] = extra_work(results[scene])
        md.append(markdown(scene, results[scene]))
        (args.out / "accel_study.json").write_text(json.dumps(results, indent=2) + "\n")
    (args.out / "accel_study.md").write_text("\n".join(md))
    print("\n".join(md))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

#!/usr/bin/env python3
# ruff: noqa: E501  (the Markdown tables' header rows are written as one line each)
"""The frame study behind docs/shading.md: traces Sponza (stand-in textures, from $RTSIM_SCENES),
the hairball and the Cornell box with 1-3 bounces, simulates each with shading.enabled on the
default machine, and writes the page's tables (between its `shading-study` markers) and figures.

    python scripts/shading_study.py [--out DIR] [--resolution 160x120]   # minutes on 2 cores

Every number on the page comes from a run of this script; it says the command, date and time.
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import os
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
DOC = REPO / "docs" / "shading.md"
SCENES = {"sponza": [], "hairball": ["--hairball-triangles", "200000"], "cornell": []}
REORDERS = ("none", "shader", "material", "material_direction")


def run(cmd: list[str]) -> None:
    result = subprocess.run(cmd, capture_output=True, text=True)
    if result.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{result.stderr}")


def trace(out: Path, scene: str, bounces: int, resolution: str, accel: str = "bvh2") -> Path:
    folder = out / f"{scene}-b{bounces}-{accel}"
    if not (folder / "manifest.json").exists():
        run(["rtsim", "trace", scene, "-o", str(folder), "--resolution", resolution,
             "--bounces", str(bounces), "--accel", accel, *SCENES[scene]])  # fmt: skip
    return folder


def simulate(out: Path, trace_dir: Path, name: str, *sets: str) -> dict:
    run_dir = out / "runs" / f"{trace_dir.name}-{name}"
    stats = run_dir / "stats.json"
    if not stats.exists():
        run(["rtsim-sim", str(trace_dir / "trace.rtt"), "-o", str(run_dir),
             *[x for s in sets for x in ("--set", s)]])  # fmt: skip
    return json.loads(stats.read_text())


def frame_row(stats: dict) -> dict:
    sh = stats["model"]["shading"]
    b, f = sh["breakdown"], sh["frame_cycles"]
    return {
        "rays": stats["summary"]["rays"],
        "frame_us": f / 1e3,
        "raygen": b["raygen"] / f,
        "traversal": b["traversal"] / f,
        "reorder": b["reorder"] / f,
        "shading": b["shading"] / f,
        "share": sh["shading_share"],
        "x2": sh["amdahl"]["speedup_2x_rt"],
        "divergence": sh["divergence"],
        "simd": sh["simd_efficiency"],
        "tex_hit": sh["tex_hit_rate"],
        "mrays": stats["summary"]["mrays_per_second"],
        "texel_mismatches": stats["validation"]["texel_mismatches"],
        "tex_dram_per_ray": stats["model"]
        .get("dram", {})
        .get("by_kind", {})
        .get("texture", {})
        .get("read_bytes", 0)
        / max(1, stats["summary"]["rays"]),
    }


def pct(x: float | None) -> str:
    return "-" if x is None else f"{100 * x:.1f}%"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=REPO / "out" / "shading_study")
    ap.add_argument("--resolution", default="160x120")
    args = ap.parse_args()
    out: Path = args.out
    out.mkdir(parents=True, exist_ok=True)
    on = ["shading.enabled=true"]

    # 1. Shading share per scene and bounce depth (wavefront loop, no reordering).
    share_rows = []
    for scene in SCENES:
        for bounces in (1, 2, 3):
            t = trace(out, scene, bounces, args.resolution)
            share_rows.append((scene, bounces, frame_row(simulate(out, t, "base", *on))))
    # 2. Reordering and the frame loop, two bounces.
    reorder_rows = []
    for scene in SCENES:
        t = trace(out, scene, 2, args.resolution)
        for loop in ("wavefront", "inflight"):
            for r in REORDERS:
                stats = simulate(
                    out, t, f"{loop}-{r}", *on, f"shading.frame_loop={loop}", f"shading.reorder={r}"
                )
                reorder_rows.append((scene, loop, r, frame_row(stats)))
    # 3. What a better structure buys traversal and the frame (Sponza, two bounces).
    accel_rows = []
    for accel in ("bvh2", "cwbvh8"):
        t = trace(out, "sponza", 2, args.resolution, accel)
        rt = simulate(out, t, "rt-only")
        frame = frame_row(simulate(out, t, "base", *on))
        accel_rows.append((accel, rt["summary"]["mrays_per_second"], frame))
    # Treelets do not run with the frame loop (docs/capabilities.md): their traversal speed-up is
    # measured RT-only and carried to the frame with the Amdahl view of the bvh2 frame.
    t = trace(out, "hairball", 2, args.resolution)
    plain = simulate(out, t, "rt-only")["summary"]["mrays_per_second"]
    treelets = simulate(out, t, "rt-treelets", "treelets.enabled=true")["summary"][
        "mrays_per_second"
    ]
    hair_frame = frame_row(simulate(out, t, "base", *on))

    # 4. What it takes to reach the source's 50%: fewer shader cores, longer shaders (Sponza).
    t = trace(out, "sponza", 2, args.resolution)
    sens_rows = []
    for cores in (8, 2):
        for base in (120, 480, 1200):
            stats = simulate(
                out,
                t,
                f"cores{cores}-base{base}",
                *on,
                f"shading.cores={cores}",
                f"shading.cost.hit_base={base}",
            )
            sens_rows.append((cores, base, frame_row(stats), stats["model"]["shading"]))

    lines = [
        f"Generated by `python scripts/shading_study.py --resolution {args.resolution}` on "
        f"{dt.datetime.now(dt.timezone.utc):%Y-%m-%d %H:%M} UTC; default machine "
        "(8 traversal units, 8 shader cores of 32 lanes), primary plus N bounces.",
        "",
        "#### Where the frame goes",
        "",
        "| scene | bounces | rays | frame (us) | raygen | traversal | reorder | shading | shading share | frame x of a 2x RT unit | texture DRAM B/ray | texel mismatches |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for scene, bounces, r in share_rows:
        lines.append(
            f"| {scene} | {bounces} | {r['rays']:,} | {r['frame_us']:.1f} | {pct(r['raygen'])} | "
            f"{pct(r['traversal'])} | {pct(r['reorder'])} | {pct(r['shading'])} | {pct(r['share'])} | "
            f"{r['x2']:.2f} | {r['tex_dram_per_ray']:.1f} | {r['texel_mismatches']} |"
        )
    lines += [
        "",
        "#### Reordering before shading and the frame loop (two bounces)",
        "",
        "| scene | loop | reorder | frame (us) | divergence (programs/warp) | SIMD efficiency | texture hit rate | frame vs none |",
        "|---|---|---|---:|---:|---:|---:|---:|",
    ]
    base = {(s, lp): r["frame_us"] for s, lp, o, r in reorder_rows if o == "none"}
    for scene, loop, r_, r in reorder_rows:
        lines.append(
            f"| {scene} | {loop} | {r_} | {r['frame_us']:.1f} | {r['divergence']:.2f} | {pct(r['simd'])} | "
            f"{pct(r['tex_hit'])} | {base[(scene, loop)] / r['frame_us']:.3f}x |"
        )
    lines += [
        "",
        "#### What traversal speed-ups buy the frame (two bounces)",
        "",
        "| change | scene | traversal (RT-only Mrays/s) speed-up | frame speed-up |",
        "|---|---|---:|---:|",
    ]
    (_, mr0, f0), (_, mr1, f1) = accel_rows
    lines.append(
        f"| bvh2 -> cwbvh8 | sponza | {mr1 / mr0:.3f}x | {f0['frame_us'] / f1['frame_us']:.3f}x (measured) |"
    )
    k = treelets / plain
    s = 1.0 - hair_frame["share"]
    lines.append(
        f"| treelets on | hairball | {k:.3f}x | {1 / (1 - s + s / k):.3f}x (Amdahl estimate, traversal share {pct(s)}) |"
    )
    lines += [
        "",
        "#### What it takes to reach the source's 50% (Sponza, two bounces, wavefront, no reordering)",
        "",
        "| shader cores | hit_base (instructions) | frame (us) | shading share | frame x of a 2x RT unit | frame x of an infinitely fast RT unit | sorting by shader then |",
        "|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for cores, base, r, sh in sens_rows:
        sorted_stats = simulate(
            out,
            t,
            f"cores{cores}-base{base}-shader",
            *on,
            f"shading.cores={cores}",
            f"shading.cost.hit_base={base}",
            "shading.reorder=shader",
        )
        gain = r["frame_us"] / (sorted_stats["model"]["shading"]["frame_cycles"] / 1e3)
        lines.append(
            f"| {cores} | {base} | {r['frame_us']:.1f} | {pct(r['share'])} | {r['x2']:.2f} | "
            f"{sh['amdahl']['speedup_infinite_rt']:.2f} | {gain:.3f}x |"
        )
    text = "\n".join(lines) + "\n"
    begin, end = "<!-- shading-study:begin -->", "<!-- shading-study:end -->"
    doc = DOC.read_text()
    head, rest = doc.split(begin, 1)
    DOC.write_text(head + begin + "\n" + text + end + rest.split(end, 1)[1])
    (out / "study.json").write_text(
        json.dumps({"share": share_rows, "reorder": reorder_rows}, indent=1)
    )
    figures(share_rows, reorder_rows)
    print(text)


def figures(share_rows: list, reorder_rows: list) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    labels = [f"{s}\n{b}b" for s, b, _ in share_rows]
    bottom = [0.0] * len(share_rows)
    for part, colour in (
        ("raygen", "#999"),
        ("traversal", "#4477aa"),
        ("reorder", "#ccbb44"),
        ("shading", "#ee6677"),
    ):
        vals = [r[part] for _, _, r in share_rows]
        axes[0].bar(labels, vals, bottom=bottom, label=part, color=colour)
        bottom = [a + b for a, b in zip(bottom, vals, strict=True)]
    axes[0].axhline(0.5, color="k", ls="--", lw=1)
    axes[0].text(0, 0.52, 'source: shading "at least 50%"', fontsize=8)
    axes[0].set_ylabel("fraction of frame time")
    axes[0].set_title("where the frame goes (wavefront loop)")
    axes[0].legend(fontsize=8)
    axes[0].tick_params(axis="x", labelsize=7)
    scenes = list(dict.fromkeys(s for s, _, _, _ in reorder_rows))
    width = 0.2
    for i, order in enumerate(REORDERS):
        vals = [
            next(
                r["simd"]
                for s, lp, o, r in reorder_rows
                if s == sc and lp == "wavefront" and o == order
            )
            for sc in scenes
        ]
        axes[1].bar([j + i * width for j in range(len(scenes))], vals, width, label=order)
    axes[1].axhline(0.9, color="k", ls="--", lw=1)
    axes[1].text(-0.1, 0.92, "Afra et al. 2016: ~90% with stream sorting", fontsize=8)
    axes[1].set_xticks([j + 1.5 * width for j in range(len(scenes))], scenes)
    axes[1].set_ylabel("shader SIMD efficiency")
    axes[1].set_ylim(0, 1.05)
    axes[1].set_title("reordering before shading (two bounces)")
    axes[1].legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    fig.savefig(REPO / "docs" / "shading.png", dpi=110)


if __name__ == "__main__":
    os.environ.setdefault("RTSIM_SCENES", str(REPO.parent / "shared" / "scenes"))
    main()

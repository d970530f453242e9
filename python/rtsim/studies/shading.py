"""The frame study behind docs/shading.md: Sponza (stand-in textures, from $RTSIM_SCENES), the
hairball and the Cornell box with 1-3 bounces, each simulated with `shading.enabled` on the
default machine (8 traversal units, 8 shader cores of 32 lanes): where the frame goes, what
reordering before shading and the in-flight frame loop buy, what a better structure and treelets
buy the frame, and what it takes to reach the source's 50% shading share. Tables between the
`shading-study` markers of docs/shading.md; figure docs/shading.png."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from rtsim.study import Figure, Study, StudyRun, Table
from rtsim.study.tables import pyplot, scene
from rtsim.sweep.store import RunRecord

SCENES = ["sponza", "hairball", "cornell"]
REORDERS = ("none", "shader", "material", "material_direction")
LOOPS = ("wavefront", "inflight")
ON = {"shading.enabled": True}


def _spec(name: str, sc: str, o: dict[str, Any], bounces: list[int], points: list, accel="bvh2"):
    return {
        "name": name,
        "scenes": [scene(sc, o["hairball_triangles"])],
        "workloads": [
            {"name": f"b{b}", "resolution": o["resolution"], "bounces": b} for b in bounces
        ],
        "accel": [accel],
        "points": points,
    }


def specs(o: dict[str, Any]) -> list[dict[str, Any]]:
    """Five parts: share (1-3 bounces), reorder (loops x orders), accel (bvh2, cwbvh8 RT-only
    and framed), treelets (RT-only, hairball) and sensitivity (shader cores x shader length)."""
    base = [{"label": "base", "set": ON}]
    rt = {"label": "rt-only", "set": {}}
    out = [_spec(f"share-{s}", s, o, [1, 2, 3], base) for s in SCENES]
    reorder = [
        {"label": f"{lp}|{r}", "set": {**ON, "shading.frame_loop": lp, "shading.reorder": r}}
        for lp in LOOPS
        for r in REORDERS
    ]
    out += [_spec(f"reorder-{s}", s, o, [2], reorder) for s in SCENES]
    out += [_spec(f"accel-{a}", "sponza", o, [2], [rt, *base], a) for a in ("bvh2", "cwbvh8")]
    treelets = {"label": "rt-treelets", "set": {"treelets.enabled": True}}
    out.append(_spec("treelets", "hairball", o, [2], [rt, treelets, *base]))
    sens = [
        {
            "label": f"{cores}|{hit}|{order}",
            "set": {
                **ON,
                "shading.cores": cores,
                "shading.cost.hit_base": hit,
                **({"shading.reorder": order} if order != "none" else {}),
            },
        }
        for cores in (8, 2)
        for hit in (120, 480, 1200)
        for order in ("none", "shader")
    ]
    out.append(_spec("sensitivity", "sponza", o, [2], sens))
    return out


def texture_dram_per_ray(rec: RunRecord) -> float:
    dram = ((rec.stats or {}).get("model") or {}).get("dram", {}).get("by_kind", {})
    return dram.get("texture", {}).get("read_bytes", 0) / max(1, int(rec.summary.get("rays") or 1))


def frame(r: dict[str, Any]) -> dict[str, Any]:
    """A framed run's figures: the frame's time and its parts, the shading share and more."""
    sh = r["shading"]
    b, f = sh["breakdown"], sh["frame_cycles"]
    return {
        "rays": r["rays"],
        "frame_us": f / 1e3,
        **{k: b[k] / f for k in ("raygen", "traversal", "reorder", "shading")},
        "share": sh["shading_share"],
        "x2": sh["amdahl"]["speedup_2x_rt"],
        "xinf": sh["amdahl"]["speedup_infinite_rt"],
        "divergence": sh["divergence"],
        "simd": sh["simd_efficiency"],
        "tex_hit": sh["tex_hit_rate"],
        "tex_dram_per_ray": r["texture_dram_per_ray"],
        "texel_mismatches": r["texel_mismatches"],
    }


def pct(x: float | None) -> str:
    return "-" if x is None else f"{100 * x:.1f}%"


def share_rows(run: StudyRun) -> list[tuple[str, int, dict[str, Any]]]:
    return [
        (s, int(r["workload"][1:]), frame(r)) for s in SCENES for r in run.rows(part=f"share-{s}")
    ]


def reorder_rows(run: StudyRun) -> list[tuple[str, str, str, dict[str, Any]]]:
    return [
        (s, *r["point"].split("|"), frame(r)) for s in SCENES for r in run.rows(part=f"reorder-{s}")
    ]


def _frame_part(run: StudyRun) -> list[str]:
    lines = [
        "#### Where the frame goes",
        "",
        "| scene | bounces | rays | frame (us) | raygen | traversal | reorder | shading | "
        "shading share | frame x of a 2x RT unit | texture DRAM B/ray | texel mismatches |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for s, bounces, r in share_rows(run):
        lines.append(
            f"| {s} | {bounces} | {r['rays']:,} | {r['frame_us']:.1f} | {pct(r['raygen'])} | "
            f"{pct(r['traversal'])} | {pct(r['reorder'])} | {pct(r['shading'])} | "
            f"{pct(r['share'])} | {r['x2']:.2f} | {r['tex_dram_per_ray']:.1f} | "
            f"{r['texel_mismatches']} |"
        )
    lines += [
        "",
        "#### Reordering before shading and the frame loop (two bounces)",
        "",
        "| scene | loop | reorder | frame (us) | divergence (programs/warp) | SIMD efficiency | "
        "texture hit rate | frame vs none |",
        "|---|---|---|---:|---:|---:|---:|---:|",
    ]
    rows = reorder_rows(run)
    base = {(s, lp): r["frame_us"] for s, lp, o, r in rows if o == "none"}
    for s, loop, order, r in rows:
        lines.append(
            f"| {s} | {loop} | {order} | {r['frame_us']:.1f} | {r['divergence']:.2f} | "
            f"{pct(r['simd'])} | {pct(r['tex_hit'])} | {base[(s, loop)] / r['frame_us']:.3f}x |"
        )
    return lines


def _speedup_part(run: StudyRun) -> list[str]:
    lines = [
        "",
        "#### What traversal speed-ups buy the frame (two bounces)",
        "",
        "| change | scene | traversal (RT-only Mrays/s) speed-up | frame speed-up |",
        "|---|---|---:|---:|",
    ]
    accels = ("bvh2", "cwbvh8")
    mr = {a: run.row(part=f"accel-{a}", point="rt-only")["mrays_per_second"] for a in accels}
    fr = {a: frame(run.row(part=f"accel-{a}", point="base")) for a in accels}
    lines.append(
        f"| bvh2 -> cwbvh8 | sponza | {mr['cwbvh8'] / mr['bvh2']:.3f}x | "
        f"{fr['bvh2']['frame_us'] / fr['cwbvh8']['frame_us']:.3f}x (measured) |"
    )
    plain = run.row(part="treelets", point="rt-only")["mrays_per_second"]
    k = run.row(part="treelets", point="rt-treelets")["mrays_per_second"] / plain
    # Treelets do not run with the frame loop (docs/capabilities.md): their traversal speed-up
    # is carried to the frame with the Amdahl view of the bvh2 frame.
    s = 1.0 - frame(run.row(part="treelets", point="base"))["share"]
    lines.append(
        f"| treelets on | hairball | {k:.3f}x | {1 / (1 - s + s / k):.3f}x (Amdahl estimate, "
        f"traversal share {pct(s)}) |"
    )
    lines += [
        "",
        "#### What it takes to reach the source's 50% (Sponza, two bounces, wavefront, no "
        "reordering)",
        "",
        "| shader cores | hit_base (instructions) | frame (us) | shading share | frame x of a 2x "
        "RT unit | frame x of an infinitely fast RT unit | sorting by shader then |",
        "|---:|---:|---:|---:|---:|---:|---:|",
    ]
    by = {r["point"]: frame(r) for r in run.rows(part="sensitivity")}
    for cores in (8, 2):
        for hit in (120, 480, 1200):
            r, sorted_ = by[f"{cores}|{hit}|none"], by[f"{cores}|{hit}|shader"]
            lines.append(
                f"| {cores} | {hit} | {r['frame_us']:.1f} | {pct(r['share'])} | {r['x2']:.2f} | "
                f"{r['xinf']:.2f} | {r['frame_us'] / sorted_['frame_us']:.3f}x |"
            )
    return lines


def table(run: StudyRun) -> str:
    m = run.measured()
    head = [
        f"Generated by `{run.command}` on {m['date']} (rtsim-sim git {m['git']}); default machine "
        "(8 traversal units, 8 shader cores of 32 lanes), primary plus N bounces.",
        "",
    ]
    return "\n".join(head + _frame_part(run) + _speedup_part(run)) + "\n"


def plot(run: StudyRun, path: Path) -> None:
    plt = pyplot()
    shares, reorders = share_rows(run), reorder_rows(run)
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    labels = [f"{s}\n{b}b" for s, b, _ in shares]
    bottom = [0.0] * len(shares)
    parts = (("raygen", "#999"), ("traversal", "#4477aa"), ("reorder", "#ccbb44"),
             ("shading", "#ee6677"))  # fmt: skip
    for part, colour in parts:
        vals = [r[part] for _, _, r in shares]
        axes[0].bar(labels, vals, bottom=bottom, label=part, color=colour)
        bottom = [a + b for a, b in zip(bottom, vals, strict=True)]
    axes[0].axhline(0.5, color="k", ls="--", lw=1)
    axes[0].text(0, 0.52, 'source: shading "at least 50%"', fontsize=8)
    axes[0].set_ylabel("fraction of frame time")
    axes[0].set_title("where the frame goes (wavefront loop)")
    axes[0].legend(fontsize=8)
    axes[0].tick_params(axis="x", labelsize=7)
    width = 0.2
    for i, order in enumerate(REORDERS):
        simd = {s: r["simd"] for s, lp, o, r in reorders if lp == "wavefront" and o == order}
        xs = [j + i * width for j in range(len(SCENES))]
        axes[1].bar(xs, [simd[s] for s in SCENES], width, label=order)
    axes[1].axhline(0.9, color="k", ls="--", lw=1)
    axes[1].text(-0.1, 0.92, "Afra et al. 2016: ~90% with stream sorting", fontsize=8)
    axes[1].set_xticks([j + 1.5 * width for j in range(len(SCENES))], SCENES)
    axes[1].set_ylabel("shader SIMD efficiency")
    axes[1].set_ylim(0, 1.05)
    axes[1].set_title("reordering before shading (two bounces)")
    axes[1].legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


STUDY = Study(
    name="shading",
    about="shading in the frame: its share, reordering before shading, what traversal buys",
    specs=specs,
    tables=[Table("shading.md", "shading-study", table)],
    figures=[Figure("shading.png", plot)],
    # The documented run (docs/shading.md).
    options={"resolution": "160x120", "hairball_triangles": 200_000},
    # 32x24: at 16x12 the in-flight loop ends early on Cornell (rtsim-sim: 253 of 1013 rays).
    quick={"resolution": "32x24", "hairball_triangles": 5_000},
    extra={
        "shading": "model.shading",
        "texel_mismatches": "validation.texel_mismatches",
        "texture_dram_per_ray": texture_dram_per_ray,
    },
)

"""The frame in `rtsim simulate`'s summary (docs/shading.md): frame time and where it went, the
shading share beside the source text's "at least 50%", the Amdahl view of a faster RT unit,
the shader cores' divergence and texture traffic, and energy per frame."""

from __future__ import annotations

from typing import Any

from rich.table import Table

from rtsim.sim_summary import _get, _is_num, _two_column, fmt_float, fmt_int, fmt_pct

BREAKDOWN = ("raygen", "build", "traversal", "reorder", "shading")


def frame_energy_mj(stats: dict[str, Any]) -> float | None:
    """RT unit and memory energy (energy per ray x rays) plus the shader cores', in mJ."""
    per_ray = _get(stats, "summary.energy_per_ray_nj")
    rays = _get(stats, "summary.rays")
    cores = _get(stats, "model.shading.energy_pj")
    if not (_is_num(per_ray) and _is_num(rays) and _is_num(cores)):
        return None
    return (per_ray * rays * 1e3 + cores) * 1e-9


def frame_table(stats: dict[str, Any]) -> Table:
    sh = _get(stats, "model.shading") or {}
    frame = sh.get("frame_cycles")
    table = _two_column(
        f"frame ({sh.get('frame_loop')} loop, reorder {sh.get('reorder')}; docs/shading.md)"
    )
    table.add_row("frame time (ms)", fmt_float(sh.get("frame_ms"), 3))
    table.add_row("frame cycles", fmt_int(frame))
    breakdown = sh.get("breakdown") or {}
    for part in BREAKDOWN:
        value = breakdown.get(part)
        if part == "build" and not value:
            continue  # only a moving scene's frame loop waits for builds
        share = value / frame if _is_num(value) and _is_num(frame) and frame else None
        table.add_row(f"  {part}", f"{fmt_int(value)} ({fmt_pct(share)})")
    stalls = sh.get("stalls") or {}
    if stalls:
        table.add_row(
            "stalls: RT unit on shading / cores on traversal / texture-bound shading",
            " / ".join(
                fmt_int(stalls.get(k))
                for k in (
                    "rt_waits_for_shading",
                    "cores_wait_for_traversal",
                    "shading_texture_bound",
                )
            ),
        )
    table.add_row(
        "shading share (all but traversal)",
        f"{fmt_pct(sh.get('shading_share'))} (source text: at least 50%)",
    )
    amdahl = sh.get("amdahl") or {}
    table.add_row("frame speed-up of a 2x RT unit", fmt_float(amdahl.get("speedup_2x_rt"), 3))
    table.add_row(
        "frame speed-up of an infinitely fast RT unit",
        fmt_float(amdahl.get("speedup_infinite_rt"), 3),
    )
    table.add_row(
        "warps / divergence (programs per warp)",
        f"{fmt_int(sh.get('warps'))} / {fmt_float(sh.get('divergence'), 2)}",
    )
    table.add_row("shader SIMD efficiency", fmt_pct(sh.get("simd_efficiency")))
    table.add_row("shader core issue utilisation", fmt_pct(sh.get("core_utilization")))
    table.add_row("texture model", str(sh.get("texture_model")))
    if sh.get("tex_hit_rate") is not None:
        table.add_row(
            "texture samples / cache hit rate",
            f"{fmt_int(sh.get('texture_samples'))} / {fmt_pct(sh.get('tex_hit_rate'))}",
        )
        tex_dram = _get(stats, "model.dram.by_kind.texture.read_bytes")
        rays = _get(stats, "summary.rays")
        if _is_num(tex_dram) and _is_num(rays) and rays:
            table.add_row("texture DRAM bytes / ray", fmt_float(tex_dram / rays, 1))
    for k in (_get(stats, "verdict.frame") or [])[:3]:
        table.add_row(
            f"  frame knob: --set {k.get('key')}={k.get('to')} (now {k.get('from')})",
            f"{fmt_float(k.get('frame_speedup'), 3)}x frame ({k.get('part')} "
            f"{fmt_float(k.get('part_speedup'), 2)}x)",
        )
    table.add_row("texel mismatches", fmt_int(sh.get("texel_mismatches")))
    table.add_row("energy / frame (mJ)", fmt_float(frame_energy_mj(stats), 4))
    return table

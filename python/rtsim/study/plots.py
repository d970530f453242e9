"""Figures several studies draw, as functions of their rows (plain dicts of the DataFrame)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from rtsim.study.tables import pyplot


def bars_against_mimd(
    rows: list[dict[str, Any]], path: Path, title: str, efficiency_title: str
) -> None:
    """Bars per `trace` and `config`: Mrays/s over the `MIMD` row's of the same trace (top) and,
    for configurations that report it, SIMD efficiency (bottom)."""
    plt = pyplot()
    traces = list(dict.fromkeys(r["trace"] for r in rows))
    configs = list(dict.fromkeys(r["config"] for r in rows))
    base = {r["trace"]: r["mrays_per_second"] for r in rows if r["config"] == "MIMD"}
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(9.5, 7.0), sharex=True)
    width = 0.8 / len(configs)
    colors = plt.get_cmap("tab10")
    for i, cfg in enumerate(configs):
        xs = [t + (i - (len(configs) - 1) / 2) * width for t in range(len(traces))]
        by = {r["trace"]: r for r in rows if r["config"] == cfg}
        top.bar(
            xs,
            [by[t]["mrays_per_second"] / base[t] for t in traces],
            width,
            label=cfg,
            color=colors(i),
        )
        if by[traces[0]].get("simd_efficiency") is not None and cfg != "MIMD":
            bottom.bar(xs, [by[t]["simd_efficiency"] for t in traces], width, color=colors(i))
    top.axhline(1.0, color="black", linewidth=0.8)
    top.set_ylabel("Mrays/s / MIMD's")
    top.set_title(title)
    ymax = max(r["mrays_per_second"] / base[r["trace"]] for r in rows)
    top.set_ylim(0, max(1.45, ymax * 1.35))  # room for the legend above the bars
    top.legend(ncol=4, fontsize=8, loc="upper center")
    bottom.set_ylabel("SIMD efficiency")
    bottom.set_ylim(0, 1)
    bottom.set_xticks(range(len(traces)))
    bottom.set_xticklabels(traces, fontsize=8)
    bottom.set_title(efficiency_title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)

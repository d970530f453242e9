"""Heatmaps of traversal work per pixel, drawn from a trace folder.

Each figure has two panels: the work of primary rays alone, and the work of every ray that
descends from the pixel (shadow, reflection, diffuse, ... rays carry their pixel). The trace is
read in chunks of its memory maps, so memory stays bounded whatever the ray count.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from rtsim.manifest import image_size
from rtsim.trace_file import Trace

CHUNK_RAYS = 1 << 20
PRIMARY = 0


@dataclass(frozen=True)
class PixelWork:
    """Per-pixel sums of one work counter: over primary rays and over all rays, (H, W)."""

    counter: str
    primary: np.ndarray
    all_rays: np.ndarray


def pixel_work(trace: Trace, width: int, height: int, counters: tuple[str, ...]) -> list[PixelWork]:
    """Sums each work counter per pixel with np.bincount, chunk by chunk."""
    pixels = width * height
    sums = {c: (np.zeros(pixels), np.zeros(pixels)) for c in counters}
    rays, work = trace.rays, trace.work
    if len(rays) != len(work):
        raise ValueError(f"{trace.path}: {len(rays)} rays but {len(work)} work records")
    for start in range(0, len(rays), CHUNK_RAYS):
        r = rays[start : start + CHUNK_RAYS]
        w = work[start : start + CHUNK_RAYS]
        pixel = np.asarray(r["pixel"], dtype=np.int64)
        inside = pixel < pixels
        primary = inside & (np.asarray(r["kind"]) == PRIMARY)
        for c in counters:
            values = np.asarray(w[c], dtype=np.float64)
            sums[c][0][:] += np.bincount(pixel[primary], values[primary], minlength=pixels)
            sums[c][1][:] += np.bincount(pixel[inside], values[inside], minlength=pixels)
    return [
        PixelWork(c, p.reshape(height, width), a.reshape(height, width))
        for c, (p, a) in sums.items()
    ]


def _draw(work: PixelWork, label: str, scene: str, path: Path) -> None:
    # The object-oriented API: no pyplot global state, safe without a display.
    from matplotlib.figure import Figure

    fig = Figure(figsize=(11, 4.4), layout="constrained")
    axes = fig.subplots(1, 2)
    for ax, data, which in zip(
        axes, (work.primary, work.all_rays), ("primary rays", "all rays"), strict=True
    ):
        # Each panel on its own scale: primary work is a fraction of the total.
        vmax = max(float(data.max(initial=0.0)), 1.0)
        image = ax.imshow(data, cmap="inferno", vmin=0.0, vmax=vmax, interpolation="nearest")
        ax.set_title(f"{which}: mean {data.mean():.1f}, max {data.max(initial=0.0):.0f}")
        ax.set_axis_off()
        fig.colorbar(image, ax=ax, shrink=0.85, label=f"{label} per pixel")
    fig.suptitle(f"{scene}: {label} per pixel")
    fig.savefig(path, dpi=110)


def write_heatmaps(
    trace: Trace,
    out_dir: str | Path | None = None,
    size: tuple[int, int] | None = None,
) -> list[Path]:
    """Writes heatmap_nodes.png and heatmap_tris.png (into the trace folder by default)."""
    size = size or image_size(trace.manifest)
    if size is None:
        raise ValueError(f"{trace.folder}: manifest.json does not give the image size")
    width, height = size
    out = Path(out_dir) if out_dir is not None else trace.folder
    out.mkdir(parents=True, exist_ok=True)
    steps, tris = pixel_work(trace, width, height, ("steps", "tri_tests"))
    paths = [out / "heatmap_nodes.png", out / "heatmap_tris.png"]
    _draw(steps, "traversal steps (nodes or cells visited)", trace.scene_name, paths[0])
    _draw(tris, "triangle tests", trace.scene_name, paths[1])
    return paths

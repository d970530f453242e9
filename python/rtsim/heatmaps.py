"""Heatmaps of traversal work per pixel, drawn from a trace folder.

Each figure has two panels: the work of primary rays alone, and the work of every ray that
descends from the pixel (shadow, reflection, diffuse, ... rays carry their pixel). A trace
without primary rays has only the second panel, and one with only primary rays only the first
(the two would be the same). The colour scale ends at the 99.5th percentile of the pixels, so a
few very costly pixels do not turn the rest black; pixels above it show the top colour. The trace
is read in chunks of its memory maps, so memory stays bounded whatever the ray count.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from rtsim.manifest import image_size
from rtsim.trace_file import Trace

CHUNK_RAYS = 1 << 20
PRIMARY = 0
CLIP_PERCENTILE = 99.5


@dataclass(frozen=True)
class PixelWork:
    """Per-pixel sums of one work counter: over primary rays and over all rays, (H, W)."""

    counter: str
    primary: np.ndarray
    all_rays: np.ndarray
    primary_rays: int = 0  # rays of kind primary inside the image
    other_rays: int = 0  # rays of any other kind inside the image


def pixel_work(trace: Trace, width: int, height: int, counters: tuple[str, ...]) -> list[PixelWork]:
    """Sums each work counter per pixel with np.bincount, chunk by chunk."""
    pixels = width * height
    sums = {c: (np.zeros(pixels), np.zeros(pixels)) for c in counters}
    n_primary = n_other = 0
    rays, work = trace.rays, trace.work
    if len(rays) != len(work):
        raise ValueError(f"{trace.path}: {len(rays)} rays but {len(work)} work records")
    for start in range(0, len(rays), CHUNK_RAYS):
        r = rays[start : start + CHUNK_RAYS]
        w = work[start : start + CHUNK_RAYS]
        pixel = np.asarray(r["pixel"], dtype=np.int64)
        inside = pixel < pixels
        primary = inside & (np.asarray(r["kind"]) == PRIMARY)
        n_primary += int(primary.sum())
        n_other += int(inside.sum()) - int(primary.sum())
        for c in counters:
            values = np.asarray(w[c], dtype=np.float64)
            sums[c][0][:] += np.bincount(pixel[primary], values[primary], minlength=pixels)
            sums[c][1][:] += np.bincount(pixel[inside], values[inside], minlength=pixels)
    return [
        PixelWork(c, p.reshape(height, width), a.reshape(height, width), n_primary, n_other)
        for c, (p, a) in sums.items()
    ]


def panels(work: PixelWork) -> list[tuple[np.ndarray, str]]:
    """The panels worth drawing: primary rays and all rays, but not an empty primary panel (no
    primary rays) and not the same picture twice (only primary rays)."""
    if work.primary_rays == 0:
        return [(work.all_rays, "all rays (no primary rays)")]
    if work.other_rays == 0:
        return [(work.primary, "primary rays (the only kind)")]
    return [(work.primary, "primary rays"), (work.all_rays, "all rays")]


def color_limit(data: np.ndarray) -> float:
    """Top of the colour scale: the CLIP_PERCENTILE-th percentile of the pixels with work, so a
    handful of extreme pixels (a ray grazing many thin triangles) cannot darken the image."""
    values = data[data > 0]
    if values.size == 0:
        return 1.0
    return max(float(np.percentile(values, CLIP_PERCENTILE)), 1.0)


def _draw(work: PixelWork, label: str, scene: str, path: Path) -> None:
    heatmap_figure(work, label, scene).savefig(path, dpi=110)


def heatmap_figure(work: PixelWork, label: str, scene: str) -> Any:
    """The heatmap panels as a matplotlib Figure. Each pixel sums the work of every ray traced
    from it (a primary ray and its bounces), so figures are per pixel, not per ray; the long
    label stays in the title, the colour bar says only its unit so it is never cut."""
    # The object-oriented API: no pyplot global state, safe without a display.
    from matplotlib.figure import Figure

    shown = panels(work)
    fig = Figure(figsize=(6.2 if len(shown) == 1 else 11.0, 4.4), layout="constrained")
    axes = fig.subplots(1, len(shown), squeeze=False)[0]
    for ax, (data, which) in zip(axes, shown, strict=True):
        # Each panel on its own scale: primary work is a fraction of the total.
        vmax = color_limit(data)
        image = ax.imshow(data, cmap="inferno", vmin=0.0, vmax=vmax, interpolation="nearest")
        ax.set_title(
            f"{which}: {data.mean():.1f} per pixel on average, max {data.max(initial=0.0):.0f}"
        )
        ax.set_axis_off()
        clipped = float(data.max(initial=0.0)) > vmax
        fig.colorbar(
            image,
            ax=ax,
            shrink=0.85,
            extend="max" if clipped else "neither",
            label="per pixel" + (f" (clipped at p{CLIP_PERCENTILE:g})" if clipped else ""),
        )
    fig.suptitle(f"{scene}: {label} per pixel")
    return fig


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
    fields = ("steps", "tri_tests", "sphere_tests", "capsule_tests")
    steps, tris, spheres, capsules = pixel_work(trace, width, height, fields)
    paths = [out / "heatmap_nodes.png", out / "heatmap_tris.png"]
    _draw(steps, "traversal steps (nodes or cells visited)", trace.scene_name, paths[0])
    # Curved primitives are primitives too: the map counts every primitive test.
    curved = spheres.all_rays.any() or capsules.all_rays.any()
    title = "primitive tests (triangles, spheres, capsules)" if curved else "triangle tests"
    tests = PixelWork(
        "primitive_tests", tris.primary + spheres.primary + capsules.primary,
        tris.all_rays + spheres.all_rays + capsules.all_rays,
        tris.primary_rays, tris.other_rays,
    )  # fmt: skip
    _draw(tests, title, trace.scene_name, paths[1])
    return paths

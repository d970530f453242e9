"""What a study reads from its runs' traces rather than from stats.json: a trace's manifest,
per-ray work statistics by ray kind (mean, p99, sum), the rays whose hit differs between two
traces of the same rays, and the trace made again under `/usr/bin/time` for the tracer's build
time and peak memory. Each reads a row's `trace_dir`; wrap the costly ones in `run.cached`
(docs/studies.md), so a study run again reuses them."""

from __future__ import annotations

import json
import re
import shutil
import statistics
import subprocess
import tempfile
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from rtsim.sweep.tasks import TRACE_DONE

#: The work counts every trace records per ray (docs/trace_format.md).
WORK = ("steps", "box_tests", "tri_tests")


def manifest(trace_dir: str | Path) -> dict[str, Any]:
    """The trace's manifest.json."""
    return dict(json.loads((Path(trace_dir) / "manifest.json").read_text()))


def work_stats(
    trace_dir: str | Path, ray_kind: str | None = None, fields: Iterable[str] = WORK
) -> dict[str, Any]:
    """Over the trace's rays of `ray_kind` (None: every ray): their count, the hit rate, and
    mean, p99 and sum of each work count in `fields`."""
    import numpy as np

    import rtsim

    t = rtsim.open_trace(Path(trace_dir))
    kinds = np.asarray(t.rays["kind"])
    mask = (
        np.ones(len(kinds), bool)
        if ray_kind is None
        else kinds == rtsim.trace_file.RAY_KINDS.index(ray_kind)
    )
    work, hits = np.asarray(t.work)[mask], np.asarray(t.hits)[mask]
    rays = int(mask.sum())
    out: dict[str, Any] = {
        "rays": rays,
        "hit_rate": float((hits["prim"] >= 0).mean()) if rays else 0.0,
    }
    for f in fields:
        v = work[f].astype(np.float64)
        out[f] = {
            "mean": float(v.mean()) if rays else 0.0,
            "p99": float(np.percentile(v, 99)) if rays else 0.0,
            "sum": float(v.sum()),
        }
    return out


def hits_differ(trace_dir: str | Path, reference_dir: str | Path) -> int:
    """Rays whose hit (primitive, or the bits of t) differs between two traces of the same rays
    in the same order (the same scene and workload through two structures)."""
    import numpy as np

    import rtsim

    hits = np.asarray(rtsim.open_trace(Path(trace_dir)).hits)
    ref = np.asarray(rtsim.open_trace(Path(reference_dir)).hits)
    differ = (hits["prim"] != ref["prim"]) | (hits["t"].view(np.uint32) != ref["t"].view(np.uint32))
    return int(differ.sum())


def retrace(trace_dir: str | Path, repeat: int = 1) -> dict[str, Any]:
    """The trace's own `rtsim trace` command (as the sweep ran it) run `repeat` more times into
    a scratch folder under `/usr/bin/time -v`: the median of the builds' times (the manifest's
    `timing_ms.accel`) and the tracer's largest resident set in MiB."""
    done = json.loads((Path(trace_dir) / TRACE_DONE).read_text())
    builds, peak = [], 0.0
    with tempfile.TemporaryDirectory(prefix="rtsim-retrace-") as tmp:
        cmd = list(done["command"])
        cmd[cmd.index("-o") + 1] = str(Path(tmp) / "trace")
        for _ in range(max(1, repeat)):
            shutil.rmtree(Path(tmp) / "trace", ignore_errors=True)
            result, rss = timed(cmd)
            if result.returncode != 0:
                raise RuntimeError(f"{' '.join(cmd)}: exit {result.returncode}: {result.stderr}")
            builds.append(manifest(Path(tmp) / "trace")["timing_ms"]["accel"])
            peak = max(peak, rss)
    return {"build_ms": statistics.median(builds), "peak_mib": peak}


def timed(cmd: list[str]) -> tuple[subprocess.CompletedProcess[str], float]:
    """Runs cmd under /usr/bin/time -v; returns the result and its peak resident set in MiB."""
    result = subprocess.run(
        ["/usr/bin/time", "-v", *cmd], capture_output=True, text=True, check=False
    )
    match = re.search(r"Maximum resident set size \(kbytes\): (\d+)", result.stderr)
    return result, (int(match.group(1)) / 1024 if match else float("nan"))

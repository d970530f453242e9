"""`rtsim demo`: the main job. A small design-space sweep (python/rtsim/specs/demo.yaml: the
Cornell box and a 200k-triangle hairball, primary and diffuse rays, 16 accelerator configs) on a
local Dask cluster, then the HTML report. Re-running resumes: finished runs are not redone."""

from __future__ import annotations

import os
import time
from importlib import resources
from pathlib import Path

from rich.console import Console

from rtsim.report import write_report
from rtsim.report.data import load, mrays
from rtsim.sweep.cli import print_outcome
from rtsim.sweep.runner import SweepOptions, run_sweep
from rtsim.sweep.spec import parse_spec


def demo_spec_text() -> str:
    return resources.files("rtsim").joinpath("specs/demo.yaml").read_text()


def run_demo(out: Path, console: Console, workers: int = 0, scheduler: str | None = None) -> int:
    t0 = time.monotonic()
    spec = parse_spec(demo_spec_text(), source="rtsim/specs/demo.yaml")
    opts = SweepOptions(out_dir=out, workers=workers, scheduler=scheduler)
    outcome = run_sweep(spec, opts, console)
    print_outcome(outcome, out, console)
    report = write_report(out, out / "report.html")
    data = load(out)
    for g in data.groups():
        if g.ok:
            best = max(g.ok, key=mrays)
            console.print(
                f"  fastest on {g.title}: {data.label(best)}: {mrays(best):.0f} Mrays/s",
                highlight=False,
            )
    console.print(f"\n[bold]report:[/] {report.resolve()}")
    console.print(f"results: rtsim results {out} --csv   (runs in {out / 'runs'})")
    where = scheduler or f"{workers or os.cpu_count()} local workers on {os.cpu_count()} cores"
    console.print(f"demo: {time.monotonic() - t0:.0f} s ({where}; typical: docs/benchmarks.md)")
    return 0 if outcome.failed == 0 and outcome.mismatch == 0 else 1

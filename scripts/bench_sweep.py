#!/usr/bin/env python
"""Measures the parallel speed-up of a sweep: the same spec on a local Dask cluster of 1 worker
and of N workers (default 2), each into a fresh folder, traces included. Prints the wall times
and the speed-up; asserts nothing (timing depends on the machine).

    python scripts/bench_sweep.py [--spec SPEC.yaml] [--workers 2] [--keep DIR]
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
import tempfile
import time
from datetime import datetime
from pathlib import Path

from rich.console import Console

from rtsim.sweep.demo import demo_spec_text
from rtsim.sweep.runner import SweepOptions, run_sweep
from rtsim.sweep.spec import load_spec, parse_spec
from rtsim.sweep.store import open_store


def simulation_span(out: Path) -> float:
    """Seconds from the first simulation's start to the last one's finish (no cluster start-up,
    and tracing only where it overlaps the simulations)."""
    with open_store(out, readonly=True) as store:
        runs = [r for r in store.runs() if r.started_utc and r.finished_utc]
    start = min(datetime.fromisoformat(r.started_utc.rstrip("Z")) for r in runs)
    end = max(datetime.fromisoformat(r.finished_utc.rstrip("Z")) for r in runs)
    return (end - start).total_seconds()


def timed_sweep(spec_path: Path | None, out: Path, workers: int) -> tuple[float, float, int]:
    """(total wall seconds, simulation span seconds, runs) of one fresh sweep."""
    spec = load_spec(spec_path) if spec_path else parse_spec(demo_spec_text(), "demo.yaml")
    console = Console(stderr=True, quiet=True)
    t0 = time.monotonic()
    outcome = run_sweep(spec, SweepOptions(out_dir=out, workers=workers, progress=False), console)
    total = time.monotonic() - t0
    if outcome.failed:
        print(f"warning: {outcome.failed} runs failed in {out}", file=sys.stderr)
    return total, simulation_span(out), outcome.total


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--spec", type=Path, default=None, help="default: the demo spec")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--keep", type=Path, default=None, help="keep the sweep folders here")
    parser.add_argument("--json", type=Path, default=None, help="also write the figures as JSON")
    args = parser.parse_args()
    base = args.keep or Path(tempfile.mkdtemp(prefix="bench_sweep_"))
    totals, spans = {}, {}
    for workers in (1, args.workers):
        out = base / f"workers{workers}"
        shutil.rmtree(out, ignore_errors=True)
        totals[workers], spans[workers], runs = timed_sweep(args.spec, out, workers)
        print(f"{workers} worker(s): {runs} runs in {totals[workers]:.1f} s wall "
              f"(simulations: {spans[workers]:.1f} s from first start to last finish)")  # fmt: skip
    speedup = totals[1] / totals[args.workers]
    sim_speedup = spans[1] / spans[args.workers]
    print(f"speed-up on {args.workers} workers: {speedup:.2f}x wall, "
          f"{sim_speedup:.2f}x on the simulations")  # fmt: skip
    if args.json:
        figures = {"wall_seconds": totals, "simulation_seconds": spans, "speedup": speedup,
                   "simulation_speedup": sim_speedup}  # fmt: skip
        args.json.write_text(json.dumps(figures, indent=2))
    if args.keep is None:
        shutil.rmtree(base, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())

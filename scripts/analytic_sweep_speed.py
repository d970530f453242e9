#!/usr/bin/env python3
"""The analytic level's speed-up over detailed (docs/benchmarks.md, "The analytic
level"): on one trace, CPU time (user + system of each rtsim-sim process, from the OS) of

- `detailed` at the default config (--detailed-runs runs, median);
- `analytic` at the default config with no cached analysis (RTSIM_ANALYTIC_CACHE=off: the
  single-configuration cost, analysis included), --repeat runs, median;
- a sweep of --configs configurations at `analytic` that share one per-trace analysis (cache
  sizes and ways, DRAM bandwidth, pipeline latencies vary; units and contexts, which shape the
  access streams, do not): the first run builds the analysis beside the trace, the others load it.

The sweep's speed-up is 100 x (detailed's median) over the sweep's total: running a 100-point
detailed sweep here would take hours, and detailed's time varies little between these configs.
Not a test: it prints figures.

    python scripts/analytic_sweep_speed.py TRACE [--configs 100] [--repeat 3] [--detailed-runs 1]
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import shutil
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

from rtsim.launcher import SimJob, find_sim

GRID = {
    "l1.size_kib": [8, 16, 32, 64, 128],
    "l2.size_kib": [256, 512, 1024, 2048, 4096],
    "dram.bytes_per_cycle": [8, 16, 32, 64],
}


def cpu_run(exe: Path, trace: Path, out: Path, sets: list[str], env: dict[str, str]) -> float:
    cmd = SimJob(trace=trace, out_dir=out, sets=sets, verdict=False).command(exe)
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env)
    _, status, usage = os.wait4(proc.pid, 0)
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"{' '.join(cmd)}: {proc.stderr.read().decode() if proc.stderr else ''}")
    return usage.ru_utime + usage.ru_stime


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("trace", type=Path)
    ap.add_argument("--configs", type=int, default=100)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--detailed-runs", type=int, default=1)
    args = ap.parse_args()
    exe = find_sim()
    env = dict(os.environ)
    out = {}
    with tempfile.TemporaryDirectory(prefix="rtsim-analytic-speed-") as tmp:
        run = Path(tmp) / "run"
        detailed, analytic = ["fidelity=detailed"], ["fidelity=analytic"]
        det = [cpu_run(exe, args.trace, run, detailed, env) for _ in range(args.detailed_runs)]
        out["detailed_cpu_s"] = statistics.median(det)
        cold = {**env, "RTSIM_ANALYTIC_CACHE": "off"}
        one = [cpu_run(exe, args.trace, run, analytic, cold) for _ in range(args.repeat)]
        out["analytic_one_config_cpu_s"] = statistics.median(one)
        # The sweep keeps its analyses in a folder of its own, so its first run builds one.
        cache = Path(tmp) / "analyses"
        swept = {**env, "RTSIM_ANALYTIC_CACHE": str(cache)}
        points = list(itertools.product(*GRID.values()))[: args.configs]
        t0 = time.perf_counter()
        times = []
        for values in points:
            sets = ["fidelity=analytic"] + [f"{k}={v}" for k, v in zip(GRID, values, strict=True)]
            times.append(cpu_run(exe, args.trace, run, sets, swept))
        out["sweep_configs"] = len(points)
        out["sweep_wall_s"] = time.perf_counter() - t0
        out["sweep_cpu_s"] = sum(times)
        out["sweep_first_run_cpu_s"] = times[0]
        later = times[1:] or [0.0]
        out["sweep_later_runs_median_cpu_s"] = statistics.median(later)
        shutil.rmtree(cache, ignore_errors=True)
    out["speedup_one_config"] = out["detailed_cpu_s"] / out["analytic_one_config_cpu_s"]
    out["speedup_sweep"] = len(points) * out["detailed_cpu_s"] / out["sweep_cpu_s"]
    print(json.dumps(out, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

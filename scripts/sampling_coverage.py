#!/usr/bin/env python3
"""Sampling accuracy and interval coverage over seeds and configurations (
docs/fidelity.md, "Sampling"): for each configuration, the full run of the level, then sampled
runs at --fraction for every seed and every functional-warming setting; per setting, the error
of the estimate against the full run (mean, max |error|), how often the 95% interval contains the
full run, the mean half-width and the wall-time speed-up. Not a test: it prints a table.

    python scripts/sampling_coverage.py TRACE [--fraction 0.01] [--seeds 5]
        [--warming 0,16384] [--configs "traversal.units=4;traversal.units=16 l1.size_kib=64"]
        [--fidelity approx] [--json out.json]

Each configuration is a space-separated list of KEY=VALUE ("" is the defaults); configurations
are separated by ";".
"""

from __future__ import annotations

import argparse
import json
import statistics
import tempfile
from pathlib import Path
from typing import Any

from rtsim.launcher import SimJob, find_sim, run_sim


def run(exe: Path, trace: Path, out: Path, sets: list[str]) -> dict[str, Any]:
    result = run_sim(SimJob(trace=trace, out_dir=out, sets=sets, verdict=False), exe=exe)
    if result.returncode != 0 or result.stats is None:
        raise SystemExit(f"{' '.join(result.command)}: {(result.messages or ['?'])[-1]}")
    return result.stats


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("trace", type=Path)
    ap.add_argument("--fraction", type=float, default=0.01)
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--warming", default="0,16384", help="sampling.warming_rays values")
    ap.add_argument("--configs", default="", help='";"-separated configurations')
    ap.add_argument("--fidelity", default="approx")
    ap.add_argument("--json", type=Path, default=None)
    args = ap.parse_args()
    exe = find_sim()
    rows = []
    with tempfile.TemporaryDirectory(prefix="rtsim-sampling-") as tmp:
        for config in args.configs.split(";"):
            base = [f"fidelity={args.fidelity}", *config.split()]
            full = run(exe, args.trace, Path(tmp), base)["summary"]
            for warming in args.warming.split(","):
                for seed in range(1, args.seeds + 1):
                    sets = [*base, f"sampling.fraction={args.fraction}", f"sampling.seed={seed}"]
                    sets.append(f"sampling.warming_rays={warming}")
                    stats = run(exe, args.trace, Path(tmp), sets)
                    s, smp = stats["summary"], stats["sampling"]
                    lo, hi = s["cycles_ci95"]
                    rows.append(
                        {
                            "config": config or "defaults",
                            "warming_rays": int(warming),
                            "seed": seed,
                            "full_cycles": full["cycles"],
                            "cycles": s["cycles"],
                            "error": s["cycles"] / full["cycles"] - 1,
                            "covered": lo <= full["cycles"] <= hi,
                            "half_width": smp["relative_half_width"],
                            "clusters": smp["clusters"],
                            "warmup_rays": smp["warmup_rays"],
                            "measured_rays": smp["measured_rays"],
                            "speedup": full["wall_seconds"] / s["wall_seconds"],
                        }
                    )
                    print(json.dumps(rows[-1]), flush=True)
    print("\n| config | warming rays | runs | mean error | max abs error | covered | "
          "mean half-width | K x (W + M) | speed-up (median) |")  # fmt: skip
    print("|---|---:|---:|---:|---:|---:|---:|---|---:|")
    keys = dict.fromkeys((r["config"], r["warming_rays"]) for r in rows)
    for config, warming in keys:
        rs = [r for r in rows if r["config"] == config and r["warming_rays"] == warming]
        errs = [r["error"] for r in rs]
        print(
            f"| {config} | {warming} | {len(rs)} | {100 * statistics.mean(errs):+.2f}% "
            f"| {100 * max(abs(e) for e in errs):.2f}% | {sum(r['covered'] for r in rs)}/{len(rs)} "
            f"| {100 * statistics.mean(r['half_width'] for r in rs):.1f}% "
            f"| {rs[0]['clusters']} x ({rs[0]['warmup_rays']} + {rs[0]['measured_rays']}) "
            f"| {statistics.median(r['speedup'] for r in rs):.1f}x |"
        )
    if args.json:
        args.json.write_text(json.dumps(rows, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

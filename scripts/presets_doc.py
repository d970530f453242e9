#!/usr/bin/env python3
"""The measured figures of docs/presets.md, from runs (so they cannot go stale).

One trace (Sponza's diffuse rays, `rtsim trace sponza --workload diffuse --resolution 256x192`)
is simulated (approx) with each published-machine preset (`rtx2060`, `rtx2080`, `strata`) and,
for the sensitivity table, with the default config and each knob doubled alone. Writes between
the markers of docs/presets.md:

- `presets-rtx`, `presets-strata`: Mrays/s, nJ/ray, W and mm^2 of each preset, with the rays in
  flight against the trace's rays;
- `presets-sensitivity`: the default config and each knob doubled: Mrays/s, gain, DRAM busy,
  L2 and L1 MSHR stall cycles, nJ/ray, mm^2.

Runs are cached in OUT (a run folder with a stats.json is reused; --fresh redoes them).

    python scripts/presets_doc.py [--out out/presets_doc] [--resolution 256x192] [--jobs 2]
        [--write-docs]
"""

from __future__ import annotations

import argparse
import json
import platform
import shutil
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

from rtsim.config import compose
from rtsim.doc_markers import write_between
from rtsim.launcher import SimJob, run_sim

REPO = Path(__file__).resolve().parents[1]
PRESETS = ("rtx2060", "rtx2080", "strata")
#: (label, --set) of the sensitivity table: each knob doubled from the default config.
KNOBS = (
    ("(base)", ""),
    ("`l2.mshrs` 128", "l2.mshrs=128"),
    ("`l1.mshrs` 32", "l1.mshrs=32"),
    ("`dram.bytes_per_cycle` 32", "dram.bytes_per_cycle=32"),
    ("`traversal.units` 16", "traversal.units=16"),
    ("`traversal.ray_contexts` 32", "traversal.ray_contexts=32"),
    ("`l1.size_kib` 32", "l1.size_kib=32"),
    ("`l2.size_kib` 2048", "l2.size_kib=2048"),
    ("`l2.banks` 16", "l2.banks=16"),
    ("`traversal.stack_entries` 16", "traversal.stack_entries=16"),
)


def make_trace(args: argparse.Namespace) -> Path:
    folder = args.out / "trace" / f"sponza-diffuse-{args.resolution}"
    if (folder / "trace.rtt").is_file() and not args.fresh:
        return folder
    shutil.rmtree(folder, ignore_errors=True)
    cmd = [sys.executable, "-m", "rtsim", "trace", "sponza", "-o", str(folder)]
    cmd += ["--workload", "diffuse", "--resolution", args.resolution, "--threads", "0"]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return folder


def simulate(
    trace: Path, name: str, preset: str | None, sets: list[str], args: argparse.Namespace
) -> dict[str, Any]:
    run = args.out / "runs" / name
    stats_file = run / "stats.json"
    if args.fresh or not stats_file.is_file():
        shutil.rmtree(run, ignore_errors=True)
        config = None
        if preset is not None:
            config = args.out / "configs" / f"{preset}.json"
            config.parent.mkdir(parents=True, exist_ok=True)
            config.write_text(compose(preset).to_json())
        job = SimJob(trace=trace / "trace.rtt", out_dir=run, config=config, sets=sets)
        result = run_sim(job)
        if result.returncode != 0:
            raise SystemExit(f"{name}: rtsim-sim exit {result.returncode}: {result.stderr[-600:]}")
    stats = json.loads(stats_file.read_text())
    if stats["summary"]["hit_mismatches"] or stats["summary"]["work_mismatches"]:
        raise SystemExit(f"{name}: mismatches: {stats['validation']['first_mismatches'][:2]}")
    return dict(stats)


def stalls(stats: dict[str, Any], level: str) -> float:
    """MSHR stall cycles summed over a cache level's instances (`model.l1.<l1>`, `model.l2`)."""
    m = stats["model"].get(level) or {}
    caches = m.values() if level == "l1" else [m]
    return float(sum((c or {}).get("mshr_stall_cycles", 0) or 0 for c in caches))


def figures(stats: dict[str, Any]) -> dict[str, Any]:
    s = stats["summary"]
    return {
        "rays": s["rays"],
        "mrays": s["mrays_per_second"],
        "nj_per_ray": s["energy_per_ray_nj"],
        "watts": s["power_w"],
        "mm2": s["area_mm2"],
        "dram_busy": s["dram_bandwidth_utilization"],
        "l2_stalls": stalls(stats, "l2"),
        "l1_stalls": stalls(stats, "l1"),
    }


def fmt(x: float | None, spec: str) -> str:
    return "n/a" if x is None else format(x, spec)


def preset_line(name: str, f: dict[str, Any]) -> str:
    return (
        f"`{name}` {fmt(f['mrays'], '.0f')} Mrays/s, {fmt(f['nj_per_ray'], '.0f')} nJ/ray, "
        f"{fmt(f['watts'], '.1f')} W, {fmt(f['mm2'], '.1f')} mm^2"
    )


def sensitivity(rows: list[tuple[str, dict[str, Any]]]) -> str:
    base = rows[0][1]["mrays"]
    out = [
        "| knob doubled | Mrays/s | gain | DRAM busy | L2 MSHR stall cycles "
        "| L1 MSHR stall cycles | nJ/ray | mm^2 |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for label, f in rows:
        gain = "" if label == "(base)" else f"{100 * (f['mrays'] / base - 1):+.0f}%"
        out.append(
            f"| {label} | {f['mrays']:.1f} | {gain} | {100 * f['dram_busy']:.0f}% "
            f"| {f['l2_stalls']:.2g} | {f['l1_stalls']:.2g} | {fmt(f['nj_per_ray'], '.1f')} "
            f"| {fmt(f['mm2'], '.2f')} |"
        )
    return "\n".join(out)


def main(argv: list[str] | None = None) -> None:
    p = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    p.add_argument("--out", type=Path, default=Path("out/presets_doc"))
    p.add_argument("--resolution", default="256x192")
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--fresh", action="store_true")
    p.add_argument("--write-docs", action="store_true")
    args = p.parse_args(argv)
    t0 = time.time()
    trace = make_trace(args)
    jobs = [(name, name, []) for name in PRESETS]
    jobs += [(f"default-{i}", None, [s] if s else []) for i, (_, s) in enumerate(KNOBS)]
    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        stats = list(pool.map(lambda j: simulate(trace, j[0], j[1], j[2], args), jobs))
    by = {j[0]: figures(s) for j, s in zip(jobs, stats, strict=True)}
    rays = by["rtx2060"]["rays"]
    how = (
        f"(generated by `scripts/presets_doc.py` on {platform.node()}, "
        f"{time.strftime('%Y-%m-%d')}: "
        f"Sponza's diffuse rays at {args.resolution}, {rays:,} rays, approx, one run each; "
        f"{len(jobs)} runs in {time.time() - t0:.0f} s)"
    )
    rtx = (
        f"On Sponza's diffuse rays: {preset_line('rtx2060', by['rtx2060'])} at 12 nm; "
        f"{preset_line('rtx2080', by['rtx2080'])} {how}. Both have 30-46 x 128 rays in flight "
        f"for a {rays:,}-ray trace, so the tail weighs; use bigger traces for such machines."
    )
    strata = (
        f"On Sponza's diffuse rays: {preset_line('strata', by['strata'])} {how}. 32,768 rays "
        f"in flight for a {rays:,}-ray trace: this machine wants frames of millions of rays."
    )
    table = sensitivity([(label, by[f"default-{i}"]) for i, (label, _) in enumerate(KNOBS)])
    table += f"\n\n{how[1:-1].capitalize()}."
    print(rtx, strata, table, sep="\n\n")
    if args.write_docs:
        doc = REPO / "docs" / "presets.md"
        write_between(doc, "presets-rtx", rtx)
        write_between(doc, "presets-strata", strata)
        write_between(doc, "presets-sensitivity", table)


if __name__ == "__main__":
    main()

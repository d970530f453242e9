#!/usr/bin/env python3
"""rtsim's DRAM model against DRAMsim3 on the same request stream (docs/model.md, "DRAM").

Each run simulates a trace with `--dram-trace` (RUN/dram_trace.dramsim3.txt: every request that
reached DRAM, with the core cycle it was issued), converts the stream to DRAMsim3's memory clock
and replays it open loop in DRAMsim3 (Li et al., "DRAMsim3", IEEE CAL 2020) with as many
channels as rtsim had, then sets the two models' mean read latency, its part above each model's
unloaded latency (the queueing at that load) and the bandwidth each delivered in the stream's
window side by side. A Ramulator 2 trace (its LoadStoreTrace frontend: `LD|ST 0xADDR`, untimed)
is written beside it; Ramulator 2 is not run here.

DRAMsim3 is not part of rtsim: build it yourself outside the repository (it is a small CMake
project) and pass its `dramsim3main` and a config:

    python scripts/dram_compare.py --dramsim3 /tmp/dramsim3/build/dramsim3main \\
        --ini /tmp/dramsim3/configs/DDR4_8Gb_x8_2133.ini [--out out/dram_compare] [--docs docs]

With --docs the table goes into DOCS/model.md between the `dram-compare` markers.

Without --dramsim3 it writes the traces and rtsim's figures only.
"""

from __future__ import annotations

import argparse
import configparser
import json
import platform
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rtsim.doc_markers import write_between
from rtsim.launcher import SimJob, run_sim

REPO = Path(__file__).resolve().parents[1]
#: Cycles DRAMsim3 runs past the stream's last request, so the last ones drain.
DRAIN_NS = 2000.0


@dataclass(frozen=True)
class Run:
    name: str
    sets: tuple[str, ...] = ()


RUNS = [
    Run("default (2 channels)"),
    Run("1 channel", ("dram.channels=1",)),
    Run("32 units, 1 channel", ("traversal.units=32", "dram.channels=1")),
]


def parse_dramsim3_line(line: str) -> tuple[int, bool, int]:
    """(address, write, cycle) of one DRAMsim3 trace line `0xADDR READ|WRITE CYCLE`."""
    addr, kind, cycle = line.split()
    if kind not in ("READ", "WRITE"):
        raise ValueError(f"not a DRAMsim3 trace line: {line!r}")
    return int(addr, 16), kind == "WRITE", int(cycle)


def to_memory_clock(
    core_trace: Path, out: Path, clock_ghz: float, tck_ns: float
) -> tuple[int, int]:
    """Writes the trace with each core cycle converted to DRAMsim3's memory cycles (tCK);
    returns the last cycle and the read transactions."""
    last = reads = 0
    with core_trace.open() as src, out.open("w") as dst:
        for line in src:
            if not line.strip():
                continue
            addr, write, cycle = parse_dramsim3_line(line)
            last = int(cycle / clock_ghz / tck_ns)
            reads += not write
            dst.write(f"0x{addr:X} {'WRITE' if write else 'READ'} {last}\n")
    return last, reads


def to_ramulator2(core_trace: Path, out: Path) -> None:
    """Ramulator 2's LoadStoreTrace lines (`LD 0xADDR` / `ST 0xADDR`, in issue order)."""
    with core_trace.open() as src, out.open("w") as dst:
        for line in src:
            if line.strip():
                addr, write, _ = parse_dramsim3_line(line)
                dst.write(f"{'ST' if write else 'LD'} 0x{addr:X}\n")


def dramsim3_ini(base: Path, channels: int, out: Path) -> configparser.ConfigParser:
    """The DRAMsim3 config with rtsim's channel count (its [system] channels)."""
    ini = configparser.ConfigParser(inline_comment_prefixes=(";", "#"))
    ini.read(base)
    ini["system"]["channels"] = str(channels)
    ini["other"]["output_level"] = "1"
    with out.open("w") as f:
        ini.write(f)
    return ini


def dramsim3_unloaded_ns(ini: configparser.ConfigParser) -> float:
    """A read to a closed bank: activate, column and the burst (tRCD + CL + BL/2), in ns."""
    t, s = ini["timing"], ini["dram_structure"]
    cycles = int(t["tRCD"]) + int(t["CL"]) + int(s["BL"]) / 2
    return cycles * float(t["tCK"])


def run_dramsim3(
    exe: Path, ini_path: Path, ini: configparser.ConfigParser, trace: Path, cycles: int, out: Path
) -> dict[str, float]:
    out.mkdir(parents=True, exist_ok=True)
    cmd = [str(exe), str(ini_path), "-c", str(cycles), "-t", str(trace), "-o", str(out)]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, cwd=out)
    stats = json.loads((out / "dramsim3.json").read_text())
    tck = float(ini["timing"]["tCK"])
    reads = sum(c["num_reads_done"] for c in stats.values())
    latency = sum(c["average_read_latency"] * c["num_reads_done"] for c in stats.values())
    return {
        "reads_done": reads,
        "writes_done": sum(c["num_writes_done"] for c in stats.values()),
        "mean_read_latency_ns": latency / reads * tck if reads else 0.0,
        "bandwidth_gbps": sum(c["average_bandwidth"] for c in stats.values()),
    }


def rtsim_figures(run: Path) -> dict[str, Any]:
    summary = json.loads((run / "dram_trace.json").read_text())
    stats = json.loads((run / "stats.json").read_text())
    ghz = float(summary["clock_ghz"])
    return {
        "summary": summary,
        "mean_read_latency_ns": summary["mean_read_latency_cycles"] / ghz,
        "unloaded_ns": summary["dram"]["latency"] / ghz,
        "utilization": stats["model"]["dram"]["bandwidth_utilization"],
        "rays": stats["summary"]["rays"],
    }


def make_trace(out: Path, scene: str, resolution: str) -> Path:
    folder = out / "traces" / f"{scene}-diffuse-{resolution}"
    if not (folder / "trace.rtt").is_file():
        shutil.rmtree(folder, ignore_errors=True)
        cmd = [sys.executable, "-m", "rtsim", "trace", scene, "-o", str(folder)]
        cmd += ["--workload", "diffuse", "--resolution", resolution, "--threads", "0"]
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return folder


def compare(r: Run, trace: Path, args: argparse.Namespace) -> dict[str, Any]:
    run = args.out / "runs" / "".join(c if c.isalnum() else "-" for c in r.name)
    if not (run / "dram_trace.json").is_file():
        result = run_sim(
            SimJob(trace=trace, out_dir=run, sets=list(r.sets), dram_trace=True, verdict=False)
        )
        if result.returncode != 0:
            raise SystemExit(f"{run}: rtsim-sim exit {result.returncode}: {result.stderr[-600:]}")
    ours = rtsim_figures(run)
    summary = ours["summary"]
    to_ramulator2(run / "dram_trace.dramsim3.txt", run / "dram_trace.ramulator2.txt")
    row: dict[str, Any] = {"run": r.name, "rtsim": ours}
    ghz = float(summary["clock_ghz"])
    window_ns = (summary["last_ready_cycle"] - summary["first_issue_cycle"]) / ghz
    ours["bandwidth_gbps"] = summary["bytes"] / window_ns if window_ns > 0 else 0.0
    if args.dramsim3:
        ini = dramsim3_ini(args.ini, summary["dram"]["channels"], run / "dramsim3.ini")
        tck = float(ini["timing"]["tCK"])
        trace_mc = run / "dram_trace.dramsim3.memclk.txt"
        last, reads = to_memory_clock(run / "dram_trace.dramsim3.txt", trace_mc, ghz, tck)
        cycles = last + int(DRAIN_NS / tck)
        theirs = run_dramsim3(
            args.dramsim3, run / "dramsim3.ini", ini, trace_mc, cycles, run / "dramsim3"
        )
        theirs["unloaded_ns"] = dramsim3_unloaded_ns(ini)
        theirs["read_transactions"] = reads
        # Its average is over the cycles it ran (the window plus the drain): over the window.
        theirs["bandwidth_gbps"] *= cycles * tck / window_ns if window_ns > 0 else 0.0
        row["dramsim3"] = theirs
    return row


def table(rows: list[dict[str, Any]]) -> str:
    lines = [
        "| run | DRAM requests | rtsim utilisation | mean read latency, rtsim / DRAMsim3 (ns) "
        "| above unloaded, rtsim / DRAMsim3 (ns) "
        "| bandwidth in the window, rtsim / DRAMsim3 (GB/s) "
        "| DRAMsim3 reads done |",
        "|---|---:|---:|---|---|---|---:|",
    ]
    for row in rows:
        ours, s = row["rtsim"], row["rtsim"]["summary"]
        theirs = row.get("dramsim3")
        excess = ours["mean_read_latency_ns"] - ours["unloaded_ns"]
        if theirs:
            lat = f"{ours['mean_read_latency_ns']:.1f} / {theirs['mean_read_latency_ns']:.1f}"
            above = f"{excess:.1f} / {theirs['mean_read_latency_ns'] - theirs['unloaded_ns']:.1f}"
            bw = f"{ours['bandwidth_gbps']:.2f} / {theirs['bandwidth_gbps']:.2f}"
            done = f"{theirs['reads_done']:,} of {theirs['read_transactions']:,}"
        else:
            lat = f"{ours['mean_read_latency_ns']:.1f} / -"
            above, bw, done = f"{excess:.1f} / -", f"{ours['bandwidth_gbps']:.2f} / -", "-"
        lines.append(
            f"| {row['run']} | {s['requests']:,} | {100 * ours['utilization']:.0f}% | {lat} | "
            f"{above} | {bw} | {done} |"
        )
    return "\n".join(lines) + "\n"


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path, default=REPO / "out" / "dram_compare")
    p.add_argument("--scene", default="hairball")
    p.add_argument("--resolution", default="160x120")
    p.add_argument("--dramsim3", type=Path, help="DRAMsim3's dramsim3main (built outside rtsim)")
    p.add_argument("--ini", type=Path, help="the DRAMsim3 config to compare with")
    p.add_argument("--docs", type=Path, help="write the table into DOCS/model.md")
    args = p.parse_args()
    if args.dramsim3 and not args.ini:
        p.error("--dramsim3 needs --ini (a DRAMsim3 config)")
    start = time.perf_counter()
    trace = make_trace(args.out, args.scene, args.resolution)
    rows = [compare(r, trace, args) for r in RUNS]
    text = table(rows)
    ini = f", DRAMsim3 config `{args.ini.name}`" if args.ini else ""
    text += (
        f"\nMeasured by `python scripts/dram_compare.py` on {platform.node()} "
        f"({platform.machine()}), {time.strftime('%Y-%m-%d', time.gmtime())}: {args.scene} "
        f"diffuse at {args.resolution}, approx level{ini}, "
        f"{time.perf_counter() - start:.0f} s wall.\n"
    )
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "figures.json").write_text(json.dumps(rows, indent=2))
    if args.docs:
        write_between(args.docs / "model.md", "dram-compare", text)
    print(text)


if __name__ == "__main__":
    main()

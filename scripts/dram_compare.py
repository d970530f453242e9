#!/usr/bin/env python3
"""rtsim's DRAM model against DRAMsim3 on the same request stream (docs/model.md, "DRAM").

Each run simulates a trace with `--dram-trace` (RUN/dram_trace.dramsim3.txt: every request that
reached DRAM, with the core cycle it was issued), converts the stream to DRAMsim3's memory clock
and replays it open loop in DRAMsim3 (Li et al., "DRAMsim3", IEEE CAL 2020) with as many
channels as rtsim had, then sets the two models' mean read latency, its part above each model's
unloaded latency (the queueing at that load) and the bandwidth each delivered in the stream's
window side by side. With --ramulator2 the same stream is replayed in Ramulator 2.1 (Luo et al.,
"Ramulator 2.0", IEEE CAL 2023) timed, each request at its own time: Ramulator's stock trace
frontends send requests as fast as the controller takes them, so scripts/ramulator2_driver.cpp
(compiled here against the user's Ramulator build) drives its External frontend, the one gem5's
wrapper uses, ticking the memory system every tCK. Its configuration is made with Ramulator's own
Python DSL: DDR4 `DDR4_8Gb_x8` at `--ramulator2-timing` (default DDR4_2133P, the speed of the
DRAMsim3 config below), FR-FCFS, open rows, RoBaRaCoCh, as many channels as rtsim had. An untimed
LoadStoreTrace file (`LD|ST 0xADDR`) is written beside it for the stock frontends.

DRAMsim3 and Ramulator 2 are not part of rtsim: build them yourself outside the repository and
pass them:

    # DRAMsim3: a small CMake project
    python scripts/dram_compare.py --dramsim3 /tmp/dramsim3/build/dramsim3main \\
        --ini /tmp/dramsim3/configs/DDR4_8Gb_x8_2133.ini [--out out/dram_compare] [--docs docs]
    # Ramulator 2.1: git clone https://github.com/CMU-SAFARI/ramulator2 /tmp/ram2, then
    #   cmake -S /tmp/ram2 -B /tmp/ram2/build -DRAMULATOR_PYTHON_BINDINGS=OFF
    #   ninja -C /tmp/ram2/build   (its CMake fetches yaml-cpp 0.9.0 and fmt 10.2.1 into ext/;
    #   libramulator.so lands in /tmp/ram2; its Python DSL, python/, makes the configs; with no
    #   network, clone yaml-cpp at yaml-cpp-0.9.0 and fmt at 10.2.1 into ext/yaml-cpp and
    #   ext/fmt and add -DFETCHCONTENT_FULLY_DISCONNECTED=ON)
    python scripts/dram_compare.py --ramulator2 /tmp/ram2 [--dramsim3 ... --ini ...]

With --docs the table goes into DOCS/model.md between the `dram-compare` markers.

Without --dramsim3 it writes the traces and rtsim's figures only.
"""

from __future__ import annotations

import argparse
import configparser
import json
import os
import platform
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rtsim.config import MODIFIERS
from rtsim.doc_markers import write_between
from rtsim.launcher import SimJob, run_sim

REPO = Path(__file__).resolve().parents[1]
#: Cycles DRAMsim3 runs past the stream's last request, so the last ones drain.
DRAIN_NS = 2000.0


@dataclass(frozen=True)
class Run:
    name: str
    sets: tuple[str, ...] = ()


#: The `ddr4` modifier's limits as --set assignments: all of them, and the bank limits alone
#: (tRAS, tRRD, tFAW, refresh; without bank groups, turnarounds or the controller queue).
DDR4 = tuple(f"dram.{k}={v}" for k, v in MODIFIERS["ddr4"]["dram"].items())
BANK_LIMITS = ("t_ras", "t_rrd", "t_rrd_l", "t_faw", "t_refi", "t_rfc")
DDR4_BANKS = tuple(
    f"dram.{k}={v}" for k, v in MODIFIERS["ddr4"]["dram"].items() if k in BANK_LIMITS
)

RUNS = [
    Run("default (2 channels)"),
    Run("ddr4 bank limits, 2 channels", DDR4_BANKS),
    Run("ddr4, 2 channels", DDR4),
    Run("ddr4 + FR-FCFS, 2 channels", (*DDR4, "dram.scheduler=frfcfs")),
    Run("1 channel", ("dram.channels=1",)),
    Run("ddr4 bank limits, 1 channel", ("dram.channels=1", *DDR4_BANKS)),
    Run("ddr4, 1 channel", ("dram.channels=1", *DDR4)),
    Run("ddr4 + FR-FCFS, 1 channel", ("dram.channels=1", *DDR4, "dram.scheduler=frfcfs")),
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
        "row_hit_rate": sum(
            c["num_read_row_hits"] + c["num_write_row_hits"] for c in stats.values()
        )
        / max(1, sum(c["num_reads_done"] + c["num_writes_done"] for c in stats.values())),
    }


DRIVER = REPO / "scripts" / "ramulator2_driver.cpp"


def ramulator2_driver(root: Path, out: Path) -> Path:
    """scripts/ramulator2_driver.cpp built against the Ramulator 2 checkout ROOT (once)."""
    exe = out / "ramulator2_driver"
    if exe.is_file() and exe.stat().st_mtime > DRIVER.stat().st_mtime:
        return exe
    out.mkdir(parents=True, exist_ok=True)
    includes = [
        root / "src",
        root / "ext" / "yaml-cpp" / "include",
        root / "ext" / "fmt" / "include",
    ]
    cmd = ["g++", "-std=c++20", "-O2", str(DRIVER), "-o", str(exe)]
    cmd += [f"-I{i}" for i in includes] + [f"-L{root}", "-lramulator", f"-Wl,-rpath,{root}"]
    subprocess.run(cmd, check=True)
    return exe


def ramulator2_config(
    root: Path, channels: int, timing: str, ranks: int, out: Path
) -> dict[str, Any]:
    """The memory system, made with Ramulator's Python DSL, and its unloaded read latency
    (activate, column, burst: nRCD + nCL + nBL, in ns) from the timing preset."""
    program = f"""
import json, ramulator
ddr4 = ramulator.dram.DDR4(org_preset="DDR4_8Gb_x8", timing_preset={timing!r}, rank={ranks})
ctrl = lambda: ramulator.controller.GenericDDR(dram=ddr4, scheduler=ramulator.scheduler.FRFCFS(),
    refresh_manager=ramulator.refresh_manager.AllBank(), row_policy=ramulator.row_policy.Open(),
    addr_mapper=ramulator.addr_mapper.RoBaRaCoCh())
ms = ramulator.memory_system.GenericDRAM(clock_ratio=1,
    controllers=[ctrl() for _ in range({channels})],
    channel_mapper=ramulator.channel_mapper.CacheLineInterleave())
t = ramulator.dram.DDR4.timing_presets[{timing!r}]
print(json.dumps({{"config": {{"frontend": {{"impl": "External", "clock_ratio": 1}},
                               "memory_system": ms.to_config()}},
                   "unloaded_ns": (t["nRCD"] + t["nCL"] + t["nBL"]) * t["tCK_ps"] / 1000}}))
"""
    env = {**os.environ, "PYTHONPATH": str(root / "python")}
    made = subprocess.run(
        [sys.executable, "-c", program], check=True, capture_output=True, text=True, env=env
    )
    made = json.loads(made.stdout)
    out.write_text(json.dumps(made["config"]))
    return made


def run_ramulator2(
    args: argparse.Namespace, run: Path, channels: int, ghz: float
) -> dict[str, Any]:
    exe = ramulator2_driver(args.ramulator2, args.out)
    made = ramulator2_config(
        args.ramulator2, channels, args.ramulator2_timing, args.ramulator2_ranks,
        run / "ramulator2.json",
    )  # fmt: skip
    out, stats = run / "ramulator2.out.json", run / "ramulator2.stats.yaml"
    cmd = [str(exe), str(run / "ramulator2.json"), str(run / "dram_trace.dramsim3.txt"), str(ghz)]
    subprocess.run([*cmd, str(out), str(stats)], check=True, stdout=subprocess.DEVNULL)
    r = json.loads(out.read_text())
    window = r["last_ns"] - r["first_ns"]
    row_hits = row_misses = row_conflicts = 0
    for line in stats.read_text().splitlines():  # per-controller counters, summed
        key, _, value = line.strip().partition(":")
        if key in ("row_hits", "num_row_hits"):
            row_hits += int(float(value))
        elif key in ("row_misses", "num_row_misses"):
            row_misses += int(float(value))
        elif key in ("row_conflicts", "num_row_conflicts"):
            row_conflicts += int(float(value))
    accesses = row_hits + row_misses + row_conflicts
    return {
        "reads_done": r["reads"],
        "mean_read_latency_ns": r["mean_read_latency_ns"],
        "unloaded_ns": made["unloaded_ns"],
        "bandwidth_gbps": r["bytes"] / window if window > 0 else 0.0,
        "row_hit_rate": row_hits / accesses if accesses else None,
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
        "row_hit_rate": stats["model"]["dram"].get("row_hit_rate"),
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


def compare(r: Run, scene: str, trace: Path, args: argparse.Namespace) -> dict[str, Any]:
    run = args.out / "runs" / scene / "".join(c if c.isalnum() else "-" for c in r.name)
    if not (run / "dram_trace.json").is_file():
        sets = ["fidelity=detailed", *r.sets]
        result = run_sim(
            SimJob(trace=trace, out_dir=run, sets=sets, dram_trace=True, verdict=False)
        )
        if result.returncode != 0:
            raise SystemExit(f"{run}: rtsim-sim exit {result.returncode}: {result.stderr[-600:]}")
    ours = rtsim_figures(run)
    summary = ours["summary"]
    to_ramulator2(run / "dram_trace.dramsim3.txt", run / "dram_trace.ramulator2.txt")
    row: dict[str, Any] = {"scene": scene, "run": r.name, "rtsim": ours}
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
    if args.ramulator2:
        row["ramulator2"] = run_ramulator2(args, run, summary["dram"]["channels"], ghz)
    return row


def _pair(ours: float, theirs: dict[str, Any] | None, key: str, fmt: str) -> str:
    return f"{ours:{fmt}}" if theirs is None else f"{theirs[key]:{fmt}}"


def table(rows: list[dict[str, Any]]) -> str:
    lines = [
        "| scene | run | DRAM requests | rtsim utilisation "
        "| mean read latency, rtsim / DRAMsim3 / Ramulator 2 (ns) "
        "| above unloaded, rtsim / DRAMsim3 / Ramulator 2 (ns) "
        "| bandwidth in the window, rtsim / DRAMsim3 / Ramulator 2 (GB/s) "
        "| row-hit rate, rtsim / DRAMsim3 / Ramulator 2 | DRAMsim3 reads done |",
        "|---|---|---:|---:|---|---|---|---|---:|",
    ]
    for row in rows:
        ours, s = row["rtsim"], row["rtsim"]["summary"]
        ds3, ram = row.get("dramsim3"), row.get("ramulator2")

        models = (ours, ds3, ram)

        def three(f: Any, models: tuple = models) -> str:
            return " / ".join(f(x) if x else "-" for x in models)

        lat = three(lambda x: f"{x['mean_read_latency_ns']:.1f}")
        above = three(lambda x: f"{x['mean_read_latency_ns'] - x['unloaded_ns']:.1f}")
        bw = three(lambda x: f"{x['bandwidth_gbps']:.2f}")
        hits = three(
            lambda x: f"{x['row_hit_rate']:.3f}" if x.get("row_hit_rate") is not None else "-"
        )
        done = f"{ds3['reads_done']:,} of {ds3['read_transactions']:,}" if ds3 else "-"
        lines.append(
            f"| {row['scene']} | {row['run']} | {s['requests']:,} | "
            f"{100 * ours['utilization']:.0f}% | {lat} | {above} | {bw} | {hits} | {done} |"
        )
    return "\n".join(lines) + "\n"


def add_common_args(p: argparse.ArgumentParser, out: Path) -> None:
    """The options both DRAM scripts take (this one and dram_closed_loop.py): where to write, which
    rays, and the DRAM simulators the user built outside rtsim."""
    p.add_argument("--out", type=Path, default=out)
    p.add_argument("--scenes", default="hairball,sponza", help="comma-separated scenes")
    p.add_argument("--resolution", default="160x120")
    p.add_argument("--dramsim3", type=Path, help="DRAMsim3's dramsim3main (built outside rtsim)")
    p.add_argument("--ini", type=Path, help="the DRAMsim3 config to compare with")
    p.add_argument("--ramulator2", type=Path, help="a Ramulator 2.1 checkout with its build")
    p.add_argument("--ramulator2-timing", default="DDR4_2133P", help="its DDR4 timing preset")
    p.add_argument(
        "--ramulator2-ranks",
        type=int,
        default=2,
        help="ranks a channel (2: the DRAMsim3 config's 16 GB of 8 Gb x8 devices)",
    )
    p.add_argument("--docs", type=Path, help="write the table into DOCS/model.md")


def simulator_configs(args: argparse.Namespace) -> str:
    """The DRAM simulators' configs a table was measured with, for its provenance line."""
    parts = []
    if args.ini:
        parts.append(f"DRAMsim3 config `{args.ini.name}`")
    if args.ramulator2:
        parts.append(
            f"Ramulator 2 DDR4 `DDR4_8Gb_x8` x {args.ramulator2_ranks} ranks at "
            f"`{args.ramulator2_timing}`"
        )
    return "".join(f", {x}" for x in parts)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_common_args(p, REPO / "out" / "dram_compare")
    args = p.parse_args()
    if args.dramsim3 and not args.ini:
        p.error("--dramsim3 needs --ini (a DRAMsim3 config)")
    start = time.perf_counter()
    rows = []
    for scene in args.scenes.split(","):
        trace = make_trace(args.out, scene, args.resolution)
        rows += [compare(r, scene, trace, args) for r in RUNS]
    text = table(rows)
    text += (
        f"\nMeasured by `python scripts/dram_compare.py` on {platform.node()} "
        f"({platform.machine()}), {time.strftime('%Y-%m-%d', time.gmtime())}: {args.scenes} "
        f"diffuse at {args.resolution}, detailed level{simulator_configs(args)}, "
        f"{time.perf_counter() - start:.0f} s wall.\n"
    )
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "figures.json").write_text(json.dumps(rows, indent=2))
    if args.docs:
        write_between(args.docs / "model.md", "dram-compare", text)
    print(text)


if __name__ == "__main__":
    main()

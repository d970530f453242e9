#!/usr/bin/env python3
"""rtsim with DRAMsim3's or Ramulator 2's latency, closed loop by latency matching (docs/model.md,
"DRAM").

scripts/dram_compare.py replays rtsim's DRAM stream open loop: the requests keep the times
rtsim's own memory gave them, so a simulator that queues longer never slows the machine that
issues them. Here the loop is closed by a fixed point instead: rtsim runs with `dram.model =
bandwidth` (each access its channel's bandwidth calendar plus a latency), its stream is replayed
in the DDR4 simulator, and rtsim's latency is searched (bracketed, then bisected) for the one at
which the simulator's mean read latency and rtsim's own on that stream agree within --tolerance. At
the fixed point rtsim's machine issues its requests as it would against a memory with the
simulator's mean latency at that load (fewer in flight when that memory is slower), and the
run's cycles are rtsim's answer with the simulator's DRAM. Only the mean is matched: each
request still takes rtsim's latency, not its own.

    python scripts/dram_closed_loop.py --dramsim3 /tmp/dramsim3/build/dramsim3main \\
        --ini /tmp/dramsim3/configs/DDR4_8Gb_x8_2133.ini [--ramulator2 /tmp/ram2] \\
        [--out out/dram_closed_loop] [--docs docs]

With --docs the table goes into DOCS/model.md between the `dram-closed-loop` markers.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import platform
import sys
import time
from pathlib import Path
from typing import Any

from rtsim.doc_markers import write_between

REPO = Path(__file__).resolve().parents[1]


def load_dram_compare() -> Any:
    """scripts/dram_compare.py as a module: its trace conversions and replays."""
    spec = importlib.util.spec_from_file_location(
        "dram_compare", REPO / "scripts" / "dram_compare.py"
    )
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    sys.modules["dram_compare"] = module  # its dataclasses look their module up there
    spec.loader.exec_module(module)
    return module


dc = load_dram_compare()

#: The machine's configurations: rtsim's own channel counts, each closed against both simulators.
CHANNELS = (2, 1)


def rtsim_run(trace: Path, run: Path, sets: list[str]) -> dict[str, Any]:
    """rtsim at the detailed level with its DRAM trace; its cycles and DRAM figures."""
    if not (run / "dram_trace.json").is_file():
        job = dc.SimJob(trace=trace, out_dir=run, sets=["fidelity=detailed", *sets],
                        dram_trace=True, verdict=False)  # fmt: skip
        result = dc.run_sim(job)
        if result.returncode != 0:
            raise SystemExit(f"{run}: rtsim-sim exit {result.returncode}: {result.stderr[-600:]}")
    figures = dc.rtsim_figures(run)
    stats = json.loads((run / "stats.json").read_text())
    figures["cycles"] = stats["summary"]["cycles"]
    return figures


def replay(simulator: str, run: Path, ours: dict[str, Any], args: argparse.Namespace) -> float:
    """The simulator's mean read latency (ns) on the run's stream, open loop."""
    summary = ours["summary"]
    ghz, channels = float(summary["clock_ghz"]), summary["dram"]["channels"]
    if simulator == "ramulator2":
        return dc.run_ramulator2(args, run, channels, ghz)["mean_read_latency_ns"]
    ini = dc.dramsim3_ini(args.ini, channels, run / "dramsim3.ini")
    tck = float(ini["timing"]["tCK"])
    trace_mc = run / "dram_trace.dramsim3.memclk.txt"
    last, _ = dc.to_memory_clock(run / "dram_trace.dramsim3.txt", trace_mc, ghz, tck)
    theirs = dc.run_dramsim3(args.dramsim3, run / "dramsim3.ini", ini, trace_mc,
                             last + int(dc.DRAIN_NS / tck), run / "dramsim3")  # fmt: skip
    return theirs["mean_read_latency_ns"]


def close_loop(
    scene: str, trace: Path, channels: int, simulator: str, args: argparse.Namespace
) -> dict[str, Any]:
    """Finds rtsim's latency at which its own mean read latency equals the simulator's on
    rtsim's stream. The gap (theirs - ours) falls as the latency grows (a slower memory slows
    the stream, which shortens the simulator's queues and lengthens rtsim's latency), so the
    root is bracketed by doubling and found by bisection; a simulator that queues steeply with
    load would make a plain iteration overshoot."""
    base = [f"dram.channels={channels}"]
    folder = args.out / "runs" / scene / f"{channels}ch"
    own = rtsim_run(trace, folder / "banks", base)
    steps: list[dict[str, Any]] = []

    def gap(latency: int) -> float:
        run = folder / simulator / f"latency-{latency}"
        ours = rtsim_run(trace, run, [*base, "dram.model=bandwidth", f"dram.latency={latency}"])
        theirs = replay(simulator, run, ours, args)
        ns = ours["mean_read_latency_ns"]
        steps.append(
            {"latency": latency, "cycles": ours["cycles"], "rtsim_ns": ns, "theirs_ns": theirs}
        )
        return theirs - ns

    def close(step: dict[str, Any]) -> bool:
        return abs(step["theirs_ns"] - step["rtsim_ns"]) <= args.tolerance * step["theirs_ns"]

    lo = hi = int(own["summary"]["dram"]["latency"])
    g = gap(lo)
    # Bracket: lo with the simulator slower than rtsim (gap > 0), hi with it faster.
    while not close(steps[-1]) and len(steps) < args.iterations:
        if g > 0:
            lo, hi = hi, hi * 2
            g = gap(hi)
            if g <= 0:
                break
        else:
            hi, lo = lo, max(1, lo // 2)
            if lo == hi:
                break
            g = gap(lo)
            if g > 0:
                break
    while not close(steps[-1]) and len(steps) < args.iterations and hi - lo > 1:
        mid = (lo + hi) // 2
        if gap(mid) > 0:
            lo = mid
        else:
            hi = mid
    best = min(steps, key=lambda st: abs(st["theirs_ns"] - st["rtsim_ns"]) / st["theirs_ns"])
    return {
        "scene": scene,
        "channels": channels,
        "simulator": simulator,
        "banks_cycles": own["cycles"],
        "banks_ns": own["mean_read_latency_ns"],
        "steps": steps,
        "best": best,
        "converged": close(best),
    }


NAMES = {"dramsim3": "DRAMsim3", "ramulator2": "Ramulator 2"}


def table(rows: list[dict[str, Any]]) -> str:
    lines = [
        "| scene | channels | DRAM | rtsim's banks: cycles, mean read latency (ns) "
        "| closed loop: cycles, against the banks | its latency (cycles) | mean read latency, "
        "rtsim / the simulator (ns) | iterations |",
        "|---|---:|---|---|---|---:|---|---:|",
    ]
    for r in rows:
        last = r["best"]
        ratio = last["cycles"] / r["banks_cycles"]
        done = f"{len(r['steps'])}" + ("" if r["converged"] else " (not within the tolerance)")
        lines.append(
            f"| {r['scene']} | {r['channels']} | {NAMES[r['simulator']]} | "
            f"{r['banks_cycles']:,}, {r['banks_ns']:.0f} | {last['cycles']:,}, {ratio:.2f}x | "
            f"{last['latency']} | {last['rtsim_ns']:.0f} / {last['theirs_ns']:.0f} | {done} |"
        )
    return "\n".join(lines) + "\n"


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    dc.add_common_args(p, REPO / "out" / "dram_closed_loop")
    p.add_argument("--iterations", type=int, default=14, help="at most this many rtsim runs a loop")
    p.add_argument("--tolerance", type=float, default=0.03, help="relative latency gap to stop at")
    args = p.parse_args()
    if bool(args.dramsim3) != bool(args.ini):
        p.error("--dramsim3 and --ini go together")
    simulators = [
        s for s, given in (("dramsim3", args.dramsim3), ("ramulator2", args.ramulator2)) if given
    ]
    if not simulators:
        p.error(
            "give --dramsim3 (with --ini) or --ramulator2: the simulator to close the loop with"
        )
    start = time.perf_counter()
    rows = []
    for scene in args.scenes.split(","):
        trace = dc.make_trace(args.out, scene, args.resolution)
        rows += [close_loop(scene, trace, ch, s, args) for ch in CHANNELS for s in simulators]
    text = table(rows)
    text += (
        f"\nMeasured by `python scripts/dram_closed_loop.py` on {platform.node()} "
        f"({platform.machine()}), {time.strftime('%Y-%m-%d', time.gmtime())}: {args.scenes} "
        f"diffuse at {args.resolution}, detailed level, `dram.model=bandwidth` in the loop"
        f"{dc.simulator_configs(args)}, tolerance {args.tolerance:.0%}; "
        f"{time.perf_counter() - start:.0f} s wall.\n"
    )
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "figures.json").write_text(json.dumps(rows, indent=2))
    if args.docs:
        write_between(args.docs / "model.md", "dram-closed-loop", text)
    print(text)


if __name__ == "__main__":
    main()

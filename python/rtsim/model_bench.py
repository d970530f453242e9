"""`rtsim bench --model TRACE`: how fast the simulator itself runs, per fidelity level.

For each trace and level, runs `rtsim-sim TRACE --no-verdict --set fidelity=LEVEL` `repeat` times
(one process each, start-up included; with `verdict=True` without `--no-verdict`, so each run is
what a default run costs, the bottleneck verdict included; the report says which) and reports
the median wall time, the median CPU time of the process (user + system, from the OS's
accounting of the finished child: less sensitive to a shared machine than wall time),
simulated rays per wall- and CPU-second, and the ratios the simulator's speed targets are
stated in (docs/benchmarks.md):

    approx/functional, detailed/approx, treelets/approx, approx/analytic

(a ratio is the CPU time of the first over the second: how many times slower it is). `treelets`
is `approx` with `treelets.enabled=true`. The analytic level caches its per-trace analysis beside
the trace: the first run builds it, later runs reuse it; both times are reported.

`--against OTHER_RTSIM_SIM` measures a change side by side: every run is followed by the same run
of the other binary (same trace, level and settings), and the report adds per level the other
binary's median CPU time, the speed-up (its CPU time over ours) and whether both simulated the
same number of cycles (a speed change should not change the simulation; when defaults differ
between the binaries, pass the old defaults with --set).
"""

from __future__ import annotations

import json
import os
import platform
import statistics
import tempfile
from dataclasses import asdict, dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

from rich.console import Console

from rtsim.launcher import SimJob, find_sim, run_sim

LEVELS: dict[str, list[str]] = {
    "functional": ["fidelity=functional"],
    "analytic": ["fidelity=analytic"],
    "approx": ["fidelity=approx"],
    "detailed": ["fidelity=detailed"],
    "treelets": ["fidelity=approx", "treelets.enabled=true"],
}
#: (slower, faster): reported as cpu(slower) / cpu(faster).
RATIOS = (
    ("approx", "functional"),
    ("detailed", "approx"),
    ("treelets", "approx"),
    ("approx", "analytic"),
)


@dataclass
class LevelTiming:
    """The runs of one level on one trace."""

    level: str
    rays: int = 0
    wall_seconds: list[float] = field(default_factory=list)
    cpu_seconds: list[float] = field(default_factory=list)
    first_wall_seconds: float | None = None  # analytic: the run that built the analysis
    error: str | None = None
    cycles: int | None = None
    against_cpu_seconds: list[float] = field(default_factory=list)  # --against: the other binary
    against_cycles: int | None = None
    against_error: str | None = None
    git: str | None = None  # the binary's commit (stats.json provenance)

    def median_wall(self) -> float | None:
        return statistics.median(self.wall_seconds) if self.wall_seconds else None

    def median_cpu(self) -> float | None:
        return statistics.median(self.cpu_seconds) if self.cpu_seconds else None

    def summary(self) -> dict[str, Any]:
        wall, cpu = self.median_wall(), self.median_cpu()
        against = statistics.median(self.against_cpu_seconds) if self.against_cpu_seconds else None
        return {
            **asdict(self),
            "median_wall_seconds": wall,
            "median_cpu_seconds": cpu,
            "rays_per_wall_second": self.rays / wall if wall else None,
            "rays_per_cpu_second": self.rays / cpu if cpu else None,
            "against_median_cpu_seconds": against,
            "speedup_over_against": against / cpu if against and cpu else None,
            "same_cycles_as_against": (self.cycles == self.against_cycles)
            if self.against_cpu_seconds
            else None,
        }


def run_once(
    exe: Path, trace: Path, settings: list[str], out: Path, verdict: bool = False
) -> tuple[float, float, int, int | None, str | None]:
    """One rtsim-sim process: (wall s, CPU s of the child, simulated rays, simulated cycles,
    the binary's git commit)."""
    result = run_sim(SimJob(trace=trace, out_dir=out, sets=settings, verdict=verdict), exe=exe)
    if result.returncode not in (0, 3) or result.stats is None:
        lines = result.messages
        raise RuntimeError(lines[-1] if lines else result.describe_failure())
    stats = result.stats
    rays = int(stats["summary"].get("rays") or stats["workload"]["rays"])
    cycles = stats["summary"].get("cycles")
    simulated = int(cycles) if cycles is not None else None
    git = stats.get("provenance", {}).get("git")
    return result.wall_seconds, result.cpu_seconds, rays, simulated, git


def bench_trace(
    exe: Path,
    trace: Path,
    levels: list[str],
    repeat: int,
    extra: list[str],
    console: Console,
    against: Path | None = None,
    verdict: bool = False,
) -> dict[str, LevelTiming]:
    timings: dict[str, LevelTiming] = {}
    with tempfile.TemporaryDirectory(prefix="rtsim-bench-model-") as tmp:
        # Rounds of every level in turn, so load on a shared machine hits all levels alike.
        for round_ in range(repeat + (1 if "analytic" in levels else 0)):
            for level in levels:
                t = timings.setdefault(level, LevelTiming(level))
                if t.error or (level != "analytic" and round_ >= repeat):
                    continue
                try:
                    wall, cpu, rays, t.cycles, t.git = run_once(
                        exe, trace, LEVELS[level] + extra, Path(tmp), verdict
                    )
                except RuntimeError as err:
                    t.error = str(err)
                    console.print(f"  {trace.name} {level}: {err}", highlight=False)
                    continue
                t.rays = rays
                if level == "analytic" and round_ == 0:
                    t.first_wall_seconds = wall  # built the per-trace analysis (or found it)
                    continue
                t.wall_seconds.append(wall)
                t.cpu_seconds.append(cpu)
                line = f"  {trace.name:<28} {level:<11} {wall:8.3f} s wall {cpu:8.3f} s cpu"
                if against and not t.against_error:
                    try:
                        _, other_cpu, _, t.against_cycles, _ = run_once(
                            against, trace, LEVELS[level] + extra, Path(tmp), verdict
                        )
                        t.against_cpu_seconds.append(other_cpu)
                        line += f"   against: {other_cpu:8.3f} s cpu"
                    except RuntimeError as err:
                        t.against_error = str(err)
                        line += f"   against: {err}"
                console.print(line, highlight=False)
    return timings


def ratios(timings: dict[str, LevelTiming]) -> dict[str, float | None]:
    out: dict[str, float | None] = {}
    for slow, fast in RATIOS:
        a = timings.get(slow)
        b = timings.get(fast)
        ca, cb = (a.median_cpu() if a else None), (b.median_cpu() if b else None)
        out[f"{slow}/{fast}"] = ca / cb if ca and cb else None
    return out


def verdict_note(verdict: bool) -> str:
    """What the timed runs include, said with every report."""
    if verdict:
        return (
            "Each run is a default run: the bottleneck verdict is included (its analysis is "
            "stepped by the first run of a trace and key, stored beside the trace, loaded by later "
            "runs)."
        )
    return (
        "The verdict is not included: every run has --no-verdict (the simulation alone; "
        "--verdict times default runs, verdict included)."
    )


def host_info() -> dict[str, Any]:
    """CPU model and load average, as rtsim-bench records them."""
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    try:
        load = os.getloadavg()[0]
    except OSError:
        load = None
    return {"cpu": cpu, "hardware_threads": os.cpu_count(), "load_average": load}


def markdown(report: list[dict[str, Any]]) -> str:
    lines = [
        "| trace | level | rays | wall s (median) | CPU s (median) | rays per wall-s "
        "| rays per CPU-s |",
        "|---|---|---:|---:|---:|---:|---:|",
    ]
    for t in report:
        for s in t["levels"].values():
            if s["error"]:
                lines.append(f"| {t['trace']} | {s['level']} | | | | {s['error']} | |")
                continue
            lines.append(
                f"| {t['trace']} | {s['level']} | {s['rays']:,} | {s['median_wall_seconds']:.3f} "
                f"| {s['median_cpu_seconds']:.3f} | {s['rays_per_wall_second']:,.0f} "
                f"| {s['rays_per_cpu_second']:,.0f} |"
            )
    lines += ["", "| trace | " + " | ".join(f"{a}/{b} (CPU)" for a, b in RATIOS) + " |"]
    lines.append("|---|" + "---:|" * len(RATIOS))
    for t in report:
        cells = [f"{v:.2f}x" if v else "" for v in t["ratios"].values()]
        lines.append(f"| {t['trace']} | " + " | ".join(cells) + " |")
    compared = [(t, s) for t in report for s in t["levels"].values() if s["against_cpu_seconds"]]
    if compared:
        lines += [
            "",
            "| trace | level | CPU s (median) | against: CPU s (median) | speed-up | same cycles |",
        ]
        lines.append("|---|---|---:|---:|---:|---|")
        for t, s in compared:
            lines.append(
                f"| {t['trace']} | {s['level']} | {s['median_cpu_seconds']:.3f} "
                f"| {s['against_median_cpu_seconds']:.3f} | {s['speedup_over_against'] or 0:.2f}x "
                f"| {'yes' if s['same_cycles_as_against'] else 'NO'} |"
            )
    return "\n".join(lines) + "\n"


def run_model_bench(
    traces: list[Path],
    levels: list[str],
    repeat: int,
    extra: list[str],
    json_path: Path | None,
    console: Console,
    against: Path | None = None,
    verdict: bool = False,
) -> int:
    unknown = [lvl for lvl in levels if lvl not in LEVELS]
    if unknown:
        known = ", ".join(LEVELS)
        console.print(f"rtsim: error: --levels: unknown {', '.join(unknown)} (known: {known})")
        return 2
    exe = find_sim()
    if against is not None and not against.is_file():
        console.print(f"rtsim: error: --against: {against}: no such binary")
        return 2
    started, host_start = datetime.now(timezone.utc), host_info()
    report = []
    for trace in traces:
        if not trace.exists():
            console.print(f"rtsim: error: {trace}: no such trace")
            return 2
        timings = bench_trace(exe, trace, levels, repeat, extra, console, against, verdict)
        report.append(
            {
                "trace": str(trace),
                "levels": {k: v.summary() for k, v in timings.items()},
                "ratios": ratios(timings),
            }
        )
    console.print(markdown(report), highlight=False, markup=False)
    console.print(verdict_note(verdict), highlight=False, markup=False)
    if json_path:
        host_end = host_info()
        gits = [s["git"] for t in report for s in t["levels"].values() if s.get("git")]
        meta = {
            "sim": str(exe),
            "git": gits[0] if gits else None,
            "against": str(against) if against else None,
            "repeat": repeat,
            "set": extra,
            "verdict": verdict,
            "cpu_count": os.cpu_count(),
            "date_start": started.isoformat(timespec="seconds"),
            "date_end": datetime.now(timezone.utc).isoformat(timespec="seconds"),
            "host": {
                "cpu": host_start["cpu"],
                "hardware_threads": host_start["hardware_threads"],
                "load_average_start": host_start["load_average"],
                "load_average_end": host_end["load_average"],
            },
        }
        json_path.write_text(json.dumps({**meta, "traces": report}, indent=2))
    return 1 if any(s["error"] for t in report for s in t["levels"].values()) else 0

#!/usr/bin/env python
"""Measures what Python start-up adds to a short simulation: `rtsim --version`, `import rtsim`,
and `rtsim simulate` against `rtsim-sim` alone on the same small trace (cornell, 64x48 primary
rays), with a bare `python -c pass` as the interpreter's own floor. Each command runs --repeat
times, interleaved round-robin so machine load hits every command alike; prints the median and
min of each and asserts nothing (docs/benchmarks.md).

    python scripts/bench_startup.py [--repeat 15] [--before DIR] [--json FILE]

--before DIR compares, in the same run, against another `rtsim` Python package: DIR holds an
`rtsim/` folder (e.g. `git archive COMMIT python/rtsim | tar -x --strip-components=1 -C DIR`,
plus the installed `_core*.so` copied into DIR/rtsim). Every rtsim command is run as
`python -m rtsim ...` so both packages are started the same way.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def timed(cmd: list[str], env: dict[str, str]) -> float:
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, env=env, capture_output=True, text=True, check=False)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        raise SystemExit(f"bench_startup: {' '.join(cmd)} failed:\n{proc.stderr}")
    return wall


def load_average() -> str:
    """1, 5 and 15 minute load averages (Linux), to judge how busy the machine was."""
    try:
        return " ".join(Path("/proc/loadavg").read_text().split()[:3])
    except OSError:
        return "unknown"


def commands(trace: Path, runs: Path, sim: str) -> dict[str, list[str]]:
    from rtsim.launcher import SimJob  # the one place rtsim-sim command lines are made

    py = [sys.executable, "-m", "rtsim"]
    return {
        "python -c pass": [sys.executable, "-c", "pass"],  # the interpreter's own start-up
        "rtsim --version": [*py, "--version"],
        "import rtsim": [sys.executable, "-c", "import rtsim"],
        "rtsim-sim TRACE": SimJob(trace=trace, out_dir=runs / "sim").command(Path(sim)),
        "rtsim simulate TRACE": [
            *py,
            "simulate",
            str(trace),
            "-o",
            str(runs / "py"),
            "--no-progress",
        ],
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=15, help="runs per command (default 15)")
    parser.add_argument("--before", type=Path, default=None, help="an older rtsim package's folder")
    parser.add_argument("--json", type=Path, default=None, help="also write the figures as JSON")
    args = parser.parse_args()

    from rtsim.launcher import find_sim  # the one rtsim-sim both variants use

    sim = str(find_sim())
    variants = {"current": dict(os.environ)}
    if args.before is not None:
        env = dict(os.environ)
        env["PYTHONPATH"] = str(args.before.resolve())
        variants["before"] = env
    with tempfile.TemporaryDirectory() as tmp:
        trace = Path(tmp) / "trace"
        subprocess.run(
            [
                sys.executable,
                "-m",
                "rtsim",
                "trace",
                "cornell",
                "-o",
                str(trace),
                "--workload",
                "primary",
                "--resolution",
                "64x48",
            ],
            check=True,
            capture_output=True,
        )
        plan = []
        for name, env in variants.items():
            for label, cmd in commands(trace, Path(tmp) / name, sim).items():
                if label.startswith(("rtsim-sim", "python -c")) and name != "current":
                    continue  # the same for both variants
                plan.append((name, label, cmd, env))
        times: dict[tuple[str, str], list[float]] = {(n, lbl): [] for n, lbl, _, _ in plan}
        print(f"load average before: {load_average()}")
        for _ in range(args.repeat):
            for name, label, cmd, env in plan:
                times[(name, label)].append(timed(cmd, env))
    print(f"load average after:  {load_average()}")
    rows = []
    for (name, label), walls in times.items():
        rows.append(
            {
                "variant": name,
                "command": label,
                "median_s": statistics.median(walls),
                "min_s": min(walls),
                "runs": len(walls),
            }
        )
    sim_median = next(r["median_s"] for r in rows if r["command"] == "rtsim-sim TRACE")
    print(f"{'variant':<9} {'command':<22} {'median s':>9} {'min s':>7}  over rtsim-sim")
    for r in rows:
        extra = ""
        if r["command"] == "rtsim simulate TRACE":
            extra = f"  +{r['median_s'] - sim_median:.3f} s"
        print(f"{r['variant']:<9} {r['command']:<22} {r['median_s']:9.3f} {r['min_s']:7.3f}{extra}")
    if args.json:
        args.json.write_text(json.dumps(rows, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Checks that a change to the simulator left its results alone: runs a matrix of traces x
configurations (every fidelity level, every structure kind, treelets, sampling, frames, spills,
shared pipelines, ideal memory) with two rtsim-sim binaries and compares their stats.json field
by field, less the fields that measure the host (wall time, peak memory, start time, command
line). A refactor that is meant to change no behaviour must print "identical".

    python scripts/stats_identity.py OLD_RTSIM_SIM [NEW_RTSIM_SIM] [-o DIR] [--quick]

NEW defaults to the installed rtsim-sim. Traces are made once with the installed tracer into
DIR/traces (default out/stats_identity) and reused; OLD's stats are kept in DIR/old so a second
check against the same OLD only runs NEW. Exit status 0 when every run is identical, 1 otherwise.
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

from rtsim.launcher import SimJob, find_sim, run_sim

#: Fields that measure the host, not the simulated machine.
HOST_FIELDS = {
    ("summary", "wall_seconds"),
    ("summary", "simulated_rays_per_wall_second"),
    ("summary", "peak_memory_mib"),
    ("provenance",),
    ("verdict", "estimate", "wall_seconds"),
    ("sampling", "effective_rays_per_wall_second"),
    ("sampling", "functional_warming", "seconds"),
    ("model", "analytic", "analysis", "seconds"),
    ("model", "analytic", "analysis", "file"),
}

#: name -> (scene, extra `rtsim trace` arguments). Small, so the whole matrix takes minutes.
TRACES: dict[str, tuple[str, list[str]]] = {
    "cornell_bvh2": ("cornell", ["--resolution", "48x36"]),
    "cornell_bvh4": ("cornell", ["--resolution", "48x36", "--accel", "bvh4"]),
    "cornell_cwbvh8": ("cornell", ["--resolution", "48x36", "--accel", "cwbvh8"]),
    "cornell_grid": ("cornell", ["--resolution", "48x36", "--accel", "grid"]),
    "hairball_bvh8": (
        "hairball",
        [
            "--resolution",
            "40x30",
            "--hairball-triangles",
            "20000",
            "--accel",
            "bvh8",
            "--workload",
            "diffuse",
        ],
    ),
    "hairball_sbvh": (
        "hairball",
        [
            "--resolution",
            "40x30",
            "--hairball-triangles",
            "20000",
            "--builder",
            "sbvh",
            "--workload",
            "primary",
        ],
    ),
    "grove_frames": ("grove", ["--resolution", "32x24", "--frames", "2"]),
    "alpha_bvh2": ("AlphaBlendModeTest", ["--resolution", "40x30"]),
}

#: name -> --set assignments; every configuration runs on every trace unless limited below.
CONFIGS: dict[str, list[str]] = {
    "approx": [],
    "detailed": ["fidelity=detailed"],
    "functional": ["fidelity=functional"],
    "analytic": ["fidelity=analytic"],
    "analytic_functional": ["fidelity=analytic", "analytic.caches=functional"],
    "treelets": ["treelets.enabled=true"],
    "treelets_detailed": ["treelets.enabled=true", "fidelity=detailed"],
    "sampled": ["sampling.fraction=0.3"],
    "spills_shared": [
        "traversal.stack_entries=2",
        "box.sharing=shared",
        "triangle.sharing=shared",
        "traversal.units=4",
    ],
    "ideal_bandwidth": ["ideal_memory=true", "dram.model=bandwidth"],
    "big_l1_detailed": ["fidelity=detailed", "l1.size_kib=64", "l2.mshrs=16"],
    # Every unit kind and traversal technique (each runs where its structure offers it: the
    # capability table, docs/capabilities.md; a refused run is compared as refused).
    "simt": ["traversal.model=simt", "traversal.simt.lanes=8"],
    "simt_if_if_detailed": [
        "traversal.model=simt",
        "traversal.simt.policy=if_if",
        "fidelity=detailed",
    ],
    "packet": [
        "traversal.model=packet",
        "traversal.packet.lanes=8",
        "traversal.packet.split_below=0.25",
    ],
    "packet_functional": ["traversal.model=packet", "fidelity=functional"],
    "restart_trail": ["traversal.stack_overflow=restart_trail", "traversal.stack_entries=2"],
    "box_precision": ["traversal.box_precision_bits=7"],
    "mailbox": ["mailbox.entries=8"],
    "prefetch": ["treelets.enabled=true", "treelets.prefetch=true"],
    "sorted": ["dispatch.sort=morton"],
}

QUICK_CONFIGS = (
    "approx",
    "detailed",
    "analytic",
    "treelets",
    "simt",
    "packet",
    "restart_trail",
    "mailbox",
)

#: Keys that moved into a unit kind's own section: the old binary gets them by their old names.
OLD_KEYS = {
    "traversal.simt.lanes": "traversal.lanes",
    "traversal.packet.lanes": "traversal.lanes",
    "traversal.simt.policy": "traversal.simt_policy",
    "traversal.simt.refill": "traversal.simt_refill",
    "traversal.packet.split_below": "traversal.packet_split_below",
}

#: Fields the new binary adds that the old one never wrote (what the run's resolution step
#: settled; the area model's SRAM by block): reported apart, not as differences.
ADDED_FIELDS = {
    ("summary", "resolved"),
    ("area", "sram_bytes"),
    ("area", "sram_total_bytes"),
    ("sampling", "measured_by"),
}


def old_sets(sets: list[str]) -> list[str]:
    out = []
    for s in sets:
        key, _, value = s.partition("=")
        out.append(f"{OLD_KEYS.get(key, key)}={value}")
    return out


def old_names(node: Any) -> Any:
    """The new stats with each moved key named by its old name (verdict knobs and texts name
    config keys), so a rename alone is not a difference."""
    if isinstance(node, dict):
        return {k: old_names(v) for k, v in node.items()}
    if isinstance(node, list):
        return [old_names(v) for v in node]
    if isinstance(node, str):
        for new, old in OLD_KEYS.items():
            node = node.replace(new, old)
    return node


def strip_host(node: Any, path: tuple[str, ...] = ()) -> Any:
    if isinstance(node, dict):
        skip = HOST_FIELDS | ADDED_FIELDS
        return {k: strip_host(v, (*path, k)) for k, v in node.items() if (*path, k) not in skip}
    if isinstance(node, list):
        return [strip_host(v, path) for v in node]
    return node


def differences(a: Any, b: Any, path: str = "") -> list[str]:
    if isinstance(a, dict) and isinstance(b, dict):
        out = [f"{path}/{k}: only in old" for k in a.keys() - b.keys()]
        out += [f"{path}/{k}: only in new" for k in b.keys() - a.keys()]
        for k in sorted(a.keys() & b.keys()):
            out += differences(a[k], b[k], f"{path}/{k}")
        return out
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        out: list[str] = []
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            out += differences(x, y, f"{path}[{i}]")
        return out
    if a != b or type(a) is not type(b):
        return [f"{path}: {json.dumps(a)[:80]} -> {json.dumps(b)[:80]}"]
    return []


def make_traces(folder: Path, names: list[str]) -> None:
    for name in names:
        out = folder / name
        if (out / "trace.rtt").is_file():
            continue
        scene, extra = TRACES[name]
        cmd = [sys.executable, "-m", "rtsim", "trace", scene, "-o", str(out), *extra]
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def run(exe: Path, trace: Path, out: Path, sets: list[str]) -> dict[str, Any]:
    stats_file = out / "stats.json"
    if stats_file.is_file():
        return json.loads(stats_file.read_text())
    # The analytic level keeps its per-trace analysis beside the trace: each binary makes its own.
    shutil.rmtree(trace / "analytic", ignore_errors=True)
    result = run_sim(SimJob(trace=trace, out_dir=out, sets=sets), exe=exe)
    if result.stats is None:
        # Refused or failed: compared by exit status (the messages moved to one resolution step).
        return {"failed": result.returncode}
    return result.stats


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("old", type=Path, help="the rtsim-sim before the change")
    parser.add_argument("new", type=Path, nargs="?", help="the rtsim-sim after (default: on PATH)")
    parser.add_argument("-o", "--out", type=Path, default=Path("out/stats_identity"))
    parser.add_argument("--quick", action="store_true", help=f"only {', '.join(QUICK_CONFIGS)}")
    args = parser.parse_args(argv)
    new_exe = args.new or find_sim()
    configs = {k: v for k, v in CONFIGS.items() if not args.quick or k in QUICK_CONFIGS}
    make_traces(args.out / "traces", list(TRACES))
    bad = 0
    for trace_name in TRACES:
        trace = args.out / "traces" / trace_name
        for config_name, sets in configs.items():
            key = f"{trace_name}/{config_name}"
            old = strip_host(run(args.old, trace, args.out / "old" / key, old_sets(sets)))
            new_dir = args.out / "new" / key
            for f in new_dir.glob("*.json"):
                f.unlink()  # the new binary always runs afresh
            new = old_names(strip_host(run(new_exe, trace, new_dir, sets)))
            diff = differences(old, new)
            if diff:
                bad += 1
                print(f"{key}: {len(diff)} differences")
                for line in diff[:8]:
                    print(f"    {line}")
            else:
                print(f"{key}: identical")
    runs = len(TRACES) * len(configs)
    print(f"{runs - bad} of {runs} runs identical")
    return 0 if bad == 0 else 1


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""How much of the design space composes (docs/capabilities.md, "How much composes"): every
execution model x structure x technique x level an architect would try, each run on a tiny
Cornell box (two levels: the grove) by one `rtsim-sim`, counted as run or refused, and the refused
ones by the rule or message that refused them.

The product: unit kinds mimd, simt (32 lanes, 32 ray contexts) and packet (16 rays); structures
bvh2, bvh4, bvh8, cwbvh8, kdtree, bih, octree, grid and two levels; no technique or one of
treelets, treelet prefetching (with queues, and without), the restart-trail short stack, 8-bit
boxes, mailboxes, ray sorting, compressed leaves (a build setting); levels functional, analytic,
approx, detailed and approx with 20% sampling. `--sim` may be an older rtsim-sim (the one key it
spelled differently, the lanes of simt and packet, is translated), so the same product gives
before-and-after counts. A combination the tracer refuses (a build setting) counts as refused.

Usage:
    python scripts/composition_matrix.py [--sim rtsim-sim] [--out out/composition] [--jobs 2]
        [--before OLD_RTSIM_SIM] [--write-docs]
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
from collections import Counter
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "python"))

from rtsim.doc_markers import write_between  # noqa: E402

UNITS = {
    "mimd": ["traversal.model=mimd"],
    "simt 32": ["traversal.model=simt", "LANES simt=32", "traversal.ray_contexts=32"],
    "packet 16": ["traversal.model=packet", "LANES packet=16", "traversal.ray_contexts=16"],
}
STRUCTURES = ["bvh2", "bvh4", "bvh8", "cwbvh8", "kdtree", "bih", "octree", "grid", "two_level"]
TECHNIQUES: dict[str, list[str]] = {
    "(none)": [],
    "treelets": ["treelets.enabled=true"],
    "treelet prefetching": ["treelets.enabled=true", "treelets.prefetch=true"],
    "prefetching, no queues": ["treelets.prefetch=true"],
    "restart trail": ["traversal.stack_overflow=restart_trail"],
    "8-bit boxes": ["traversal.box_precision_bits=7"],
    "mailbox": ["mailbox.entries=8"],
    "ray sorting": ["dispatch.sort=morton"],
    "compressed leaves": [],  # a build setting: the trace is built with it
}
LEVELS = {
    "functional": ["fidelity=functional"],
    "analytic": ["fidelity=analytic"],
    "approx": ["fidelity=approx"],
    "detailed": ["fidelity=detailed"],
    "20% sampling": ["fidelity=approx", "sampling.fraction=0.2"],
}


def lanes_key(sim: str) -> dict[str, str]:
    """How this simulator spells each kind's lanes: traversal.<kind>.lanes, or (before the unit
    kinds had sections of their own) one traversal.lanes."""
    schema = json.loads(subprocess.run([sim, "--dump-schema"], capture_output=True, text=True,
                                       check=True).stdout)
    fields = schema.get("traversal", {}).get("fields", {})
    own = "simt" in fields or "simt" in schema.get("traversal", {})
    return {k: f"traversal.{k}.lanes" if own else "traversal.lanes" for k in ("simt", "packet")}


def make_traces(out: Path) -> dict[tuple[str, bool], Path | str]:
    """A trace per structure, plain and with compressed leaves; the tracer's message where it
    refuses."""
    traces: dict[tuple[str, bool], Path | str] = {}
    for s in STRUCTURES:
        for compressed in (False, True):
            where = out / "traces" / (s + ("-cl" if compressed else ""))
            args = ["grove"] if s == "two_level" else ["cornell", "--accel", s]
            if compressed:
                args += ["--build-set", "compressed_leaves=true"]
            if not (where / "manifest.json").exists():
                made = subprocess.run(
                    ["rtsim", "trace", *args, "--resolution", "8x6", "-o", str(where)],
                    capture_output=True,
                    text=True,
                )
                if made.returncode != 0:
                    error = made.stderr.split("error: ", 1)[-1]
                    traces[(s, compressed)] = " ".join(error.split())
                    continue
            traces[(s, compressed)] = where
    return traces


def cells() -> list[dict[str, Any]]:
    return [
        {"unit": u, "structure": s, "technique": t, "level": lv}
        for u in UNITS
        for s in STRUCTURES
        for t in TECHNIQUES
        for lv in LEVELS
    ]


def run_cell(sim: str, lanes: dict[str, str], traces: dict, out: Path, i: int,
             cell: dict[str, Any]) -> dict[str, Any]:
    trace = traces[(cell["structure"], cell["technique"] == "compressed leaves")]
    if isinstance(trace, str):
        return {**cell, "ok": False, "by": "tracer", "message": trace}
    sets = []
    for a in UNITS[cell["unit"]] + TECHNIQUES[cell["technique"]] + LEVELS[cell["level"]]:
        if a.startswith("LANES "):
            kind, n = a[len("LANES "):].split("=")
            a = f"{lanes[kind]}={n}"
        sets += ["--set", a]
    run = out / "runs" / str(i)
    r = subprocess.run([sim, str(trace), "-o", str(run), "--no-verdict", *sets],
                       capture_output=True, text=True)
    shutil.rmtree(run, ignore_errors=True)
    message = " ".join(r.stderr.split())
    if r.returncode == 0:
        clean = "0 hit mismatches, 0 work mismatches" in message
        return {**cell, "ok": True, "clean": clean, "message": "" if clean else message[-300:]}
    return {**cell, "ok": False, "by": "simulator", "exit": r.returncode, "message": message}


def reason(result: dict[str, Any]) -> str:
    """What refused: the tracer, or the setting the simulator's message names and what it needs."""
    if result.get("by") == "tracer":
        return f"the tracer: {result['message'].split(' (')[0]}"
    m = result["message"]
    if "config: '" in m:
        asks, rest = m.split("config: '", 1)[1].split("'", 1)
        needs = rest.split(" needs ", 1)[-1].split(", which")[0].split(":")[0]
        return f"{asks.split('=')[0]} needs {needs}"
    return m.split("error: ", 1)[-1][:100]


def measure(sim: str, out: Path, jobs: int) -> list[dict[str, Any]]:
    lanes = lanes_key(sim)
    traces = make_traces(out)
    todo = cells()
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        return list(pool.map(lambda ic: run_cell(sim, lanes, traces, out, *ic), enumerate(todo)))


def summary(results: list[dict[str, Any]]) -> dict[str, Any]:
    refused = [r for r in results if not r["ok"]]
    by = lambda key: dict(Counter(r[key] for r in refused).most_common())  # noqa: E731
    return {
        "combinations": len(results),
        "run": len(results) - len(refused),
        "refused": len(refused),
        "unclean": sum(1 for r in results if r["ok"] and not r.get("clean")),
        "refused_by_unit": by("unit"),
        "refused_by_level": by("level"),
        "refused_by_technique": by("technique"),
        "refused_by_reason": dict(Counter(reason(r) for r in refused).most_common()),
    }


def markdown(after: dict[str, Any], before: dict[str, Any] | None, sim: str, old: str | None) -> str:
    cols = [("after", after)] + ([("before", before)] if before else [])
    lines = [
        f"Measured with `python scripts/composition_matrix.py"
        + (" --before OLD_RTSIM_SIM" if before else "")
        + f" --write-docs` ({after['combinations']:,} combinations: 3 unit kinds x 9 structures x "
        "9 techniques x 5 levels, each one `rtsim-sim` run on an 8x6 trace; after: "
        f"`{Path(sim).name}`" + (f", before: `{Path(old).name}`" if old else "") + ").",
        "",
        "| | " + " | ".join(c for c, _ in cols) + " |",
        "|---|" + "---:|" * len(cols),
        "| combinations run | " + " | ".join(f"{s['run']:,}" for _, s in cols) + " |",
        "| refused | " + " | ".join(f"{s['refused']:,}" for _, s in cols) + " |",
        "| run with a hit or work mismatch | "
        + " | ".join(f"{s['unclean']:,}" for _, s in cols) + " |",
    ]
    for title, key in (("unit kind", "refused_by_unit"), ("level", "refused_by_level"),
                       ("technique", "refused_by_technique")):
        names = list(dict.fromkeys(n for _, s in cols for n in s[key]))
        for n in names:
            lines.append(f"| refused, {title} {n} | "
                         + " | ".join(f"{s[key].get(n, 0):,}" for _, s in cols) + " |")
    lines += ["", "What refuses the remaining combinations (after), by the setting the refusal "
              "names and what it needs:", "", "| refused by | combinations |", "|---|---:|"]
    lines += [f"| {k} | {v:,} |" for k, v in after["refused_by_reason"].items()]
    return "\n".join(lines) + "\n"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sim", default="rtsim-sim", help="the simulator (default: rtsim-sim)")
    ap.add_argument("--before", help="an older rtsim-sim to count the same product with")
    ap.add_argument("--out", type=Path, default=Path("out/composition"))
    ap.add_argument("--jobs", type=int, default=2, help="runs at once (default: 2)")
    ap.add_argument("--write-docs", action="store_true",
                    help="write the counts between the composition-counts markers of "
                    "docs/capabilities.md")
    a = ap.parse_args()
    sim = shutil.which(a.sim) or a.sim
    after_results = measure(sim, a.out / "after", a.jobs)
    after = summary(after_results)
    before = None
    if a.before:
        before_results = measure(a.before, a.out / "before", a.jobs)
        before = summary(before_results)
        (a.out / "before.json").write_text(json.dumps(before_results, indent=1))
    (a.out / "after.json").write_text(json.dumps(after_results, indent=1))
    text = markdown(after, before, sim, a.before)
    print(text)
    if a.write_docs:
        write_between(REPO / "docs" / "capabilities.md", "composition-counts", text)
    return 1 if after["unclean"] else 0


if __name__ == "__main__":
    sys.exit(main())

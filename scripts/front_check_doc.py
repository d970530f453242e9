#!/usr/bin/env python3
"""The verdict checked on a sweep's Pareto front (docs/verdict.md, "Checked on a sweep's front").

Reads SWEEP/front_check.json (from `rtsim sweep SPEC -o SWEEP --check-front`) and writes a table
of every front design, with the knob its verdict named, that knob's estimate and measured gain,
and the best single knob among those re-run. With --docs the table goes into DOCS/verdict.md
between the `front-check` markers:

    rtsim sweep python/rtsim/specs/front_check.yaml -o out/front_check --check-front
    python scripts/front_check_doc.py out/front_check --docs docs
"""

from __future__ import annotations

import argparse
import datetime
import json
import platform
import statistics
from pathlib import Path
from typing import Any

from rtsim.doc_markers import write_between
from rtsim.sweep.store import open_store


def design(r: dict[str, Any]) -> str:
    params = ", ".join(f"{k}={v}" for k, v in r["params"].items() if k != "accel")
    return f"{r['scene']} {r['workload']}, {r['accel']}, {params}"


def x(v: float | None) -> str:
    return "-" if v is None else f"{v:.2f}x"


def within(named: float | None, best: float | None) -> bool:
    """The named knob's speed-up at least the best's / 1.10."""
    return named is not None and best is not None and named * 1.10 >= best


def table(sweep: Path) -> str:
    rows = json.loads((sweep / "front_check.json").read_text())
    with open_store(sweep, readonly=True) as store:
        designs = sum(1 for r in store.runs() if r.status == "ok")
    ok = [r for r in rows if "error" not in r]
    lines = [
        "| design | verdict names | estimated | measured | best single knob re-run (measured) "
        "| within 10% | best of the re-runs, pairs too |",
        "|---|---|---:|---:|---|:-:|---|",
    ]
    for r in rows:
        if "error" in r:
            lines.append(f"| {design(r)} | {r['error']} | | | | | |")
            continue
        lines.append(
            f"| {design(r)} | `{r['named']}` | {x(r['estimated'])} | {x(r['measured'])} | "
            f"`{r['best_single']}` {x(r['best_single_measured'])} | "
            f"{'yes' if within(r['measured'], r['best_single_measured']) else 'no'} | "
            f"`{r['best']}` {x(r['best_measured'])} |"
        )
    hits = sum(within(r["measured"], r["best_single_measured"]) for r in ok)
    errors = [
        abs(r["estimated"] - r["measured"]) / r["measured"]
        for r in ok
        if r["estimated"] is not None and r["measured"]
    ]
    median = statistics.median(errors) if errors else float("nan")
    date = datetime.date.today().isoformat()
    lines += [
        "",
        f"The named knob is within 10% of the best single knob re-run in **{hits} of {len(ok)}** "
        f"front designs; median error of its estimate against its measured gain: "
        f"**{100 * median:.1f}%**. Measured by `rtsim sweep python/rtsim/specs/front_check.yaml "
        f"--check-front` on {platform.node()} ({platform.machine()}), {date}: {designs} designs "
        f"swept, {len(rows)} on the rays/s-against-SRAM fronts (one per scene, workload and "
        "structure), each re-run with `--check-verdict` (its top three knobs, best co-limit and "
        "best structural alternatives, on the structures traced beside its trace) at the approx "
        "level; the named knob is the verdict's `relax`; table by `scripts/front_check_doc.py`.",
    ]
    return "\n".join(lines) + "\n"


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("sweep", type=Path, help="a sweep folder run with --check-front")
    p.add_argument("--docs", type=Path, default=None, help="write into DOCS/verdict.md")
    a = p.parse_args()
    text = table(a.sweep)
    print(text)
    if a.docs:
        write_between(a.docs / "verdict.md", "front-check", text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""`rtsim sweep ... --check-front`: re-run the Pareto front's verdicts (docs/sweeps.md).

A sweep's report draws a Pareto front of rays/s against on-chip SRAM per scene and workload.
Each design on it has a verdict (docs/verdict.md) that names the knob to relax next with an
estimated gain. This re-runs every front design with `--check-verdict` (rtsim-sim re-simulates
its top three knobs, best co-limit and best structural alternatives, each in its own process)
into SWEEP/front_check/<run>,
and sets the named knob's estimate beside its measured gain and the best measured one, so a user
can trust or overrule the front's verdicts in one command. The table is written to
SWEEP/front_check.json.
"""

from __future__ import annotations

import json
import shlex
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

from rtsim.launcher import SimJob, run_sim
from rtsim.report.data import pareto_front, sram_kib
from rtsim.sweep.store import RunRecord, open_store


def front_runs(records: list[RunRecord]) -> list[RunRecord]:
    """The ok runs on each (scene, workload, structure) group's rays/s-against-SRAM front."""
    groups: dict[tuple[str, str, str], list[RunRecord]] = {}
    for r in records:
        if r.status == "ok" and r.stats:
            groups.setdefault((r.scene, r.workload, r.accel), []).append(r)
    return [r for runs in groups.values() for r in pareto_front(runs, sram_kib)]


def run_folder(out: Path, rec: RunRecord) -> Path:
    """The sweep's folder of a run (OUT/runs/<scene>-<workload>-<accel>-<id12>)."""
    found = sorted((out / "runs").glob(f"*-{rec.run_id[:12]}"))
    if not found:
        raise FileNotFoundError(f"{out / 'runs'}: no folder of run {rec.run_id[:12]}")
    return found[0]


def _gain(x: Any) -> float | None:
    return float(x) if isinstance(x, (int, float)) else None


def check_one(out: Path, rec: RunRecord, timeout: float | None = None) -> dict[str, Any]:
    """Re-runs one front design with --check-verdict; its named knob, estimated and measured."""
    folder = run_folder(out, rec)
    command = shlex.split((folder / "command.txt").read_text())
    dest = out / "front_check" / folder.name
    job = SimJob(trace=Path(command[1]), out_dir=dest, config=folder / "config.json")
    job.check_verdict = True
    result = run_sim(job, timeout=timeout)
    row: dict[str, Any] = {"run": folder.name, "params": rec.params, "scene": rec.scene,
                           "workload": rec.workload, "accel": rec.accel}  # fmt: skip
    verdict = (result.stats or {}).get("verdict") or {}
    checks = verdict.get("check") or []
    # The knob the verdict names: its best candidate, or a structural alternative that pays
    # clearly more (`relax`); the first of `top` when it names none.
    top = verdict.get("relax") or (verdict.get("top") or [None])[0]
    if result.returncode != 0 or not top or not checks:
        row["error"] = result.describe_failure() if result.returncode else "no verdict to check"
        return row
    named = f"{top['key']}={json.dumps(top['to']) if not isinstance(top['to'], str) else top['to']}"
    mine = next((c for c in checks if c.get("sets") == [named]), None)
    best = max(checks, key=lambda c: _gain(c.get("measured")) or 0.0)
    singles = [c for c in checks if len(c.get("sets", [])) == 1] or checks
    best_single = max(singles, key=lambda c: _gain(c.get("measured")) or 0.0)
    row.update(
        named=named,
        estimated=_gain(top.get("speedup")),
        measured=_gain(mine.get("measured")) if mine else None,
        best=" + ".join(best.get("sets", [])),
        best_measured=_gain(best.get("measured")),
        best_single=" + ".join(best_single.get("sets", [])),
        best_single_measured=_gain(best_single.get("measured")),
    )
    return row


def check_front(
    out: Path,
    workers: int = 1,
    timeout: float | None = None,
    on_row: Callable[[dict[str, Any]], None] | None = None,
) -> list[dict[str, Any]]:
    """Checks every front design of the sweep in OUT; writes OUT/front_check.json."""
    with open_store(out, readonly=True) as store:
        records = list(store.runs())
    front = front_runs(records)
    rows: list[dict[str, Any]] = []
    with ThreadPoolExecutor(max_workers=max(1, workers)) as pool:
        for row in pool.map(lambda r: check_one(out, r, timeout), front):
            rows.append(row)
            if on_row is not None:
                on_row(row)
    (out / "front_check.json").write_text(json.dumps(rows, indent=1) + "\n")
    return rows


def pct(x: float | None) -> str:
    return "-" if x is None else f"{100 * (x - 1):+.0f}%"

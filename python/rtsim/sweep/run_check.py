"""The spec check's last step: every run of the spec resolved by the simulator itself before any
trace is made (docs/sweeps.md, "the spec check").

Each distinct (structure, config) pair of the spec is handed to ``rtsim-sim --check-runs``, which
applies the run's one resolution step (sim/resolve/: the config's ranges and field rules, the unit
kind's and techniques' needs against the structure's capabilities) and the model's memory
estimate, exactly as a run does. So packets on a kd-tree, restart trails on a grid or
``traversal.lanes: [5]`` with 16 contexts stop the sweep at the check, with the spec's line and key,
instead of failing in every run after every scene was traced. One set of rules answers for the
CLI, Python and sweeps.

Not checked here: what only the scene decides (an instanced scene is traced through two levels,
whose structure offers less than the single-level kind the check assumes).
"""

from __future__ import annotations

import json
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rtsim.config import SimConfig, effective_dict, flatten, unflatten

#: Seconds the check process may take (100,000 runs resolve in a few seconds).
CHECK_TIMEOUT = 300.0


@dataclass(frozen=True)
class CheckedRun:
    """One distinct run of a spec as the simulator checks it."""

    kind: str
    compressed_leaves: bool
    patch: dict[str, Any]  # the config as a patch over the defaults
    accel_label: str | None  # the accel axis entry (None: the spec has no axis)
    params: dict[str, Any]  # the swept values of the point


def config_patch(config: SimConfig) -> dict[str, Any]:
    """The fields of `config` (as the simulator sees it) that differ from the defaults."""
    flat, default = flatten(effective_dict(config)), flatten(SimConfig().to_dict())
    return unflatten({k: v for k, v in flat.items() if default.get(k) != v})


def resolve_runs(runs: list[CheckedRun]) -> list[dict[str, Any]]:
    """rtsim-sim --check-runs over the runs: [{ok, error, resolved}] in order. [] when there is
    no rtsim-sim to ask (the sweep then reports that itself)."""
    from rtsim.launcher import SimNotFoundError, find_sim

    try:
        exe = find_sim()
    except SimNotFoundError:
        return []
    items = [
        {"config": r.patch, "accel": r.kind, "compressed_leaves": r.compressed_leaves} for r in runs
    ]
    with tempfile.TemporaryDirectory(prefix="rtsim-check-") as tmp:
        path = Path(tmp) / "runs.json"
        path.write_text(json.dumps(items))
        done = subprocess.run(
            [str(exe), "--check-runs", str(path)],
            capture_output=True,
            text=True,
            timeout=CHECK_TIMEOUT,
            check=False,
        )
    if done.returncode != 0:
        raise RuntimeError(f"{exe} --check-runs failed: {done.stderr.strip()}")
    out = json.loads(done.stdout)
    if not isinstance(out, list) or len(out) != len(runs):
        raise RuntimeError(f"{exe} --check-runs: expected {len(runs)} answers")
    return out


def first_refusal(runs: list[CheckedRun]) -> tuple[CheckedRun, str] | None:
    """The first run the simulator would refuse, with its message; None when all resolve."""
    for run, answer in zip(runs, resolve_runs(runs), strict=False):
        if not answer.get("ok"):
            return run, str(answer.get("error") or "refused")
    return None


def describe(run: CheckedRun) -> str:
    """The run as the message names it: its structure and swept values."""
    parts = [f"accel={run.accel_label}"] if run.accel_label is not None else []
    parts += [
        f"{k}={json.dumps(v) if not isinstance(v, str) else v}" for k, v in run.params.items()
    ]
    return ", ".join(parts) if parts else "every run"

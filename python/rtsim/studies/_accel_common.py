"""What the structure comparisons share (the `accel`, `partition` and `structures` studies,
docs/accel.md): the build side from `rtsim-accel-study` (one thread, median of repeated builds:
build time, footprint, structure and node bytes, SAH cost), one spec per scene over every
structure and workload at the default config, per-ray work of each ray kind from the traces,
the rays whose hit differs from the binary BVH's, and the runs stopped at the study's time limit
(a row without model figures, not an error)."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import tempfile
from pathlib import Path
from typing import Any

from rtsim.scenes import resolve_scene
from rtsim.study import StudyRun
from rtsim.study.core import StudyError
from rtsim.study.traces import hits_differ, work_stats
from rtsim.sweep.spec import stable_hash

ACCEL_STUDY = "rtsim-accel-study"
REFERENCE = "bvh2"  # every structure's hits are compared with the binary BVH's


def find_accel_study() -> Path:
    """$RTSIM_ACCEL_STUDY, else the one installed in the package (rtsim/bin), else on PATH."""
    import rtsim

    env = os.environ.get("RTSIM_ACCEL_STUDY")
    if env:
        return Path(env)
    installed = Path(rtsim.__file__).resolve().parent / "bin" / ACCEL_STUDY
    if installed.is_file():
        return installed
    found = shutil.which(ACCEL_STUDY)
    if not found:
        raise StudyError(f"{ACCEL_STUDY} not found (build it, or set RTSIM_ACCEL_STUDY)")
    return Path(found)


def build_figures(run: StudyRun, scene: str, accels: list[str]) -> dict[str, Any]:
    """`rtsim-accel-study` on one scene for every structure in `accels` (kept in
    OUT/study/build-SCENE-HASH.json: other structures or repeats are measured again)."""
    o = run.options
    args = {"accels": accels, "repeats": o["repeats"], "tris": o["hairball_triangles"]}

    def measure() -> dict[str, Any]:
        with tempfile.TemporaryDirectory(prefix="rtsim-accel-study-") as tmp:
            path = Path(tmp) / "build.json"
            cmd = [str(find_accel_study()), resolve_scene(scene), "--accel", ",".join(accels)]
            cmd += ["--repeat", str(o["repeats"]), "--json", str(path)]
            cmd += ["--hairball-triangles", str(o["hairball_triangles"])]
            result = subprocess.run(cmd, capture_output=True, text=True, check=False)
            if result.returncode != 0:
                raise StudyError(f"{' '.join(cmd)} failed ({result.returncode}):\n{result.stderr}")
            return dict(json.loads(path.read_text()))

    return dict(run.cached(f"build-{scene}-{stable_hash(args, 8)}", measure))


def spec(
    name: str, scene: dict[str, Any], o: dict[str, Any], points: list[dict[str, Any]] | None = None
) -> dict[str, Any]:
    """One scene's spec: every structure and workload (one ray kind each) at the default config
    (or `points`), with the study's time limit per simulation."""
    out: dict[str, Any] = {
        "name": name,
        "scenes": [scene],
        "workloads": [
            {"name": w, "rays": [w], "resolution": o["resolution"]} for w in o["workloads"]
        ],
        "accel": list(o["accels"]),
    }
    if points:
        out["points"] = points
    if o["sim_timeout"]:
        out["timeout"] = o["sim_timeout"]
    return out


def label(accel: str) -> str:
    return accel.replace(":", " ")


def fmt(x: Any, digits: int = 1) -> str:
    """A figure with thousands separators (`digits` decimals for a float), `-` when missing."""
    if x is None:
        return "-"
    if isinstance(x, str):
        return x
    return f"{x:,.{digits}f}" if isinstance(x, float) else f"{x:,}"


def timed_out(row: dict[str, Any]) -> bool:
    """The run was stopped at the study's time limit (it has no model figures); any other
    failure stops the study."""
    if row["status"] == "ok":
        return False
    if str(row.get("error") or "").startswith("timed out"):
        return True
    raise StudyError(f"{row['scene']} {row['workload']} {row['accel']}: {row['error']}")


def ray_work(run: StudyRun, row: dict[str, Any], fields: tuple[str, ...]) -> dict[str, Any]:
    """Per-ray work of the row's ray kind (its workload traces one) over its trace, kept in
    OUT/study/work-TRACE.json."""
    folder = Path(row["trace_dir"])
    return dict(
        run.cached(
            f"work-{folder.name}-{'-'.join(fields)}",
            lambda: work_stats(folder, row["workload"], fields),
        )
    )


def reference_hits_differ(run: StudyRun, row: dict[str, Any], part: str) -> int | None:
    """Rays whose hit differs from the binary BVH's trace of the same scene and workload (None
    without one), kept in OUT/study/hits-TRACE.json."""
    ref = run.rows(part=part, workload=row["workload"], accel=REFERENCE)
    if not ref:
        return None
    folder, other = Path(row["trace_dir"]), Path(ref[0]["trace_dir"])
    return int(run.cached(f"hits-{folder.name}", lambda: hits_differ(folder, other)))

"""Runs a sweep: traces once per scene and workload, one rtsim-sim process per run, all
scheduled on Dask (a LocalCluster of single-threaded worker processes by default, or an existing
cluster with --scheduler tcp://HOST:PORT). The client is the store's only writer: each result is
written in its own transaction as it arrives, so a killed sweep resumes where it stopped.
"""

from __future__ import annotations

import logging
import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rich.console import Console

from rtsim import __version__
from rtsim.sweep.accel_axis import folder_label
from rtsim.sweep.lock import clean_stale_traces, sweep_lock
from rtsim.sweep.progress_bar import SweepBar
from rtsim.sweep.spec import RunPlan, SweepSpec, TracePlan
from rtsim.sweep.store import ResultsStore, RunRecord, open_store
from rtsim.sweep.tasks import SimTask, TraceTask, make_trace, run_sim, utc_now

DEFAULT_TIMEOUT = 3600.0
#: Between the specs of a store's `spec` meta (a YAML document separator).
SPEC_SEPARATOR = "\n---\n"
TRACE_TIMEOUT = 3600.0


@dataclass
class SweepOptions:
    out_dir: Path
    scheduler: str | None = None  # tcp://HOST:PORT, else a LocalCluster
    workers: int = 0  # LocalCluster workers; 0: one per core
    timeout: float | None = None  # per run, seconds; None: the spec's, else DEFAULT_TIMEOUT
    retry_failed: bool = False
    progress: bool = True


@dataclass
class SweepOutcome:
    total: int
    skipped: int
    ok: int = 0
    mismatch: int = 0
    failed: int = 0
    wall_seconds: float = 0.0
    failures: list[tuple[str, str]] = field(default_factory=list)  # (run dir name, error)


def run_dir_name(run: RunPlan) -> str:
    parts = (run.trace.scene.label, run.trace.workload.label, folder_label(run.trace.accel))
    return f"{'-'.join(parts)}-{run.run_id[:12]}"


def _resolved(scene: str) -> str:
    """The scene's path or name; an unknown one is passed on for `rtsim trace` to report."""
    from rtsim.scenes import resolve_scene

    try:
        return resolve_scene(scene)
    except ValueError:
        return scene


def trace_task(plan: TracePlan, out: Path) -> TraceTask:
    """The task that makes the plan's trace in OUT/traces (the sweep's trace cache)."""
    w = plan.workload
    return TraceTask(
        trace_dir=str(out / "traces" / plan.folder_name),
        scene=_resolved(plan.scene.source),
        rays=list(w.rays),
        width=w.width,
        height=w.height,
        bounces=w.bounces,
        seed=w.seed,
        hairball_triangles=plan.scene.hairball_triangles,
        accel=plan.accel.kind,
        builder=plan.accel.builder,
        build_settings=dict(plan.accel.settings),
        frames=w.frames,
        frame_policy=w.frame_policy,
        rebuild_threshold=w.rebuild_threshold,
        reflections=w.reflections,
        roulette_after=w.roulette_after,
        alternatives=w.alternatives,
        flatten=plan.scene.flatten,
        lights=plan.scene.lights,
    )


def _record(run: RunPlan, result: dict[str, Any]) -> RunRecord:
    return RunRecord(
        run_id=run.run_id,
        scene=run.trace.scene.label,
        workload=run.trace.workload.label,
        trace_id=run.trace.trace_id,
        preset=run.preset,
        status=result["status"],
        params=run.params,
        config=run.config.to_dict(),
        exit_code=result.get("exit_code"),
        error=result.get("error"),
        started_utc=result.get("started_utc"),
        finished_utc=result.get("finished_utc"),
        wall_seconds=result.get("wall_seconds"),
        worker=result.get("worker"),
        stats=result.get("stats"),
        provenance=result.get("provenance"),
    )


def _client(opts: SweepOptions) -> Any:
    from distributed import Client, LocalCluster

    if opts.scheduler:
        return Client(opts.scheduler, timeout="30s")
    workers = opts.workers or os.cpu_count() or 1
    cluster = LocalCluster(
        n_workers=workers,
        threads_per_worker=1,
        processes=True,
        dashboard_address=":0",
        silence_logs=logging.CRITICAL,  # task failures come back through futures
    )
    return Client(cluster)


def run_sweep(
    spec: SweepSpec | list[SweepSpec], opts: SweepOptions, console: Console
) -> SweepOutcome:
    """Runs every run of the spec not yet in the store (and failed ones with retry_failed).
    Several specs (a study's parts) run as one sweep into one store: one cluster, their runs
    merged (a run two parts ask for runs once)."""
    specs = spec if isinstance(spec, list) else [spec]
    out = opts.out_dir.resolve()
    out.mkdir(parents=True, exist_ok=True)
    with sweep_lock(out):
        stale = clean_stale_traces(out)
        if stale:
            console.print(f"removed {len(stale)} unfinished trace folder(s) of an earlier sweep")
        return _run_locked(specs, opts, out, console)


def _merged_runs(specs: list[SweepSpec]) -> list[RunPlan]:
    runs, seen = [], set()
    for spec in specs:
        for run in spec.runs():
            if run.run_id not in seen:
                seen.add(run.run_id)
                runs.append(run)
    return runs


def _run_locked(
    specs: list[SweepSpec], opts: SweepOptions, out: Path, console: Console
) -> SweepOutcome:
    spec = specs[0]
    runs = _merged_runs(specs)
    timeout = opts.timeout if opts.timeout is not None else (spec.timeout or DEFAULT_TIMEOUT)
    swept = list(dict.fromkeys(k for s in specs for k in s.swept_keys))
    with open_store(out) as store:
        # A store may hold several specs' runs (docs/sweeps.md): keep every spec swept into it
        # and every key they swept, so the report reads each run against its own spec.
        before = store.meta()
        texts = [t for t in before.get("spec", "").split(SPEC_SEPARATOR) if t.strip()]
        texts += [s.text for s in specs if s.text not in texts]
        old_keys = [k for k in before.get("swept_keys", "").split(",") if k]
        store.set_meta(
            {
                "name": spec.name,
                "spec": SPEC_SEPARATOR.join(texts),
                "rtsim_version": __version__,
                "swept_keys": ",".join(dict.fromkeys([*old_keys, *swept])),
            }
        )
        if "created_utc" not in store.meta():
            store.set_meta({"created_utc": utc_now()})
        store.ensure_columns([k for k in swept if k != "preset"])
        status = store.statuses()
        skip = {"ok", "mismatch"} | (set() if opts.retry_failed else {"failed"})
        todo = [r for r in runs if status.get(r.run_id) not in skip]
        outcome = SweepOutcome(total=len(runs), skipped=len(runs) - len(todo))
        shape = (
            f"{len(spec.scenes)} scenes x {len(spec.workloads)} workloads x "
            f"{len(spec.accels or [None])} structures x {len(spec.points())} configs"
            if len(specs) == 1
            else f"{len(specs)} specs"
        )
        console.print(
            f"[bold]rtsim sweep[/] {spec.name}: {len(runs)} runs ({shape}), "
            f"{outcome.skipped} already in {store.path.name}, {len(todo)} to run"
        )
        t0 = time.monotonic()
        if todo:
            _execute(todo, out, timeout, opts, store, outcome, console)
        outcome.wall_seconds = time.monotonic() - t0
    return outcome


def _execute(
    todo: list[RunPlan],
    out: Path,
    timeout: float,
    opts: SweepOptions,
    store: ResultsStore,
    outcome: SweepOutcome,
    console: Console,
) -> None:
    from distributed import as_completed

    client = _client(opts)
    try:
        where = (
            opts.scheduler
            or f"a local Dask cluster of {len(client.scheduler_info()['workers'])} workers"
        )
        console.print(f"scheduling on {where}")
        # Traces first; each trace's simulations are submitted when it is done, with its result
        # as a plain value: a future argument would pin them to the worker holding it.
        by_trace: dict[str, list[RunPlan]] = {}
        for run in todo:
            by_trace.setdefault(run.trace.trace_id, []).append(run)
        traces = {
            client.submit(
                make_trace,
                trace_task(runs[0].trace, out),
                TRACE_TIMEOUT,
                key=f"trace-{tid}",
                pure=False,
                retries=0,
                priority=10,
            ): tid
            for tid, runs in by_trace.items()
        }
        sims: dict[Any, RunPlan] = {}
        pending = as_completed(list(traces))
        with SweepBar(len(todo), opts.progress, console) as bar:
            for fut in pending:
                if fut in traces:
                    trace = _result(fut)
                    for run in by_trace[traces[fut]]:
                        sim = client.submit(
                            run_sim,
                            _sim_task(run, out, timeout),
                            trace,
                            key=f"sim-{run.run_id}",
                            pure=False,
                            retries=0,
                        )
                        sims[sim] = run
                        pending.add(sim)
                    continue
                run, result = sims.pop(fut), _result(fut)
                store.record(_record(run, result))
                bar.add(result["status"])
                setattr(outcome, result["status"], getattr(outcome, result["status"]) + 1)
                if result["status"] != "ok":
                    outcome.failures.append((run_dir_name(run), str(result.get("error"))))
    finally:
        cluster = getattr(client, "cluster", None)
        client.close()
        if cluster is not None:
            cluster.close()


def _sim_task(run: RunPlan, out: Path, timeout: float) -> SimTask:
    return SimTask(
        run.run_id,
        str(out / "traces" / run.trace.folder_name),
        str(out / "runs" / run_dir_name(run)),
        run.config.to_dict(),
        timeout,
    )


def _result(fut: Any) -> dict[str, Any]:
    """A task's result; a worker that died under it, or a cancelled task, is a failure."""
    try:
        return fut.result()
    except Exception as err:
        return {
            "status": "failed",
            "ok": False,
            "error": f"{type(err).__name__}: {err}",
            "finished_utc": utc_now(),
        }

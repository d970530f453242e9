"""`rtsim.sweep(...)`: a sweep from Python (a notebook, a script), the same as `rtsim sweep`:
the same spec (a dict of the YAML's shape, or the YAML file), the same local or Dask execution,
the same resumable store, and a progress bar in a terminal or a notebook. It returns the sweep's
`Results` (rtsim/sweep/results.py)."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from rtsim.errors import RtsimError
from rtsim.sweep.results import Results
from rtsim.sweep.spec import SweepSpec, load_spec, spec_from_dict

SpecLike = dict[str, Any] | str | os.PathLike[str] | SweepSpec


def as_spec(spec: SpecLike) -> SweepSpec:
    """A parsed spec from a dict, a YAML path or a parsed spec (SpecError names the key)."""
    if isinstance(spec, SweepSpec):
        return spec
    if isinstance(spec, dict):
        return spec_from_dict(spec)
    if isinstance(spec, (str, os.PathLike)):
        return load_spec(Path(spec))
    raise RtsimError(
        f"sweep: spec must be a dict, a YAML file's path or a SweepSpec, got {type(spec).__name__}"
    )


def sweep(
    spec: SpecLike | list[SpecLike],
    out: str | os.PathLike[str],
    *,
    workers: int = 0,
    scheduler: str | None = None,
    timeout: float | None = None,
    retry_failed: bool = False,
    progress: bool = True,
    quiet: bool = False,
) -> Results:
    """Runs every run of `spec` not yet in `out`'s store and returns the sweep's `Results`.

    - `spec`: a dict of the YAML's shape (docs/sweeps.md, "The spec"), the path of a spec file,
      or a list of them (one sweep into one store, a run asked for twice run once);
    - `out`: the sweep folder (traces, runs, results.sqlite); re-running resumes, as
      `rtsim sweep` does, and both fill the same store the same way;
    - `workers`: processes of the local Dask cluster (0: one per core); `scheduler`:
      `tcp://HOST:PORT` of an existing cluster instead;
    - `timeout`: seconds per run (default: the spec's, else an hour); `retry_failed`: re-run the
      runs recorded as failed;
    - `progress`: a progress bar (rich in a terminal, an updating line in a notebook);
      `quiet`: print nothing.

    A failed or mismatched run never raises: it is a row with its status and error
    (`results.counts()`, `results.outcome`). A bad spec raises `SpecError` before any run."""
    from rich.console import Console

    from rtsim.args import check_utf8_path
    from rtsim.sweep.runner import SweepOptions, run_sweep

    specs = [as_spec(s) for s in (spec if isinstance(spec, list) else [spec])]
    if not specs:
        raise RtsimError("sweep: an empty list of specs")
    check_utf8_path(os.fsdecode(out), "out")
    if not isinstance(workers, int) or isinstance(workers, bool) or workers < 0:
        raise RtsimError(f"sweep: workers must be a non-negative integer, got {workers!r}")
    opts = SweepOptions(
        out_dir=Path(out),
        scheduler=scheduler,
        workers=workers,
        timeout=timeout,
        retry_failed=retry_failed,
        progress=progress and not quiet,
    )
    console = Console(quiet=quiet, stderr=False)
    outcome = run_sweep(specs, opts, console)
    if not quiet:
        from rtsim.sweep.cli import print_outcome

        print_outcome(outcome, opts.out_dir, console)
    return Results(opts.out_dir, outcome)

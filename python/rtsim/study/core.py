"""The study machinery: options, running a study's specs through the sweep engine, its DataFrame,
and writing its tables and figures between the doc markers they own (docs/studies.md)."""

from __future__ import annotations

import datetime
import json
import platform
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rtsim.doc_markers import write_between
from rtsim.errors import RtsimError

if TYPE_CHECKING:
    import pandas as pd
    from rich.console import Console

    from rtsim.sweep.results import Extra, Results
    from rtsim.sweep.spec import SweepSpec
    from rtsim.sweep.store import RunRecord


class StudyError(RtsimError):
    """A study that cannot run or whose runs failed; the message names the study and the runs."""


@dataclass(frozen=True)
class Table:
    """A table (markdown text) of the study, written between `marker`'s markers of `doc` (a
    file of the docs folder)."""

    doc: str
    marker: str
    render: Callable[[StudyRun], str]


@dataclass(frozen=True)
class Figure:
    """A figure of the study, drawn by `draw(run, path)` into `path` of the docs folder."""

    path: str
    draw: Callable[[StudyRun, Path], None]


@dataclass
class Study:
    """A study: sweep specs from options, and tables and figures from the study's DataFrame.

    - `specs(options)`: the sweep specs (dicts of the YAML's shape) the study needs;
    - `follow_up(run)`: optional more specs chosen from the first runs' results (a second stage:
      the verdict study measures the knobs each design's verdict names);
    - `options`: the study's options and their defaults (`--option KEY=VALUE` on the command
      line, converted to the default's type; a list default takes `a,b,c`); `quick`: the values
      `--quick` sets (a small first look, and what the tests run);
    - `extra`: columns the study's DataFrame adds from each run's stats.json (a dotted path, or a
      function of the run's `RunRecord`);
    - `tables`, `figures`: what it writes, each a function of the `StudyRun`;
    - `allow_failed`: a run that failed is a row to report rather than an error (hit or work
      mismatches are always an error)."""

    name: str
    about: str
    specs: Callable[[dict[str, Any]], list[dict[str, Any]]]
    tables: list[Table] = field(default_factory=list)
    figures: list[Figure] = field(default_factory=list)
    options: dict[str, Any] = field(default_factory=dict)
    quick: dict[str, Any] = field(default_factory=dict)
    extra: dict[str, Extra] = field(default_factory=dict)
    follow_up: Callable[[StudyRun], list[dict[str, Any]]] | None = None
    allow_failed: bool = False

    def resolve(self, quick: bool, given: dict[str, str] | None = None) -> dict[str, Any]:
        """The options: defaults, then the quick values, then `given` (text, converted)."""
        opts = {**self.options, **(self.quick if quick else {})}
        for key, text in (given or {}).items():
            if key not in self.options:
                known = ", ".join(self.options) or "none"
                raise StudyError(f"study {self.name}: unknown option '{key}' (options: {known})")
            opts[key] = _convert(text, self.options[key], f"study {self.name}: option {key}")
        return opts


def _convert(text: Any, like: Any, where: str) -> Any:
    if not isinstance(text, str):
        return text
    try:
        if isinstance(like, bool):
            if text.lower() not in ("true", "false", "1", "0", "yes", "no"):
                raise ValueError(text)
            return text.lower() in ("true", "1", "yes")
        if isinstance(like, int):
            return int(text)
        if isinstance(like, float):
            return float(text)
        if isinstance(like, list):
            items = [t.strip() for t in text.split(",") if t.strip()]
            kind = type(like[0]) if like else str
            return [kind(t) for t in items]
    except ValueError:
        raise StudyError(f"{where}: {text!r} is not a {type(like).__name__}") from None
    return text


@dataclass
class StudyRun:
    """A study's runs and its DataFrame: `frame` has one row per planned point of its specs (a
    point two specs share appears under each), the sweep's tidy columns (docs/sweeps.md), the
    study's extra columns, `part` (the spec's name) and `trace_dir`."""

    study: Study
    options: dict[str, Any]
    quick: bool
    out: Path
    results: Results
    specs: list[SweepSpec]
    frame: pd.DataFrame
    records: dict[str, RunRecord] = field(default_factory=dict)  # run_id -> its record
    plain: list[dict[str, Any]] = field(default_factory=list)  # the frame's rows, plain values

    def rows(self, **where: Any) -> list[dict[str, Any]]:
        """The frame's rows as dicts (plain Python values, None where missing), optionally only
        those whose columns equal `where` (`run.rows(scene="sponza", point="baseline")`)."""
        return [r for r in self.plain if all(r.get(k) == v for k, v in where.items())]

    def row(self, **where: Any) -> dict[str, Any]:
        """The one row matching `where` (StudyError if none or several)."""
        found = self.rows(**where)
        if len(found) != 1:
            raise StudyError(f"study {self.study.name}: {len(found)} rows match {where}")
        return found[0]

    def stats(self, row: dict[str, Any]) -> dict[str, Any]:
        """A row's whole stats.json."""
        return dict(self.records[row["run_id"]].stats or {})

    @property
    def command(self) -> str:
        """The command that makes this study's output, with the options it was given."""
        base = self.study.resolve(self.quick)
        given = [f"--option {k}={_text(v)}" for k, v in self.options.items() if v != base.get(k)]
        return " ".join(
            ["rtsim study", self.study.name, *(["--quick"] if self.quick else []), *given]
        )

    @property
    def runs(self) -> int:
        """Distinct runs behind the frame (a point two specs share is one run)."""
        return int(self.frame["run_id"].nunique())

    @property
    def sim_seconds(self) -> float:
        """The runs' own wall time, summed (from the store: the same when a re-run reuses them)."""
        seen = self.frame.drop_duplicates("run_id")
        return float(sum(self.records[r].wall_seconds or 0 for r in seen["run_id"]))

    def measured(self) -> dict[str, str]:
        """Where and when: host, machine, today's date, the rtsim-sim git hashes of the runs."""
        gits = sorted(
            {
                str((self.records[r].provenance or {}).get("git"))
                for r in self.frame["run_id"].unique()
            }
        )
        return {
            "host": platform.node() or "host",
            "machine": platform.machine(),
            "date": datetime.date.today().isoformat(),
            "git": ", ".join(gits),
        }

    def cached(self, name: str, make: Callable[[], Any]) -> Any:
        """A measurement that is not a simulation (a build timing, a trace's work counts), kept
        as JSON in OUT/study/NAME.json and reused when the study is run again."""
        path = self.out / "study" / f"{name}.json"
        if path.is_file():
            return json.loads(path.read_text())
        value = make()
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(value, indent=1, default=str) + "\n")
        return value


def _text(value: Any) -> str:
    return ",".join(map(str, value)) if isinstance(value, list) else str(value)


def build_frame(
    specs: list[SweepSpec], results: Results, extra: dict[str, Extra]
) -> tuple[pd.DataFrame, dict[str, RunRecord], list[dict[str, Any]]]:
    """One row per planned point of the specs, in spec order: the run's tidy columns and the
    extra columns, with the plan's own swept values (its `point` label) and `part`."""
    import pandas as pd

    from rtsim.sweep.results import Column, _stats_path

    records = {r.run_id: r for r in results.records()}
    cols = results.columns(list(records.values()))
    for name, how in extra.items():
        cols.append(Column(name, "", str(how), _stats_path(how) if isinstance(how, str) else how))
    rows = []
    for spec in specs:
        for plan in spec.plans():
            rec = records.get(plan.run_id)
            row: dict[str, Any] = {c.name: c.get(rec) for c in cols} if rec else {}
            row.update(
                run_id=plan.run_id,
                scene=plan.trace.scene.label,
                workload=plan.trace.workload.label,
                accel=plan.trace.accel.label,
                status=rec.status if rec else "missing",
            )
            row.update(plan.params)
            row["part"] = spec.name
            row["trace_dir"] = str(results.path / "traces" / plan.trace.folder_name)
            rows.append(row)
    frame = pd.DataFrame(rows)
    frame.attrs["units"] = {c.name: c.unit for c in cols}
    return frame, records, rows


def run_study(
    study: Study,
    out: str | Path,
    *,
    quick: bool = False,
    options: dict[str, str] | None = None,
    workers: int = 0,
    scheduler: str | None = None,
    progress: bool = True,
    console: Console | None = None,
) -> StudyRun:
    """Runs the study's specs (and its follow-up) through the sweep engine into `out` and
    returns its `StudyRun`; raises StudyError when a run mismatched (or failed, unless the study
    allows it)."""
    from rich.console import Console

    from rtsim.sweep.results import Results
    from rtsim.sweep.runner import SweepOptions, run_sweep
    from rtsim.sweep.spec import spec_from_dict

    console = console or Console(stderr=True)
    opts = study.resolve(quick, options)
    out = Path(out)
    sweep_opts = SweepOptions(out_dir=out, scheduler=scheduler, workers=workers, progress=progress)

    def parse(dicts: list[dict[str, Any]]) -> list[SweepSpec]:
        return [spec_from_dict(d, f"study {study.name}: {d.get('name', 'spec')}") for d in dicts]

    specs = parse(study.specs(opts))
    t0 = time.monotonic()
    run_sweep(specs, sweep_opts, console)
    results = Results(out)
    run = StudyRun(
        study, opts, quick, out, results, specs, *build_frame(specs, results, study.extra)
    )
    if study.follow_up is not None:
        specs = specs + parse(study.follow_up(run))
        run_sweep(specs, sweep_opts, console)
        run.specs = specs
        run.frame, run.records, run.plain = build_frame(specs, results, study.extra)
    _check(run)
    console.print(f"study {study.name}: {run.runs} runs, {time.monotonic() - t0:.0f} s -> {out}")
    run.frame.to_csv(out / "study.csv", index=False)
    return run


def _check(run: StudyRun) -> None:
    bad = run.frame[run.frame["status"] != "ok"].drop_duplicates("run_id")
    failed = bad[bad["status"] == "mismatch"] if run.study.allow_failed else bad
    if len(failed):
        lines = [
            f"  {r.scene} {r.workload} {r.accel} {r.run_id[:12]}: {r.status} "
            f"{str(r.error or '').splitlines()[:1]}"
            for r in failed.itertuples()
        ]
        raise StudyError(f"study {run.study.name}: {len(failed)} runs not ok:\n" + "\n".join(lines))


def write_outputs(run: StudyRun, docs: Path | None, console: Console) -> dict[str, str]:
    """Renders every table (printed; written between its markers when `docs` is given) and
    draws every figure into `docs` (or into OUT/figures without `docs`)."""
    texts = {}
    for table in run.study.tables:
        text = table.render(run)
        texts[table.marker] = text
        console.print(f"[bold]{table.doc} {table.marker}[/]", highlight=False)
        print(text)
        if docs is not None:
            write_between(docs / table.doc, table.marker, text)
    for fig in run.study.figures:
        path = (docs if docs is not None else run.out / "figures") / fig.path
        path.parent.mkdir(parents=True, exist_ok=True)
        fig.draw(run, path)
        console.print(f"figure: {path}", highlight=False)
    return texts

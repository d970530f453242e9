"""A sweep's results: the `Results` object (`rtsim.sweep(...)` returns one, `rtsim.open_results`
opens one) and the tidy table of its runs as a DataFrame, CSV, Parquet or plain text.

One row per run, in a stable order (scene, workload, then each swept key by value); the columns
are declared once in rtsim/sweep/columns.py, so `to_pandas()`, `rtsim results` and its `--csv`
and `--parquet` files have the same columns in the same order.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rtsim.config import config_keys, flatten
from rtsim.sweep.columns import (
    DATA_KINDS,
    Column,
    bytes_per_ray_by_kind,
    columns,
    key_value,
    sram_bytes,
    swept_keys,
)
from rtsim.sweep.store import RunRecord, open_store

if TYPE_CHECKING:
    import pandas as pd

    from rtsim.stats import Stats
    from rtsim.sweep.runner import SweepOutcome

__all__ = [
    "DATA_KINDS",
    "Results",
    "bytes_per_ray_by_kind",
    "key_value",
    "open_results",
    "results_order",
    "sram_bytes",
    "tidy_row",
    "tidy_rows",
    "to_csv",
]

#: An extra column of `to_pandas(extra=...)`: a dotted stats.json path, or a function of a run.
Extra = str | Callable[[RunRecord], Any]


def results_order(records: list[RunRecord], keys: list[str]) -> list[RunRecord]:
    """Runs in a stable, readable order: by scene, workload, then each swept key's value
    (numbers by value, 2 before 16; text by name), never the order they happened to finish."""

    def rank(value: Any) -> tuple[int, float, str]:
        if isinstance(value, bool) or value is None:
            return (2, 0.0, str(value))
        if isinstance(value, int | float):
            return (0, float(value), "")
        return (1, 0.0, str(value))

    return sorted(
        records,
        key=lambda r: (r.scene, r.workload, *(rank(key_value(r, k)[0]) for k in keys)),
    )


def _stats_path(path: str) -> Callable[[RunRecord], Any]:
    parts = path.split(".")

    def get(rec: RunRecord) -> Any:
        node: Any = rec.stats or {}
        for part in parts:
            node = node.get(part) if isinstance(node, dict) else None
        return node

    return get


class Results:
    """The runs of one sweep folder (its `results.sqlite`), read when asked: a sweep still
    writing, or resumed later, is seen as it is now.

    >>> results = rtsim.sweep(spec, "out/s1")       # or rtsim.open_results("out/s1")
    >>> df = results.to_pandas()                    # one row per run, tidy columns
    >>> df.attrs["units"]["mrays_per_second"]       # 'Mrays/s'
    """

    def __init__(self, sweep_dir: str | Path, outcome: SweepOutcome | None = None) -> None:
        self.path = Path(sweep_dir)
        #: What the sweep that returned this object did (None when opened from a folder).
        self.outcome = outcome
        with open_store(self.path, readonly=True):
            pass  # a missing, empty or foreign store is refused now, naming the file

    def records(self, status: str | None = None) -> list[RunRecord]:
        """Every run (or those of one status) in the table's order."""
        with open_store(self.path, readonly=True) as store:
            records = list(store.runs(status))
            stored = store.swept_keys()
        return results_order(records, swept_keys(records, stored))

    def __iter__(self) -> Iterator[RunRecord]:
        return iter(self.records())

    def __len__(self) -> int:
        with open_store(self.path, readonly=True) as store:
            return sum(store.count().values())

    def counts(self) -> dict[str, int]:
        """Runs per status (`ok`, `mismatch`, `failed`)."""
        with open_store(self.path, readonly=True) as store:
            return store.count()

    def swept_keys(self) -> list[str]:
        """Every key any run swept (the config keys of the grid, points and sampling, and
        `accel`, `preset`, `point` where the spec used them)."""
        with open_store(self.path, readonly=True) as store:
            return swept_keys(list(store.runs()), store.swept_keys())

    def columns(self, records: list[RunRecord] | None = None) -> list[Column]:
        """The tidy table's columns: name, unit, meaning (docs/sweeps.md lists them)."""
        records = self.records() if records is None else records
        return columns(records, swept_keys(records, self.swept_keys()))

    def rows(self, config: bool = False) -> tuple[list[Column], list[dict[str, Any]]]:
        """The columns and one dict per run; `config=True` adds every config key."""
        records = self.records()
        cols = self.columns(records)
        if config:
            cols = _with_config(cols)
        return cols, [{c.name: c.get(r) for c in cols} for r in records]

    def to_pandas(
        self, config: bool = False, extra: dict[str, Extra] | None = None
    ) -> pd.DataFrame:
        """The tidy table as a DataFrame: one row per run. Units and meanings are in
        `df.attrs["units"]` and `df.attrs["docs"]`; `config=True` adds a column per config key;
        `extra` adds columns from each run's stats.json (`{"l2_reads": "model.l2.reads"}`, or a
        function of the run's `RunRecord`)."""
        import pandas as pd

        records = self.records()
        cols = self.columns(records)
        if config:
            cols = _with_config(cols)
        for name, how in (extra or {}).items():
            get = _stats_path(how) if isinstance(how, str) else how
            cols.append(Column(name, "", how if isinstance(how, str) else "extra", get))
        df = pd.DataFrame(
            [[c.get(r) for c in cols] for r in records], columns=[c.name for c in cols]
        )
        df.attrs["units"] = {c.name: c.unit for c in cols}
        df.attrs["docs"] = {c.name: c.doc for c in cols}
        df.attrs["sweep"] = str(self.path)
        return df

    def to_csv(self, path: str | Path | None = None, config: bool = False) -> str:
        """The tidy table as CSV text (also written to `path` when given)."""
        cols, rows = self.rows(config)
        text = to_csv(rows, [c.name for c in cols])
        if path is not None:
            Path(path).write_text(text)
        return text

    def to_parquet(self, path: str | Path, config: bool = False) -> None:
        """The tidy table as a Parquet file (needs pyarrow: `pip install rtsim[parquet]`); the
        column units travel in the file's schema metadata."""
        try:
            import pyarrow as pa
            import pyarrow.parquet as pq
        except ImportError as err:
            raise ImportError("Parquet needs pyarrow: pip install 'rtsim[parquet]'") from err
        df = self.to_pandas(config)
        table = pa.Table.from_pandas(df, preserve_index=False)
        units = {k: v for k, v in df.attrs["units"].items() if v}
        meta = {**(table.schema.metadata or {}), b"rtsim.units": json_bytes(units)}
        pq.write_table(table.replace_schema_metadata(meta), str(path))

    def stats(self, run_id: str) -> Stats:
        """One run's whole stats.json (as `rtsim.Stats`)."""
        from rtsim.stats import Stats

        rec = self.record(run_id)
        if rec.stats is None:
            raise KeyError(f"run {run_id} has no stats ({rec.status}: {rec.error})")
        return Stats(rec.stats)

    def record(self, run_id: str) -> RunRecord:
        """One run's record; a unique prefix of its id is enough."""
        found = [r for r in self.records() if r.run_id.startswith(run_id)]
        if len(found) != 1:
            raise KeyError(f"{self.path}: {len(found)} runs have an id starting {run_id!r}")
        return found[0]

    def run_dir(self, run_id: str) -> Path:
        """The run's folder (config.json, stats.json, provenance.json, stderr.log)."""
        return _one(self.path / "runs", f"*-{self.record(run_id).run_id[:12]}")

    def trace_dir(self, run_id: str) -> Path:
        """The folder of the trace the run replayed (`rtsim.open_trace` reads it)."""
        return _one(self.path / "traces", f"*-{self.record(run_id).trace_id[:8]}")

    def __repr__(self) -> str:
        counts = self.counts()
        what = ", ".join(f"{n} {s}" for s, n in sorted(counts.items())) or "no runs"
        return f"<rtsim.Results {self.path}: {what}>"

    def _repr_html_(self) -> str:
        return f"<p>{self!r}</p>" + self.to_pandas().to_html(max_rows=20, na_rep="-")


def _one(folder: Path, pattern: str) -> Path:
    found = sorted(p for p in folder.glob(pattern) if p.is_dir())
    if len(found) != 1:
        raise FileNotFoundError(f"{folder}: {len(found)} folders match {pattern}")
    return found[0]


def _with_config(cols: list[Column]) -> list[Column]:
    """The columns with every config key not already there, after the swept keys."""
    have = {c.name for c in cols}
    extra = [
        Column(k, "", "config key", lambda r, k=k: flatten(r.config or {}).get(k))
        for k in config_keys()
        if k not in have
    ]
    first_summary = next(i for i, c in enumerate(cols) if c.source.startswith("summary"))
    return [*cols[:first_summary], *extra, *cols[first_summary:]]


def json_bytes(data: Any) -> bytes:
    import json

    return json.dumps(data).encode()


def open_results(sweep_dir: str | Path) -> Results:
    """The results of a sweep folder (a finished sweep, or one still running)."""
    return Results(sweep_dir)


def tidy_row(rec: RunRecord) -> dict[str, Any]:
    """One run's row (its own columns, as a table of this run alone would have)."""
    cols = columns([rec], list(rec.params))
    return {c.name: c.get(rec) for c in cols}


def tidy_rows(records: list[RunRecord]) -> list[dict[str, Any]]:
    cols = columns(records, swept_keys(records))
    return [{c.name: c.get(r) for c in cols} for r in records]


def to_csv(rows: list[dict[str, Any]], names: list[str] | None = None) -> str:
    """CSV with the given columns (default: the union, in first-seen order)."""
    if names is None:
        names = list(dict.fromkeys(k for row in rows for k in row))
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=names, lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: _csv_cell(row.get(k)) for k in names})
    return buf.getvalue()


def _csv_cell(value: Any) -> Any:
    if isinstance(value, bool):
        return "true" if value else "false"
    return "" if value is None else value


def text_cell(value: Any) -> str:
    """A value as `rtsim results` prints it: short, never cut."""
    if value is None:
        return "-"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        if value != value:  # NaN
            return "-"
        return f"{value:.0f}" if abs(value) >= 1e5 else f"{value:.4g}"
    text = str(value)
    return text.splitlines()[0] if text else "-"


def text_table(names: list[str], rows: list[dict[str, Any]]) -> str:
    """Plain aligned columns under their full names (no truncation, no colour, numbers to the
    right): readable in a terminal, through a pipe, with `less -S` or `column`."""
    cells = [[text_cell(r.get(n)) for n in names] for r in rows]
    widths = [max([len(n), *(len(row[i]) for row in cells)]) for i, n in enumerate(names)]
    numeric = [
        any(isinstance(r.get(n), int | float) for r in rows)
        and all(isinstance(r.get(n), int | float) or r.get(n) is None for r in rows)
        for n in names
    ]

    def line(texts: list[str]) -> str:
        parts = [
            t.rjust(w) if num else t.ljust(w)
            for t, w, num in zip(texts, widths, numeric, strict=True)
        ]
        return "  ".join(parts).rstrip()

    return "\n".join([line(names), *(line(row) for row in cells)]) + "\n"

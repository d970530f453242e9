"""The results store: one SQLite file per sweep (SWEEP/results.sqlite), one row per run.

Why SQLite (docs/sweeps.md): it is in the standard library, one file, and every write is an
ACID transaction, so a sweep killed at any instant leaves either the whole row of a run or none
of it. Only the sweep's client process writes (results come back to it from the workers), so
there is never write contention; WAL mode lets `rtsim results` / `rtsim report` read while a
sweep is writing.

Schema (version 1):
  meta(key, value)       sweep name, spec text, created time, rtsim version
  runs(run_id PRIMARY KEY, scene, workload, trace_id, preset, status, exit_code, error,
       started_utc, finished_utc, wall_seconds, worker, attempts,
       params_json, config_json, stats_json, provenance_json,
       "<swept key>" ... one column per swept key, added as keys appear: the config keys of
       the grid and sampling, and `accel` when the spec has an accel axis)
"""

from __future__ import annotations

import functools
import json
import sqlite3
from collections.abc import Callable, Iterator
from contextlib import closing, contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

from rtsim.errors import RtsimError

F = TypeVar("F", bound=Callable[..., Any])

SCHEMA_VERSION = "1"
STATUSES = ("ok", "mismatch", "failed")
DB_NAME = "results.sqlite"

_RUNS = """
CREATE TABLE IF NOT EXISTS runs (
  run_id TEXT PRIMARY KEY,
  scene TEXT NOT NULL,
  workload TEXT NOT NULL,
  trace_id TEXT NOT NULL,
  preset TEXT NOT NULL,
  status TEXT NOT NULL CHECK (status IN ('ok', 'mismatch', 'failed')),
  exit_code INTEGER,
  error TEXT,
  started_utc TEXT,
  finished_utc TEXT,
  wall_seconds REAL,
  worker TEXT,
  attempts INTEGER NOT NULL DEFAULT 1,
  params_json TEXT NOT NULL,
  config_json TEXT NOT NULL,
  stats_json TEXT,
  provenance_json TEXT
)"""
_FIXED = (
    "run_id",
    "scene",
    "workload",
    "trace_id",
    "preset",
    "status",
    "exit_code",
    "error",
    "started_utc",
    "finished_utc",
    "wall_seconds",
    "worker",
    "params_json",
    "config_json",
    "stats_json",
    "provenance_json",
)


@dataclass
class RunRecord:
    """One run's row: identity, outcome and the full config, stats and provenance."""

    run_id: str
    scene: str
    workload: str
    trace_id: str
    preset: str
    status: str
    params: dict[str, Any]
    config: dict[str, Any]
    exit_code: int | None = None
    error: str | None = None
    started_utc: str | None = None
    finished_utc: str | None = None
    wall_seconds: float | None = None
    worker: str | None = None
    stats: dict[str, Any] | None = None
    provenance: dict[str, Any] | None = None
    attempts: int = 1
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def summary(self) -> dict[str, Any]:
        return (self.stats or {}).get("summary", {})

    @property
    def accel(self) -> str:
        """The acceleration structure the run's trace was made with (its label on the spec's
        `accel` axis; a spec without one traces with the default structure)."""
        return str(self.params.get("accel", "bvh2"))


class StoreError(RtsimError):
    """A results store that SQLite cannot read (truncated, corrupt, not a database) or that is
    not an rtsim results store; the message names the file."""


@contextmanager
def _store_errors(path: Path) -> Iterator[None]:
    """SQLite's and JSON's errors on a damaged or foreign store, as StoreError naming it."""
    try:
        yield
    except (sqlite3.DatabaseError, json.JSONDecodeError, KeyError, IndexError) as err:
        raise StoreError(
            f"{path}: not a readable rtsim results store ({type(err).__name__}: {err}); "
            "move it away and re-run the sweep to rebuild it"
        ) from err


def _checked(method: F) -> F:
    @functools.wraps(method)
    def wrapper(self: ResultsStore, *args: Any, **kwargs: Any) -> Any:
        with _store_errors(self.path):
            return method(self, *args, **kwargs)

    return wrapper  # type: ignore[return-value]


def _quote(name: str) -> str:
    return '"' + name.replace('"', '""') + '"'


class ResultsStore:
    """SQLite results of one sweep. Use as a context manager; writes are one transaction each."""

    def __init__(self, path: Path, readonly: bool = False) -> None:
        self.path = Path(path)
        if self.path.exists() and not self.path.is_file():
            # SQLite cannot open a folder, FIFO or device ("unable to open database file").
            raise StoreError(
                f"{self.path}: a folder, FIFO or device, not a results store; move it away "
                "(the sweep then makes a new store there)"
            )
        if readonly and not self.path.is_file():
            raise FileNotFoundError(f"{self.path}: no results store here (run `rtsim sweep`)")
        with _store_errors(self.path):
            self.conn = sqlite3.connect(self.path, timeout=30, isolation_level=None)
        self.conn.row_factory = sqlite3.Row
        try:
            with _store_errors(self.path):
                self._open(readonly)
        except BaseException:
            self.conn.close()
            raise

    def _open(self, readonly: bool) -> None:
        # A store is this schema or empty: a foreign database is never written into.
        tables = {r[0] for r in self.conn.execute("SELECT name FROM sqlite_master")}
        if tables and not {"meta", "runs"} <= tables:
            raise StoreError(
                f"{self.path}: an SQLite database but not an rtsim results store (its tables: "
                f"{', '.join(sorted(tables))}); give the sweep another folder"
            )
        if readonly and not tables:
            raise StoreError(f"{self.path}: an empty results store (run `rtsim sweep`)")
        check = self.conn.execute("PRAGMA quick_check").fetchone()[0]
        if check != "ok":
            raise sqlite3.DatabaseError(f"quick_check: {check}")
        if not readonly:
            self.conn.execute("PRAGMA journal_mode=WAL")
            self.conn.execute("PRAGMA synchronous=FULL")
            with self.transaction():
                self.conn.execute(
                    "CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, value TEXT)"
                )
                self.conn.execute(_RUNS)
                self.conn.execute(
                    "INSERT OR IGNORE INTO meta VALUES ('schema_version', ?)", (SCHEMA_VERSION,)
                )

    def __enter__(self) -> ResultsStore:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        self.conn.close()

    def transaction(self) -> _Transaction:
        return _Transaction(self.conn)

    @_checked
    def columns(self) -> list[str]:
        return [r["name"] for r in self.conn.execute("PRAGMA table_info(runs)")]

    def swept_keys(self) -> list[str]:
        known = {*_FIXED, "attempts"}
        return [c for c in self.columns() if c not in known]

    @_checked
    def ensure_columns(self, keys: list[str]) -> None:
        """Adds a column per swept key not seen before (a resumed spec may sweep more)."""
        missing = [k for k in keys if k not in set(self.columns())]
        if missing:
            with self.transaction():
                for key in missing:
                    self.conn.execute(f"ALTER TABLE runs ADD COLUMN {_quote(key)}")

    @_checked
    def set_meta(self, values: dict[str, str]) -> None:
        with self.transaction():
            for k, v in values.items():
                self.conn.execute("INSERT OR REPLACE INTO meta VALUES (?, ?)", (k, v))

    @_checked
    def meta(self) -> dict[str, str]:
        return {r["key"]: r["value"] for r in self.conn.execute("SELECT key, value FROM meta")}

    @_checked
    def statuses(self) -> dict[str, str]:
        """run_id -> status of every recorded run."""
        return {r[0]: r[1] for r in self.conn.execute("SELECT run_id, status FROM runs")}

    @_checked
    def record(self, rec: RunRecord) -> None:
        """Writes one run atomically; a re-run of a recorded id replaces its row (attempts+1)."""
        if rec.status not in STATUSES:
            raise ValueError(f"status must be one of {STATUSES}, got {rec.status!r}")
        values: dict[str, Any] = {
            "run_id": rec.run_id,
            "scene": rec.scene,
            "workload": rec.workload,
            "trace_id": rec.trace_id,
            "preset": rec.preset,
            "status": rec.status,
            "exit_code": rec.exit_code,
            "error": rec.error,
            "started_utc": rec.started_utc,
            "finished_utc": rec.finished_utc,
            "wall_seconds": rec.wall_seconds,
            "worker": rec.worker,
            "params_json": json.dumps(rec.params),
            "config_json": json.dumps(rec.config, sort_keys=True),
            "stats_json": json.dumps(rec.stats) if rec.stats is not None else None,
            "provenance_json": json.dumps(rec.provenance) if rec.provenance is not None else None,
        }
        swept = {k: v for k, v in rec.params.items() if k not in values}
        self.ensure_columns(list(swept))
        names = [*values, *swept]
        cells = [*values.values(), *(_cell(v) for v in swept.values())]
        cols = ", ".join(_quote(n) for n in names)
        marks = ", ".join("?" for _ in names)
        update = ", ".join(f"{_quote(n)} = excluded.{_quote(n)}" for n in names if n != "run_id")
        with self.transaction():
            self.conn.execute(
                f"INSERT INTO runs ({cols}) VALUES ({marks}) ON CONFLICT(run_id) DO UPDATE SET "
                f"{update}, attempts = runs.attempts + 1",
                cells,
            )

    def runs(self, status: str | None = None) -> Iterator[RunRecord]:
        query = "SELECT * FROM runs" + (" WHERE status = ?" if status else "")
        query += " ORDER BY scene, workload, rowid"
        with (
            _store_errors(self.path),
            closing(self.conn.execute(query, (status,) if status else ())) as cur,
        ):
            for row in cur:
                yield _from_row(row)

    @_checked
    def count(self) -> dict[str, int]:
        rows = self.conn.execute("SELECT status, COUNT(*) FROM runs GROUP BY status")
        return {r[0]: r[1] for r in rows}


class _Transaction:
    """BEGIN IMMEDIATE ... COMMIT, or ROLLBACK on an exception."""

    def __init__(self, conn: sqlite3.Connection) -> None:
        self.conn = conn

    def __enter__(self) -> sqlite3.Connection:
        self.conn.execute("BEGIN IMMEDIATE")
        return self.conn

    def __exit__(self, exc_type: object, *rest: object) -> None:
        self.conn.execute("ROLLBACK" if exc_type else "COMMIT")


def _cell(value: Any) -> Any:
    return value if isinstance(value, (int, float, str)) or value is None else json.dumps(value)


def _loads(text: str | None) -> Any:
    return json.loads(text) if text else None


def _from_row(row: sqlite3.Row) -> RunRecord:
    return RunRecord(
        run_id=row["run_id"],
        scene=row["scene"],
        workload=row["workload"],
        trace_id=row["trace_id"],
        preset=row["preset"],
        status=row["status"],
        params=_loads(row["params_json"]) or {},
        config=_loads(row["config_json"]) or {},
        exit_code=row["exit_code"],
        error=row["error"],
        started_utc=row["started_utc"],
        finished_utc=row["finished_utc"],
        wall_seconds=row["wall_seconds"],
        worker=row["worker"],
        stats=_loads(row["stats_json"]),
        provenance=_loads(row["provenance_json"]),
        attempts=row["attempts"],
    )


def open_store(sweep_dir: Path, readonly: bool = False) -> ResultsStore:
    return ResultsStore(Path(sweep_dir) / DB_NAME, readonly=readonly)

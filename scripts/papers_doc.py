#!/usr/bin/env python3
"""The papers page (docs/papers.md): each published figure of a memory-traffic technique beside
ours. One row per figure: the technique, the paper, the published figure, the setup it came from,
our figure on the closest setup rtsim runs, and why the two differ.

Rows come from modules `scripts/papers/*_rows.py`; each exposes `rows(out_dir, quick)` returning
a list of dicts with exactly the keys of COLUMNS (strings), measured from runs it makes under
`out_dir` (`quick`: small runs, for tests and a first look). The generator imports every such
module, caches each module's rows in OUT/<module>.json, and writes the table between the `papers`
markers of docs/papers.md, so the page cannot go stale: re-run it.

    python scripts/papers_doc.py [--out out/papers] [--quick] [--only treelet_rows,...]

`--only` re-runs the named modules and takes the others' rows from their caches (a module with no
cache is run).
"""

from __future__ import annotations

import argparse
import datetime
import importlib.util
import json
import platform
import sys
import time
from pathlib import Path
from types import ModuleType
from typing import Any

REPO = Path(__file__).resolve().parents[1]
MODULES = Path(__file__).resolve().parent / "papers"
sys.path.insert(0, str(REPO / "python"))

from rtsim.doc_markers import write_between  # noqa: E402

COLUMNS = {
    "technique": "technique",
    "paper": "paper",
    "published": "published figure",
    "setup": "their setup",
    "ours": "ours (closest setup we run)",
    "why": "why they differ",
}


class RowsError(ValueError):
    """A rows module broke the contract; the message names the module and the key."""


def row_modules(folder: Path = MODULES) -> list[Path]:
    return sorted(folder.glob("*_rows.py"))


def load(path: Path) -> ModuleType:
    spec = importlib.util.spec_from_file_location(f"papers_{path.stem}", path)
    if spec is None or spec.loader is None:
        raise RowsError(f"{path}: cannot be imported")
    module = importlib.util.module_from_spec(spec)
    sys.path.insert(0, str(path.parent))  # rows modules may share helpers beside them
    try:
        spec.loader.exec_module(module)
    finally:
        sys.path.remove(str(path.parent))
    if not callable(getattr(module, "rows", None)):
        raise RowsError(f"{path.name}: has no rows(out_dir, quick) function")
    return module


def check(rows: Any, name: str) -> list[dict[str, str]]:
    """The module's rows, checked: a list of dicts with exactly COLUMNS' keys, string values."""
    if not isinstance(rows, list):
        raise RowsError(f"{name}: rows() returned {type(rows).__name__}, not a list")
    for i, r in enumerate(rows):
        if not isinstance(r, dict):
            raise RowsError(f"{name}: row {i} is {type(r).__name__}, not a dict")
        missing, extra = set(COLUMNS) - set(r), set(r) - set(COLUMNS)
        if missing or extra:
            raise RowsError(
                f"{name}: row {i} lacks {sorted(missing)} / has unknown {sorted(extra)} keys"
            )
        for key in COLUMNS:
            if not isinstance(r[key], str) or not r[key].strip():
                raise RowsError(f"{name}: row {i} key '{key}' must be a non-empty string")
    return rows


def collect(
    out: Path, quick: bool, only: set[str] | None = None, folder: Path = MODULES
) -> list[dict[str, str]]:
    """Every module's rows in module order: run (or, outside `only`, read from its cache)."""
    result: list[dict[str, str]] = []
    for path in row_modules(folder):
        cache = out / f"{path.stem}.json"
        if only is not None and path.stem not in only and cache.is_file():
            rows = json.loads(cache.read_text())
        else:
            (out / path.stem).mkdir(parents=True, exist_ok=True)
            rows = load(path).rows(out / path.stem, quick)
            check(rows, path.name)
            cache.write_text(json.dumps(rows, indent=1))
        result += check(rows, path.name)
    return result


def cell(text: str) -> str:
    return " ".join(text.split()).replace("|", "\\|")


def render(rows: list[dict[str, str]]) -> str:
    lines = [
        "| " + " | ".join(COLUMNS.values()) + " |",
        "|" + "---|" * len(COLUMNS),
    ]
    lines += ["| " + " | ".join(cell(r[k]) for k in COLUMNS) + " |" for r in rows]
    return "\n".join(lines) + "\n"


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path, default=REPO / "out" / "papers")
    p.add_argument("--quick", action="store_true", help="small runs (a first look, tests)")
    p.add_argument("--only", default="", help="comma-separated module names to re-run")
    p.add_argument("--docs", type=Path, default=REPO / "docs")
    args = p.parse_args()
    start = time.perf_counter()
    only = {m.strip() for m in args.only.split(",") if m.strip()} or None
    args.out.mkdir(parents=True, exist_ok=True)
    rows = collect(args.out, args.quick, only)
    note = (
        f"Generated by `python scripts/papers_doc.py{' --quick' if args.quick else ''}` on "
        f"{datetime.date.today().isoformat()} ({platform.node() or 'host'}, "
        f"{platform.machine()}); each row's runs and settings are in its module under "
        "`scripts/papers/`, every run has 0 hit and 0 work mismatches.\n\n"
    )
    write_between(args.docs / "papers.md", "papers", note + render(rows))
    print(render(rows))
    print(f"{len(rows)} rows, {time.perf_counter() - start:.0f} s; wrote {args.docs / 'papers.md'}")


if __name__ == "__main__":
    main()

"""`rtsim study`: runs one of the project's studies (or a file with a `STUDY`) through the sweep
engine and prints its tables; `--write-docs` writes them between their doc markers and draws the
figures into the docs folder (docs/studies.md)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

from rtsim.cli_help import HelpFormatter

if TYPE_CHECKING:
    from rich.console import Console


def cmd_study(args: argparse.Namespace, console: Console) -> int:
    from rich.console import Console

    from rtsim import studies
    from rtsim.study.core import StudyError, run_study, write_outputs

    if args.list or not args.name:
        for name in studies.names():
            study = studies.load(name)
            console.print(f"[bold]{name}[/]: {study.about}", highlight=False)
        return 0
    study = studies.load(args.name)
    given = {}
    for item in args.option or []:
        key, sep, value = item.partition("=")
        if not sep:
            raise StudyError(f"--option {item!r}: expected KEY=VALUE")
        given[key.strip()] = value.strip()
    out = Path(args.output or f"out/studies/{study.name}{'-quick' if args.quick else ''}")
    err = Console(stderr=True)
    run = run_study(
        study,
        out,
        quick=args.quick,
        options=given,
        workers=args.workers,
        scheduler=args.scheduler,
        progress=not args.no_progress,
        console=err,
    )
    docs = Path(args.docs) if args.write_docs else None
    if docs is not None and not docs.is_dir():
        raise StudyError(f"--docs {docs}: not a folder")
    write_outputs(run, docs, err)
    return 0


def add_parser(sub: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    p = sub.add_parser(
        "study",
        formatter_class=HelpFormatter,
        help="run a study: a sweep plus its tables and figures (docs/studies.md)",
        description="Runs a study's sweep specs (re-running reuses every finished run in its "
        "folder), prints its tables, and with --write-docs writes them between the markers they "
        "own in the docs and draws its figures there.",
    )
    p.add_argument(
        "name", nargs="?", metavar="NAME|FILE.py", help="a study (--list) or a file defining STUDY"
    )
    p.add_argument("--list", action="store_true", help="list the studies")
    p.add_argument("--quick", action="store_true", help="the study's quick mode: small runs")
    p.add_argument(
        "--option",
        action="append",
        metavar="KEY=VALUE",
        help="a study option (repeatable; docs/studies.md names them; default: none)",
    )
    p.add_argument(
        "-o",
        "--output",
        metavar="OUT",
        default=None,
        help="the study's sweep folder (default: out/studies/NAME[-quick])",
    )
    p.add_argument(
        "--write-docs",
        action="store_true",
        help="write the tables between their markers and the figures into --docs",
    )
    p.add_argument("--docs", metavar="DIR", default="docs", help="the docs folder (default: docs)")
    p.add_argument(
        "--workers",
        type=int,
        default=0,
        metavar="N",
        help="local Dask workers (default: one per core)",
    )
    p.add_argument(
        "--scheduler",
        metavar="tcp://HOST:PORT",
        default=None,
        help="an existing Dask scheduler (default: a local cluster)",
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_study)

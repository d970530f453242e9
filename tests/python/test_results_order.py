"""`rtsim results` lists runs in a readable order (scene, workload, swept values by value), not
in the order they finished, and never cuts a column's header."""

from __future__ import annotations

import io
import re

from rich.console import Console

from rtsim.sweep.cli import results_order
from rtsim.sweep.store import RunRecord


def record(run_id: str, scene: str, units: int, policy: str) -> RunRecord:
    params = {"traversal.units": units, "dispatch.policy": policy}
    return RunRecord(run_id, scene, "diffuse", "t", "base", "ok", params, {})


def test_rows_sorted_by_swept_values_not_completion() -> None:
    finished = [
        record("a", "sponza", 16, "on_demand"),
        record("b", "hairball", 8, "interleaved"),
        record("c", "sponza", 2, "on_demand"),
        record("d", "sponza", 2, "interleaved"),
    ]
    ordered = results_order(finished, ["traversal.units", "dispatch.policy"])
    assert [r.run_id for r in ordered] == ["b", "d", "c", "a"]  # 2 before 16: numbers by value


def test_headers_are_never_cut(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    """A narrow terminal or a pipe: `rtsim results` prints every column under its full name."""
    import argparse

    import rtsim.sweep.cli as cli
    from rtsim.sweep.store import open_store

    records = [record(str(i), "sponza", 2**i, "interleaved") for i in range(3)]
    with open_store(tmp_path) as store:
        for r in records:
            store.record(r)
    console = Console(file=io.StringIO(), width=40, color_system=None)
    cli.cmd_results(argparse.Namespace(sweep=str(tmp_path), csv=None), console)
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 1 + len(records)
    for header in ("traversal.units", "dispatch.policy", "scene", "status"):
        assert re.search(rf"(^|\s){re.escape(header)}(\s|$)", lines[0]), (header, lines[0])
    assert [line.split()[0] for line in lines[1:]] == ["0", "1", "2"]  # by units: 1, 2, 4

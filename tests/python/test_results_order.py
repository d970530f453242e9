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


def test_headers_are_never_cut(monkeypatch, tmp_path) -> None:  # type: ignore[no-untyped-def]
    import argparse

    import rtsim.sweep.cli as cli

    records = [record(str(i), "sponza", 2**i, "interleaved") for i in range(3)]

    class Store:
        def __enter__(self) -> Store:
            return self

        def __exit__(self, *a: object) -> None:
            return None

        def runs(self) -> list[RunRecord]:
            return records

    monkeypatch.setattr("rtsim.sweep.store.open_store", lambda *a, **k: Store())
    out = io.StringIO()
    console = Console(file=out, width=80, color_system=None)
    cli.cmd_results(argparse.Namespace(sweep=str(tmp_path), csv=None), console)
    text = out.getvalue()
    for header in ("traversal.units", "dispatch.policy", "DRAM B/ray", "Mrays/s"):
        assert re.search(re.escape(header), text), (header, text)

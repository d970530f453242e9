"""The `rtsim simulate` summary tables (python/rtsim/sim_summary.py): DRAM row-buffer outcomes."""

from __future__ import annotations

from typing import Any

from rich.console import Console

from rtsim.sim_summary import utilisation_table


def rendered(stats: dict[str, Any]) -> str:
    console = Console(record=True, width=160)
    console.print(utilisation_table(stats))
    return console.export_text()


def test_row_buffer_outcomes_shown_with_the_bank_model() -> None:
    stats = {
        "summary": {"dram_bytes": 640},
        "model": {"dram": {"row_hits": 2, "row_misses": 1, "row_conflicts": 1}},
    }
    text = rendered(stats)
    assert "DRAM row buffers (hit / miss / conflict)" in text
    assert "50.0% / 25.0% / 25.0%" in text


def test_no_row_buffer_line_with_bandwidth_calendars() -> None:
    text = rendered({"summary": {"dram_bytes": 640}, "model": {"dram": {"reads": 10}}})
    assert "row buffers" not in text

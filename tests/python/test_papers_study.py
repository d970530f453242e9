"""The papers study (rtsim/studies/papers.py): its table's rows and their contract, on stub rows
(the real rows come from simulations; the same check holds them when the page is generated)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from rtsim.studies import papers
from rtsim.study.core import StudyError

REPO = Path(__file__).resolve().parents[2]

ROWS = [
    {"technique": "T1", "paper": "P 2010", "published": "-90% | traffic", "setup": "big",
     "ours": "-50%", "why": "small scene"},
    {"technique": "T2", "paper": "Q 2023", "published": "+32%", "setup": "GPU",
     "ours": "+5%\nnew line", "why": "no warps"},
]  # fmt: skip


def cells(line: str) -> list[str]:
    return [c.strip() for c in re.split(r"(?<!\\)\|", line)[1:-1]]


def test_table_has_one_row_per_figure_and_six_columns() -> None:
    lines = papers.render(papers.check(ROWS, "stub")).splitlines()
    assert len(lines) == 2 + 2
    assert cells(lines[0]) == list(papers.COLUMNS.values())
    for line in lines[2:]:
        assert len(cells(line)) == 6, line
    assert cells(lines[2])[2] == r"-90% \| traffic"  # a pipe in a cell is escaped
    assert cells(lines[3])[4] == "+5% new line"  # newlines folded


@pytest.mark.parametrize(
    ("rows", "message"),
    [
        ({}, r"papers bad: rows are a dict"),
        (
            [{"technique": "x"}],
            r"papers bad: row 0 lacks \['ours', 'paper', 'published', 'setup', 'why'\]",
        ),
        ([{**ROWS[0], "ours": ""}], "papers bad: row 0 key 'ours' must be a non-empty string"),
        ([{**ROWS[0], "extra": "x"}], r"has unknown \['extra'\] keys"),
    ],
)
def test_contract_errors_name_the_group_and_key(rows: object, message: str) -> None:
    with pytest.raises(StudyError, match=message):
        papers.check(rows, "bad")


def test_the_study_runs_every_group_and_writes_both_tables() -> None:
    specs = papers.specs(papers.STUDY.resolve(quick=True))
    parts = {s["name"].split("-")[1] for s in specs}
    assert parts == {"leaves", "shortstack", "treelets"}
    assert {(t.doc, t.marker) for t in papers.STUDY.tables} == {
        ("papers.md", "papers"),
        ("accel.md", "compressed-leaves"),
    }


def test_the_page_has_its_markers_and_the_readme_links_it() -> None:
    page = (REPO / "docs" / "papers.md").read_text()
    assert "<!-- papers:begin -->" in page and "<!-- papers:end -->" in page
    assert "docs/papers.md" in (REPO / "README.md").read_text()

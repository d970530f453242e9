"""scripts/papers_doc.py: the papers page's generator on stub rows modules (the real modules run
simulations; their rows are checked by the same contract when the page is generated)."""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path
from types import ModuleType

import pytest

REPO = Path(__file__).resolve().parents[2]


def generator() -> ModuleType:
    spec = importlib.util.spec_from_file_location("papers_doc", REPO / "scripts" / "papers_doc.py")
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


STUB = """
CALLS = []
def rows(out_dir, quick):
    (out_dir / "ran").write_text(str(quick))
    return [
        {"technique": "T1", "paper": "P 2010", "published": "-90% | traffic", "setup": "big",
         "ours": "-50%", "why": "small scene"},
        {"technique": "T2", "paper": "Q 2023", "published": "+32%", "setup": "GPU",
         "ours": "+5%\\nnew line", "why": "no warps"},
    ]
"""


def cells(line: str) -> list[str]:
    return [c.strip() for c in re.split(r"(?<!\\)\|", line)[1:-1]]


def test_table_has_one_row_per_figure_and_six_columns(tmp_path: Path) -> None:
    g = generator()
    (tmp_path / "mods").mkdir()
    (tmp_path / "mods" / "stub_rows.py").write_text(STUB)
    (tmp_path / "mods" / "helper.py").write_text("X = 1\n")  # not a rows module: ignored
    rows = g.collect(tmp_path / "out", True, folder=tmp_path / "mods")
    assert (tmp_path / "out" / "stub_rows" / "ran").read_text() == "True"
    lines = g.render(rows).splitlines()
    assert len(lines) == 2 + 2
    assert cells(lines[0]) == list(g.COLUMNS.values())
    for line in lines[2:]:
        assert len(cells(line)) == 6, line
    assert cells(lines[2])[2] == r"-90% \| traffic"  # a pipe in a cell is escaped
    assert cells(lines[3])[4] == "+5% new line"  # newlines folded


def test_only_reruns_named_modules_and_reads_the_others_from_cache(tmp_path: Path) -> None:
    g = generator()
    mods = tmp_path / "mods"
    mods.mkdir()
    (mods / "a_rows.py").write_text(STUB)
    (mods / "b_rows.py").write_text(STUB)
    first = g.collect(tmp_path / "out", True, folder=mods)
    (mods / "b_rows.py").write_text("def rows(out_dir, quick):\n    raise SystemExit('ran')\n")
    assert g.collect(tmp_path / "out", True, only={"a_rows"}, folder=mods) == first


@pytest.mark.parametrize(
    ("body", "message"),
    [
        ("def rows(out_dir, quick):\n    return {}\n", r"bad_rows.py: rows\(\) returned dict"),
        (
            "def rows(out_dir, quick):\n    return [{'technique': 'x'}]\n",
            r"bad_rows.py: row 0 lacks \['ours', 'paper', 'published', 'setup', 'why'\]",
        ),
        (
            "def rows(out_dir, quick):\n    return [dict(technique='t', paper='p', "
            "published='x', setup='s', ours='', why='w')]\n",
            "bad_rows.py: row 0 key 'ours' must be a non-empty string",
        ),
        ("X = 1\n", r"bad_rows.py: has no rows\(out_dir, quick\) function"),
    ],
)
def test_contract_errors_name_the_module_and_key(tmp_path: Path, body: str, message: str) -> None:
    g = generator()
    (tmp_path / "bad_rows.py").write_text(body)
    with pytest.raises(g.RowsError, match=message):
        g.collect(tmp_path / "out", True, folder=tmp_path)


def test_the_page_has_its_markers_and_the_readme_links_it() -> None:
    page = (REPO / "docs" / "papers.md").read_text()
    assert "<!-- papers:begin -->" in page and "<!-- papers:end -->" in page
    assert "docs/papers.md" in (REPO / "README.md").read_text()

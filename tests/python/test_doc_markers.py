"""python/rtsim/doc_markers.py: generated text between markers, the prose around it untouched."""

from __future__ import annotations

from pathlib import Path

import pytest

from rtsim.doc_markers import replace_between, write_between

DOC = "intro\n<!-- t:begin -->\nold\n<!-- t:end -->\nafter\n"


def test_replaces_only_between_the_markers() -> None:
    assert (
        replace_between(DOC, "t", "new") == "intro\n<!-- t:begin -->\nnew\n<!-- t:end -->\nafter\n"
    )
    assert replace_between(DOC, "t", "new\n") == replace_between(DOC, "t", "new")


def test_missing_markers_name_the_doc_and_the_markers(tmp_path: Path) -> None:
    doc = tmp_path / "x.md"
    doc.write_text("no markers\n")
    with pytest.raises(ValueError, match=r"x\.md: no <!-- other:begin -->"):
        write_between(doc, "other", "text")


def test_write_between_rewrites_the_file(tmp_path: Path) -> None:
    doc = tmp_path / "x.md"
    doc.write_text(DOC)
    write_between(doc, "t", "a\nb")
    assert doc.read_text() == "intro\n<!-- t:begin -->\na\nb\n<!-- t:end -->\nafter\n"


def test_end_marker_before_begin_is_named() -> None:
    with pytest.raises(ValueError, match="comes before"):
        replace_between("<!-- t:end -->\n<!-- t:begin -->\n", "t", "x")

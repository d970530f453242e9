"""Generated text between `<!-- NAME:begin -->` and `<!-- NAME:end -->` markers in a doc.

The studies (`rtsim study NAME`, rtsim/study) and the doc-generator scripts
(scripts/gen_stats_doc.py) write their tables this way, so the prose
around a table stays hand written and the table stays reproducible.
"""

from __future__ import annotations

from pathlib import Path


def markers(name: str) -> tuple[str, str]:
    return f"<!-- {name}:begin -->", f"<!-- {name}:end -->"


def replace_between(content: str, name: str, text: str, where: str = "the doc") -> str:
    """`content` with what lies between the NAME markers replaced by `text` (newline-framed)."""
    begin, end = markers(name)
    if begin not in content or end not in content:
        raise ValueError(f"{where}: no {begin} ... {end} markers to write between")
    head, rest = content.split(begin, 1)
    if end not in rest:
        raise ValueError(f"{where}: {end} comes before {begin}")
    _, tail = rest.split(end, 1)
    body = text if text.endswith("\n") else text + "\n"
    return f"{head}{begin}\n{body}{end}{tail}"


def write_between(doc: Path, name: str, text: str) -> None:
    """Rewrites `doc` with `text` between its NAME markers."""
    doc.write_text(replace_between(doc.read_text(), name, text, str(doc)))

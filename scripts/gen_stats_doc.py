#!/usr/bin/env python3
"""Writes the stats tables of docs/stats.md from the simulator's declarations: each block declares
its stats once, in C++, beside its code (rtl_model/common/stats.h; `rtsim-sim
--dump-stats-schema` prints them), and each table sits between `<!-- stats PATH:begin -->` and
`<!-- stats PATH:end -->` markers (tests/python/test_stats_doc.py checks they agree).

    python scripts/gen_stats_doc.py [--sim PATH] [--check]
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import subprocess
import sys
from pathlib import Path
from typing import Any

from rtsim.doc_markers import replace_between

REPO = Path(__file__).resolve().parents[1]
DOC = REPO / "docs" / "stats.md"


def find_sim() -> str:
    """rtsim-sim found as gen_config_doc.py finds it."""
    spec = importlib.util.spec_from_file_location(
        "gen_config_doc", REPO / "scripts" / "gen_config_doc.py"
    )
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return str(module.find_sim())


def load_schema(sim: str | None = None) -> list[dict[str, Any]]:
    """[{path, stats: [{key, unit, meaning, timed, optional}]}, ...] of every block."""
    out = subprocess.run(
        [sim or find_sim(), "--dump-stats-schema"], capture_output=True, text=True, check=True
    )
    return json.loads(out.stdout)


def render_table(stats: list[dict[str, Any]]) -> str:
    lines = ["| key | unit | meaning |", "|---|---|---|"]
    for d in stats:
        lines.append(f"| `{d['key']}` | {d['unit']} | {d['meaning']} |")
    return "\n".join(lines)


def render(doc: str, schema: list[dict[str, Any]]) -> str:
    """The doc with every block's table between its markers replaced."""
    for block in schema:
        doc = replace_between(doc, f"stats {block['path']}", render_table(block["stats"]), str(DOC))
    return doc


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sim", default=None, help="rtsim-sim to ask (default: as rtsim finds it)")
    p.add_argument("--check", action="store_true", help="exit 1 if docs/stats.md is out of date")
    args = p.parse_args()
    doc = DOC.read_text()
    new = render(doc, load_schema(args.sim))
    if args.check:
        return 0 if new == doc else 1
    DOC.write_text(new)
    return 0


if __name__ == "__main__":
    sys.exit(main())

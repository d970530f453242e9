#!/usr/bin/env python3
"""Writes the generated part of docs/capabilities.md from the simulator's one resolution step
(`rtsim-sim --capabilities-markdown`: what each structure offers, what each unit kind needs,
what each level costs, every rule and the composition matrix, each cell resolved by the same
code a run uses), between its `<!-- capabilities:begin -->` and `<!-- capabilities:end -->`
markers.

    python scripts/gen_capabilities_doc.py [--sim PATH] [--check]

tests/python/test_capabilities.py fails when the page is out of date.
"""

from __future__ import annotations

import argparse
import importlib.util
import subprocess
import sys
from pathlib import Path

from rtsim.doc_markers import replace_between

REPO = Path(__file__).resolve().parents[1]
DOC = REPO / "docs" / "capabilities.md"


def find_sim() -> str:
    """rtsim-sim found as gen_config_doc.py finds it."""
    spec = importlib.util.spec_from_file_location(
        "gen_config_doc", REPO / "scripts" / "gen_config_doc.py"
    )
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return str(module.find_sim())


def render(doc: str, sim: str | None = None) -> str:
    out = subprocess.run(
        [sim or find_sim(), "--capabilities-markdown"], capture_output=True, text=True, check=True
    )
    return replace_between(doc, "capabilities", out.stdout.strip(), str(DOC))


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sim", default=None, help="rtsim-sim executable (default: found)")
    p.add_argument("--check", action="store_true", help="fail if the page is out of date")
    args = p.parse_args()
    doc = DOC.read_text()
    new = render(doc, args.sim)
    if args.check:
        if new != doc:
            print(f"{DOC} is out of date: run python scripts/gen_capabilities_doc.py")
            return 1
        print(f"{DOC} is up to date")
        return 0
    DOC.write_text(new)
    print(f"wrote {DOC}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

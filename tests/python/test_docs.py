"""Every code block of README.md and docs/*.md works as written (rules: doc_blocks.py)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import REPO
from doc_blocks import Block, blocks, command_problems, rtsim_commands
from rtsim.cli import build_parser
from rtsim.sweep.spec import parse_spec

DOCS = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]
BLOCK_TIMEOUT = 300


def doc_id(path: Path) -> str:
    return str(path.relative_to(REPO))


def block_env() -> dict[str, str]:
    """The test's environment (RTSIM_SIM, RTSIM_SCENES, ...) with this Python's scripts first on
    PATH, so `rtsim` and `python` are the ones under test."""
    env = dict(os.environ)
    env["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{env.get('PATH', '')}"
    env.setdefault("RTSIM_SCENES", str(REPO.parent / "shared" / "scenes"))
    return env


def run_block(block: Block, cwd: Path) -> None:
    if block.lang == "python":
        cmd = [sys.executable, "-c", block.code]
    else:
        cmd = ["bash", "-euo", "pipefail", "-c", block.code]
    result = subprocess.run(
        cmd,
        cwd=cwd,
        env=block_env(),
        capture_output=True,
        text=True,
        timeout=BLOCK_TIMEOUT,
        check=False,
    )
    assert result.returncode == 0, (
        f"{block.where} ({block.lang}) failed with exit {result.returncode}:\n"
        f"{block.code}\n--- stdout\n{result.stdout[-2000:]}\n--- stderr\n{result.stderr[-4000:]}"
    )


@pytest.mark.parametrize("doc", DOCS, ids=doc_id)
def test_code_blocks_run(doc: Path, tmp_path: Path) -> None:
    ran = 0
    for block in blocks(doc):
        if block.marker == "skip":
            assert block.reason, f"{block.where}: a skipped block must say why"
            continue
        if block.lang == "python" or (block.lang in ("sh", "bash") and block.marker == "run"):
            run_block(block, tmp_path)
            ran += 1
    if doc.name == "README.md":
        assert ran >= 2  # the Python and the command-line quick starts


@pytest.mark.parametrize("doc", DOCS, ids=doc_id)
def test_documented_commands_exist(doc: Path) -> None:
    parser = build_parser()
    problems = []
    for block in blocks(doc):
        if block.lang in ("sh", "bash") and block.marker != "skip":
            for command in rtsim_commands(block.code):
                found = command_problems(command, parser)
                problems += [f"{block.where}: {p}: {command}" for p in found]
    assert not problems, "\n".join(problems)


@pytest.mark.parametrize("doc", DOCS, ids=doc_id)
def test_documented_specs_parse(doc: Path) -> None:
    for block in blocks(doc):
        if block.lang == "yaml" and block.marker != "skip" and "\nscenes:" in "\n" + block.code:
            spec = parse_spec(block.code, source=block.where)
            assert spec.runs(), f"{block.where}: the spec has no runs"


def test_the_checks_catch_wrong_docs(tmp_path: Path) -> None:
    """The checkers fail on what they must catch: unknown options, commands, skip reasons."""
    doc = tmp_path / "doc.md"
    doc.write_text(
        "```sh\nrtsim trace SCENE -o OUT \\\n  [--resolutoin WxH]   # a typo\nrtsim tarce x\n```\n"
        "<!-- doc-test: skip: needs a GPU -->\n```python\nraise SystemExit(1)\n```\n"
        "<!-- doc-test: run -->\n```sh\nfalse\n```\n"
    )
    sh, skipped, run = blocks(doc)
    parser = build_parser()
    found = [p for c in rtsim_commands(sh.code) for p in command_problems(c, parser)]
    assert found == ["'rtsim trace' has no option --resolutoin", "unknown command 'rtsim tarce'"]
    assert skipped.marker == "skip" and skipped.reason == "needs a GPU" and skipped.line == 7
    assert run.marker == "run"
    with pytest.raises(AssertionError, match=r"doc\.md:11"):
        run_block(run, tmp_path)

"""Fenced code blocks of the Markdown docs, and the checks test_docs.py runs on them.

- ``python`` blocks run: each in a fresh interpreter, in file order, in one temporary folder per
  document (so relative paths such as ``out/cornell`` land there and files written by an earlier
  block are there for a later one; variables are not: each block is self-contained);
- ``sh`` blocks are checked: every ``rtsim ...`` command in them must name a real subcommand and
  only options it has. A block preceded by ``<!-- doc-test: run -->`` is also run with bash;
- ``yaml`` blocks holding a sweep spec (a ``scenes:`` key) must parse as one;
- ``<!-- doc-test: skip: REASON -->`` before a block skips it. Use it sparingly.
"""

from __future__ import annotations

import argparse
import re
from dataclasses import dataclass
from pathlib import Path

FENCE = re.compile(r"^(\s*)```\s*([\w+-]*)\s*$")
MARKER = re.compile(r"<!--\s*doc-test:\s*(run|skip)\b:?\s*(.*?)\s*-->")
OPTION = re.compile(r"(?<![\w/-])(--?[A-Za-z][\w-]*)")


@dataclass(frozen=True)
class Block:
    path: Path
    line: int  # 1-based line of the opening fence
    lang: str
    code: str
    marker: str = ""  # "run", "skip" or ""
    reason: str = ""

    @property
    def where(self) -> str:
        return f"{self.path.name}:{self.line}"


def blocks(path: Path) -> list[Block]:
    """The fenced blocks of a Markdown file, with the doc-test marker just above each."""
    lines = path.read_text().splitlines()
    out: list[Block] = []
    i = 0
    while i < len(lines):
        match = FENCE.match(lines[i])
        if not match:
            i += 1
            continue
        indent, lang = match.groups()
        end = i + 1
        while end < len(lines) and not lines[end].strip().startswith("```"):
            end += 1
        code = "\n".join(line[len(indent) :] for line in lines[i + 1 : end]) + "\n"
        above = next((lines[j] for j in range(i - 1, -1, -1) if lines[j].strip()), "")
        marker = MARKER.search(above)
        out.append(
            Block(
                path,
                i + 1,
                lang.lower(),
                code,
                marker.group(1) if marker else "",
                marker.group(2) if marker else "",
            )
        )
        i = end + 1
    return out


def rtsim_commands(code: str) -> list[str]:
    """The `rtsim ...` commands of a shell block: comments dropped, continuation lines (indented,
    or after a backslash) joined, `&&` and `;` separating commands."""
    joined: list[str] = []
    for raw in code.splitlines():
        line = raw.split(" #", 1)[0].rstrip() if not raw.lstrip().startswith("#") else ""
        if not line.strip():
            continue
        if joined and (raw[:1].isspace() or joined[-1].endswith("\\")):
            joined[-1] = joined[-1].rstrip("\\") + " " + line.strip()
        else:
            joined.append(line.strip())
    commands = []
    for line in joined:
        for part in re.split(r"&&|;", line):
            part = part.strip()
            if part.split()[:1] == ["rtsim"]:
                commands.append(part)
    return commands


def command_problems(command: str, parser: argparse.ArgumentParser) -> list[str]:
    """What in a documented rtsim command the real parser does not know."""
    words = command.split()
    sub_action = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    if len(words) < 2 or words[1].startswith("-"):
        options = set(parser._option_string_actions)
        return [f"unknown option {o}" for o in OPTION.findall(command) if o not in options]
    sub = sub_action.choices.get(words[1])
    if sub is None:
        return [f"unknown command 'rtsim {words[1]}'"]
    known = set(sub._option_string_actions)
    rest = " ".join(words[2:])
    return [f"'rtsim {words[1]}' has no option {o}" for o in OPTION.findall(rest) if o not in known]

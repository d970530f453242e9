"""`--help` tells: every option of every subcommand has a one-line description and its default;
`rtsim simulate --help` lists the fidelity levels and points to `rtsim config --schema`."""

from __future__ import annotations

import argparse

import pytest

from conftest import run_rtsim
from rtsim.cli import build_parser
from rtsim.config import SimConfig, field_info
from rtsim.sim_cli import FIDELITY_LEVELS


def subparsers() -> dict[str, argparse.ArgumentParser]:
    parser = build_parser()
    action = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(action.choices)


def rendered_help(parser: argparse.ArgumentParser, action: argparse.Action) -> str:
    formatter = parser._get_formatter()
    return formatter._expand_help(action) if action.help else ""


def test_every_command_has_a_description() -> None:
    for name, sub in subparsers().items():
        assert sub.description and sub.description.strip(), name


@pytest.mark.parametrize("command", sorted(subparsers()))
def test_every_option_says_what_it_does_and_its_default(command: str) -> None:
    sub = subparsers()[command]
    for action in sub._actions:
        if isinstance(action, argparse._HelpAction):
            continue
        name = "/".join(action.option_strings) or action.dest
        text = rendered_help(sub, action)
        assert text.strip(), f"rtsim {command} {name}: no description"
        assert "\n" not in text, f"rtsim {command} {name}: description is not one line"
        is_flag = action.nargs == 0
        if action.option_strings and not is_flag and not action.required:
            assert "default" in text.lower(), f"rtsim {command} {name}: no default in '{text}'"


def test_defaults_are_shown_as_typed() -> None:
    result = run_rtsim("trace", "--help")
    assert result.returncode == 0
    text = " ".join(result.stdout.split())
    assert "(default: 320x240)" in text and "(default: 200000)" in text
    assert "every kind the scene calls for" in text


def test_simulate_help_lists_fidelity_levels_and_schema() -> None:
    levels = field_info("fidelity").metadata["choices"]
    assert tuple(FIDELITY_LEVELS) == tuple(levels)  # the help's table is the config tree's
    assert SimConfig().fidelity in levels
    result = run_rtsim("simulate", "--help")
    assert result.returncode == 0, result.stderr
    for level in levels:
        assert f"  {level} " in result.stdout, level
    assert "rtsim config --schema" in result.stdout
    assert "fidelity=" in result.stdout

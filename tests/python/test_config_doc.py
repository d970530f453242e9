"""docs/config.md is generated from `rtsim-sim --dump-schema` and must be up to date."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from types import ModuleType

import pytest

from conftest import REPO


def load_generator() -> ModuleType:
    path = REPO / "scripts" / "gen_config_doc.py"
    spec = importlib.util.spec_from_file_location("gen_config_doc", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_config_doc_is_up_to_date() -> None:
    gen = load_generator()
    try:
        schema = gen.load_schema()
    except FileNotFoundError as err:
        pytest.skip(str(err))
    expected = gen.render(schema)
    current = (REPO / "docs" / "config.md").read_text()
    assert current == expected, (
        "docs/config.md is out of date with the config schema: "
        f"run `{sys.executable} scripts/gen_config_doc.py`"
    )


def test_config_doc_lists_every_field() -> None:
    gen = load_generator()
    try:
        schema = gen.load_schema()
    except (FileNotFoundError, subprocess.CalledProcessError) as err:
        pytest.skip(str(err))
    text = gen.render(schema)

    def check(fields: dict, prefix: str) -> None:
        for name, entry in fields.items():
            if entry.get("type") == "section":  # a section, or a unit kind's inside traversal
                check(entry["fields"], f"{prefix}{name}.")
            else:
                assert f"| `{prefix}{name}` |" in text

    check(schema, "")

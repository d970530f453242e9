"""Help text of the `rtsim` command line: every option says what it does and its default
(tests/python/test_cli_help.py checks it), and help that needs the C++ extension is computed
only when help is shown, so ordinary commands start without loading it."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from typing import Any


class HelpFormatter(argparse.HelpFormatter):
    """Ends each option's help with its default, unless the help already says it (an option
    whose default is None must say in words what happens without it). Descriptions and epilogs
    are wrapped paragraph by paragraph; a paragraph with indented lines is kept as written."""

    def _fill_text(self, text: str, width: int, indent: str) -> str:
        paragraphs = text.strip("\n").split("\n\n")
        return "\n\n".join(
            "\n".join(indent + line for line in para.splitlines())
            if any(line.startswith(" ") for line in para.splitlines())
            else super(HelpFormatter, self)._fill_text(para, width, indent)
            for para in paragraphs
        )

    def _get_help_string(self, action: argparse.Action) -> str | None:
        text = action.help or ""
        flag = action.nargs == 0  # store_true, store_const, version, help
        if (
            flag
            or action.required
            or not action.option_strings
            or action.default in (None, argparse.SUPPRESS)
            or "default" in text.lower()
        ):
            return text
        return f"{text} (default: %(default)s)"


class LazyHelpStore(argparse.Action):
    """Stores the value like the default action; its help is computed only when help is shown,
    because it needs the C++ extension, which `rtsim --version` or `rtsim simulate` must not
    load."""

    def __init__(self, *args: Any, help_text: Callable[[], str], **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._help_text = help_text

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: Any,
        option_string: str | None = None,
    ) -> None:
        setattr(namespace, self.dest, values)

    @property
    def help(self) -> str:  # type: ignore[override]
        return self._help_text()

    @help.setter
    def help(self, value: str | None) -> None:
        pass

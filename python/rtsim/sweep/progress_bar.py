"""The sweep's progress bar: done, ok, failed, remaining and an ETA, in a terminal (rich) and in
a notebook (one HTML line updated in place through IPython's display handles, which every
Jupyter front end and nbclient understand; rich's own notebook display needs ipywidgets)."""

from __future__ import annotations

import time
from typing import Any

from rich.console import Console
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)


class SweepBar:
    """`with bar: ... bar.add(status)`; a terminal bar, a notebook line, or nothing."""

    def __init__(self, total: int, enabled: bool, console: Console) -> None:
        self.total, self.ok, self.failed = total, 0, 0
        self.t0 = time.monotonic()
        self._handle: Any = None
        self.notebook = enabled and console.is_jupyter
        self.progress = Progress(
            TextColumn("[bold]sweep"),
            BarColumn(),
            MofNCompleteColumn(),
            TextColumn(
                "[green]ok {task.fields[ok]}[/] [red]failed {task.fields[failed]}[/] "
                "remaining {task.fields[remaining]}"
            ),
            TimeElapsedColumn(),
            TextColumn("eta"),
            TimeRemainingColumn(),
            console=console,
            disable=not enabled or self.notebook,
        )
        self.task = self.progress.add_task("sweep", total=total, ok=0, failed=0, remaining=total)

    def __enter__(self) -> SweepBar:
        if self.notebook:
            from IPython.display import HTML, display

            self._handle = display(HTML(self._html()), display_id=True)
        self.progress.__enter__()
        return self

    def __exit__(self, *exc: object) -> None:
        self.progress.__exit__(None, None, None)
        self._update()

    def add(self, status: str) -> None:
        self.ok += status != "failed"
        self.failed += status == "failed"
        remaining = self.total - self.ok - self.failed
        self.progress.update(
            self.task, advance=1, ok=self.ok, failed=self.failed, remaining=remaining
        )
        self._update()

    def _update(self) -> None:
        if self._handle is not None:
            from IPython.display import HTML

            self._handle.update(HTML(self._html()))

    def _html(self) -> str:
        done = self.ok + self.failed
        elapsed = time.monotonic() - self.t0
        eta = elapsed / done * (self.total - done) if done else None
        eta_text = f", eta {eta:.0f} s" if eta is not None and done < self.total else ""
        return (
            f"<progress value='{done}' max='{max(self.total, 1)}' style='width:40%'></progress> "
            f"sweep {done}/{self.total}: ok {self.ok}, failed {self.failed}, "
            f"remaining {self.total - done}, {elapsed:.0f} s{eta_text}"
        )

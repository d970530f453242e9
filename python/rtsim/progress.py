"""A rich progress bar that the C++ tracer drives through its progress callback."""

from __future__ import annotations

from types import TracebackType

from rich.console import Console
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    ProgressColumn,
    Task,
    TaskID,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)
from rich.text import Text


class RateColumn(ProgressColumn):
    """Items per second, e.g. ``1.2 M rays/s``."""

    def render(self, task: Task) -> Text:
        speed = task.finished_speed or task.speed
        if not speed:
            return Text("-", style="progress.data.speed")
        for scale, prefix in ((1e9, "G"), (1e6, "M"), (1e3, "k")):
            if speed >= scale:
                return Text(f"{speed / scale:.1f} {prefix}rays/s", style="progress.data.speed")
        return Text(f"{speed:.0f} rays/s", style="progress.data.speed")


class TraceProgress:
    """Context manager and callable ``(done, total, stage)``: one bar per tracer stage, the last
    MAX_BARS of them shown. Older bars are dropped, so each refresh draws a bounded number of
    rows and the display costs time linear in the stages (an animated trace of 1024 frames has
    thousands of stages)."""

    MAX_BARS = 6

    def __init__(self, console: Console | None = None, disable: bool = False) -> None:
        self._progress = Progress(
            TextColumn("[bold]{task.description:<10}"),
            BarColumn(),
            MofNCompleteColumn(),
            RateColumn(),
            TimeElapsedColumn(),
            TextColumn("eta"),
            TimeRemainingColumn(),
            console=console or Console(stderr=True),
            disable=disable,
            transient=False,
        )
        self._stage: str | None = None
        self._task: TaskID | None = None
        self._shown: list[TaskID] = []
        self._total = 1

    def __enter__(self) -> TraceProgress:
        self._progress.start()
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        if exc_type is None:
            self._finish_stage()
        self._progress.stop()

    def _finish_stage(self) -> None:
        if self._task is not None:
            self._progress.update(self._task, completed=self._total)

    def __call__(self, done: int, total: int, stage: str) -> None:
        if stage != self._stage:
            self._finish_stage()
            self._stage = stage
            self._task = self._progress.add_task(stage, total=max(total, 1))
            self._shown.append(self._task)
            if len(self._shown) > self.MAX_BARS:
                self._progress.remove_task(self._shown.pop(0))
        assert self._task is not None
        self._total = max(total, done, 1)
        self._progress.update(self._task, completed=done, total=self._total)

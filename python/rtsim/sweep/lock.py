"""One sweep at a time per sweep folder: an exclusive lock on SWEEP/sweep.lock, held while the
sweep runs. Two sweeps on one folder would share run folders and could record a false failure;
the second is refused with a message naming the first (process id, host, start time).

The lock is flock(2) on an open file: the kernel drops it when the holder exits, however it
exits, so a killed sweep never leaves a stale lock behind (the file may stay; it is not the lock).
It protects a folder on one machine's file system; workers on other hosts never write the store.
"""

from __future__ import annotations

import fcntl
import os
import shutil
import socket
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

LOCK_NAME = "sweep.lock"
TMP_MARK = ".tmp-"  # tasks.make_trace traces into TRACE.tmp-HOST-PID, then renames it


class SweepLockedError(OSError):
    """Another sweep holds the folder's lock; the message names it."""


@contextmanager
def sweep_lock(out: Path) -> Iterator[None]:
    """Holds SWEEP/sweep.lock for the duration, or raises SweepLockedError at once."""
    path = Path(out) / LOCK_NAME
    fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 512, 0).decode(errors="replace").strip() or "unknown process"
            raise SweepLockedError(
                f"{out}: another sweep is running on this folder ({holder}); wait for it to "
                f"finish or stop it, then run again (it resumes)"
            ) from None
        os.ftruncate(fd, 0)
        started = time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())
        os.pwrite(
            fd, f"pid {os.getpid()} on {socket.gethostname()}, started {started}\n".encode(), 0
        )
        yield
    finally:
        os.close(fd)  # releases the lock


def clean_stale_traces(out: Path) -> list[Path]:
    """Removes SWEEP/traces/*.tmp-* folders left by a killed sweep. Call with the lock held
    and before any task starts: then no live task owns one."""
    removed = []
    traces = Path(out) / "traces"
    if not traces.is_dir():
        return removed
    for tmp in traces.iterdir():
        if TMP_MARK in tmp.name and tmp.is_dir():
            shutil.rmtree(tmp, ignore_errors=True)
            removed.append(tmp)
    return removed

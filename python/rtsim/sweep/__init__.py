"""Design-space sweeps: a YAML spec (spec.py), traces made once per scene and workload, one
rtsim-sim process per run scheduled on Dask (runner.py, tasks.py), a SQLite results store that a
killed sweep resumes from (store.py) and the tidy results table (results.py). See docs/sweeps.md.

The package is also callable: `rtsim.sweep(spec, out, ...)` runs a sweep from Python and returns
its `Results` (rtsim/sweep/api.py), while `rtsim.sweep.store`, `rtsim.sweep.spec`, ... stay its
modules. Importing it stays cheap: the sweep machinery loads when a sweep is run.
"""

from __future__ import annotations

import sys
import types
from typing import Any


class _CallableModule(types.ModuleType):
    """This package's module type: calling it runs `rtsim.sweep.api.sweep`."""

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        from rtsim.sweep.api import sweep

        return sweep(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule

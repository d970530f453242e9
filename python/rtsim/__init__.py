"""rtsim: a cycle-approximate simulator of ray-tracing accelerators.

>>> import rtsim
>>> scene = rtsim.load_scene("cornell")            # a built-in or shared scene name, or a path
>>> hits = rtsim.trace_rays(scene, origins, directions)
>>> rtsim.trace_scene("cornell", "out/cornell")     # the workload the scene calls for
>>> stats = rtsim.simulate("out/cornell", l1__size_kib=32)
>>> stats.mrays_per_second, stats.dram_bytes_per_ray
>>> results = rtsim.sweep({"scenes": ["cornell"], ...}, "out/s1")   # a sweep, resumable
>>> results.to_pandas()                             # one row per run, tidy columns

Names are imported on first use (PEP 562), so ``import rtsim`` and the command line stay fast:
the C++ extension ``rtsim._core`` (and numpy with it) loads only when a tracer function is used.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from rtsim.errors import HitMismatchError, RtsimError

try:
    from rtsim._version import __version__
except ImportError:  # not built by scikit-build-core (e.g. a source checkout on sys.path)
    from importlib.metadata import version as _version

    __version__ = _version("rtsim")

#: Public name -> the module that defines it (imported on first access).
_LAZY = {
    "Scene": "rtsim._core",
    "procedural_scene_names": "rtsim._core",
    "trace_rays": "rtsim.tracing",
    "trace_sections": "rtsim.trace_file",
    "verify_trace": "rtsim.trace_file",
    "write_procedural_scene": "rtsim.tracing",
    "load_scene": "rtsim.tracing",
    "trace_scene": "rtsim.tracing",
    "write_trace": "rtsim.tracing",
    "Trace": "rtsim.trace_file",
    "open_trace": "rtsim.trace_file",
    "simulate": "rtsim.simulation",
    "Stats": "rtsim.stats",
    "SimConfig": "rtsim.config",
    "Results": "rtsim.sweep.results",
    "open_results": "rtsim.sweep.results",
    "Study": "rtsim.study",
}

#: Public names defined under another name in their module.
_RENAMED = {"trace_sections": "trace_section_table", "verify_trace": "verify_trace_file"}

if TYPE_CHECKING:
    from rtsim._core import Scene, procedural_scene_names
    from rtsim.config import SimConfig
    from rtsim.simulation import simulate
    from rtsim.stats import Stats
    from rtsim.study import Study
    from rtsim.sweep.results import Results, open_results
    from rtsim.trace_file import Trace, open_trace
    from rtsim.trace_file import trace_section_table as trace_sections
    from rtsim.trace_file import verify_trace_file as verify_trace
    from rtsim.tracing import (
        load_scene,
        trace_rays,
        trace_scene,
        write_procedural_scene,
        write_trace,
    )


def __getattr__(name: str) -> Any:
    if name == "sweep":  # the subpackage, callable: rtsim.sweep(spec, out) runs a sweep
        return importlib.import_module("rtsim.sweep")
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'rtsim' has no attribute '{name}'")
    value = getattr(importlib.import_module(module), _RENAMED.get(name, name))
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted([*globals(), *_LAZY, "sweep"])


__all__ = [
    "HitMismatchError",
    "Results",
    "RtsimError",
    "Scene",
    "SimConfig",
    "Stats",
    "Study",
    "Trace",
    "__version__",
    "load_scene",
    "open_results",
    "open_trace",
    "procedural_scene_names",
    "simulate",
    "sweep",
    "trace_rays",
    "trace_scene",
    "trace_sections",
    "verify_trace",
    "write_procedural_scene",
    "write_trace",
]

"""rtsim: a cycle-approximate simulator of ray-tracing accelerators.

The C++ reference tracer is reached through the extension module ``rtsim._core``; this package
adds trace-file access (numpy memory maps), plots and the ``rtsim`` command line.

>>> import rtsim
>>> scene = rtsim.load_scene("cornell")
>>> hits = rtsim.trace_rays(scene, origins, directions, 0.0, float("inf"))
"""

from __future__ import annotations

from rtsim._core import (
    RtsimError,
    Scene,
    load_scene,
    procedural_scene_names,
    trace_rays,
    trace_scene,
    trace_sections,
    verify_trace,
    write_procedural_scene,
)
from rtsim._core import __version__ as __version__
from rtsim.trace_file import Trace, open_trace

__all__ = [
    "RtsimError",
    "Scene",
    "Trace",
    "__version__",
    "load_scene",
    "open_trace",
    "procedural_scene_names",
    "trace_rays",
    "trace_scene",
    "trace_sections",
    "verify_trace",
    "write_procedural_scene",
]

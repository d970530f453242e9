"""`rtsim.simulate()`: one simulation from Python, through the same launcher as the command line
and sweeps (rtsim/launcher.py: one rtsim-sim process per simulation, docs/architecture.md, rule 4).

Config overrides are keyword arguments whose double underscores stand for the dots of a config
key (``l1__size_kib=32`` is ``l1.size_kib``; top-level keys as they are: ``fidelity="analytic"``),
or a dict of dotted keys (``{"l1.size_kib": 32}``) given as ``config``. Keys and types are checked
here against the config tree (rtsim/config.py) and ranges by rtsim-sim's one validate(); either
way a bad key or value raises RtsimError naming it.
"""

from __future__ import annotations

import copy
import json
import os
import tempfile
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from rtsim.args import ArgumentTypeError, bool_arg, check_utf8_path, path_arg, timeout_arg
from rtsim.config import ConfigError, SimConfig, apply_patch, compose
from rtsim.errors import HitMismatchError, RtsimError
from rtsim.launcher import EXIT_BAD_INPUT, EXIT_MISMATCH, EXIT_OK, SimJob, read_json, run_sim
from rtsim.stats import Stats

ConfigLike = SimConfig | Mapping[str, Any] | str | os.PathLike[str] | None


def resolve_config(
    config: ConfigLike = None, overrides: Mapping[str, Any] | None = None
) -> SimConfig:
    """The full config of a run: `config` (None: the defaults; a SimConfig; a dict, nested or with
    dotted keys; a preset name such as "base+tu16+l1-64k"; or a path to a config .json file)
    with `overrides` (keyword style, l1__size_kib=32) applied over it."""
    dotted = {key.replace("__", "."): value for key, value in (overrides or {}).items()}
    try:
        if config is None:
            base = SimConfig()
        elif isinstance(config, SimConfig):
            base = config
        elif isinstance(config, Mapping):
            if not all(isinstance(k, str) for k in config):
                raise ArgumentTypeError(f"config: keys must be strings, got {list(config)!r}")
            # Nested sections first, then dotted keys over them: {"l1": {...}, "l1.ways": 8}.
            nested = {k: v for k, v in config.items() if "." not in k}
            dotted_keys = {k: v for k, v in config.items() if "." in k}
            base = apply_patch(SimConfig(), copy.deepcopy(nested)).with_values(dotted_keys)
        elif isinstance(config, os.PathLike) or (
            isinstance(config, str) and config.endswith(".json")
        ):
            base = _config_file(Path(config))
        elif isinstance(config, str):
            base = compose(config)
        else:
            raise ArgumentTypeError(
                f"config: expected a SimConfig, a dict, a preset name or a .json path, "
                f"got {type(config).__name__}"
            )
        return base.with_values(dotted)
    except ConfigError as err:
        raise RtsimError(str(err)) from err


#: Largest config file read (the defaults are about 6 KB): /dev/zero must not be read forever.
MAX_CONFIG_BYTES = 64 << 20


def _config_file(path: Path) -> SimConfig:
    check_utf8_path(str(path), "config")
    try:
        if path.is_dir():
            raise RtsimError(f"{path}: is a folder, not a config JSON file")
        if path.exists() and not path.is_file():
            raise RtsimError(
                f"{path}: is not a regular file (a FIFO, device or socket); give a config JSON file"
            )
        with path.open("rb") as f:
            raw = f.read(MAX_CONFIG_BYTES + 1)
        if len(raw) > MAX_CONFIG_BYTES:
            raise RtsimError(f"{path}: more than {MAX_CONFIG_BYTES} bytes; not a config JSON file")
        data = json.loads(raw.decode("utf-8"))
    except OSError as err:
        raise RtsimError(f"{path}: cannot read the config ({err.strerror or err})") from err
    except (json.JSONDecodeError, UnicodeDecodeError, RecursionError) as err:
        raise RtsimError(f"{path}: not valid JSON ({type(err).__name__}: {err})") from err
    try:
        return SimConfig.from_dict(data)
    except ConfigError as err:
        raise RtsimError(f"{path}: {err}") from err


@contextmanager
def _run_folder(out: str | os.PathLike[str] | None) -> Iterator[Path]:
    if out is not None:
        path = Path(out)
        if path.exists() and not path.is_dir():
            raise RtsimError(f"{path}: is a file, not a folder (out: the run folder)")
        try:
            path.mkdir(parents=True, exist_ok=True)
        except OSError as err:
            raise RtsimError(
                f"{path}: cannot create the run folder ({err.strerror or err})"
            ) from err
        yield path
        return
    with tempfile.TemporaryDirectory(prefix="rtsim-run-") as tmp:
        yield Path(tmp)


def _error_text(messages: list[str]) -> str:
    """rtsim-sim's error lines without its prefix (they name the file or field)."""
    errors = [m.replace("rtsim-sim: error: ", "", 1) for m in messages if "error" in m]
    return "; ".join(errors or messages[-3:]) or "(no message)"


def simulate(
    trace: str | os.PathLike[str] | Any,
    config: ConfigLike = None,
    *,
    out: str | os.PathLike[str] | None = None,
    timeline: bool = False,
    timeout: float | None = None,
    check: bool = True,
    progress: bool = False,
    **overrides: Any,
) -> Stats:
    """Replays a trace on the accelerator model (one rtsim-sim process) and returns its Stats.

    trace: a trace folder, a .rtt file or a Trace (rtsim.open_trace). config: see
    resolve_config. overrides: config keys, "__" for "." (l1__size_kib=32, fidelity="analytic").
    out: the run folder to keep (stats.json, config.resolved.json, provenance.json, config.json);
    None runs in a temporary folder that is removed (the Stats keep everything). timeline: also
    write timeline.json (needs out). timeout: seconds before the process is killed. check: raise
    HitMismatchError when simulated hits or work differ from the reference (False: return them).
    progress: a progress bar on stderr.

    Raises RtsimError naming the key, field or file for bad input (unknown key, wrong type, out
    of range, missing or corrupt trace), and for a crash or a timeout."""
    resolved = resolve_config(config, overrides)
    timeout = timeout_arg(timeout)
    timeline = bool_arg(timeline, "timeline")
    check = bool_arg(check, "check")
    progress = bool_arg(progress, "progress")
    if timeline and out is None:
        raise RtsimError("timeline=True needs out=RUN: a run folder to keep timeline.json in")
    trace_path = Path(path_arg(getattr(trace, "folder", trace), "trace"))
    if out is not None:
        out = path_arg(out, "out")
    with _run_folder(out) as run:
        (run / "config.json").write_text(resolved.to_json() + "\n")
        job = SimJob(trace_path, run, config=run / "config.json", timeline=timeline)
        result = _launch(job, timeout, progress)
        if result.timed_out:
            raise RtsimError(f"{trace_path}: rtsim-sim timed out after {timeout:g} s")
        if result.returncode == EXIT_BAD_INPUT:
            raise RtsimError(_error_text(result.messages))
        if result.returncode not in (EXIT_OK, EXIT_MISMATCH) or result.stats is None:
            raise RtsimError(
                f"{trace_path}: {result.describe_failure()}: {_error_text(result.messages)}"
            )
        stats = Stats(
            result.stats,
            read_json(run / "config.resolved.json") or {},
            run if out is not None else None,
            result.returncode,
        )
    if result.returncode == EXIT_MISMATCH and check:
        s = stats.summary
        raise HitMismatchError(
            f"{trace_path}: {s.get('hit_mismatches')} simulated hits and "
            f"{s.get('work_mismatches')} work counts differ from the reference "
            "(the error's .stats.validation lists the first ones)",
            stats,
        )
    return stats


def _launch(job: SimJob, timeout: float | None, progress: bool) -> Any:
    if not progress:
        return run_sim(job, timeout=timeout)
    from rtsim.progress import TraceProgress

    job.progress = True
    with TraceProgress() as bar:
        return run_sim(
            job, timeout=timeout, on_progress=lambda done, total: bar(done, total, "simulate")
        )

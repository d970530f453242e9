"""The project's own studies, one module each with a `STUDY` (rtsim/study): `rtsim study --list`
names them, `rtsim study NAME` runs one (docs/studies.md)."""

from __future__ import annotations

import importlib
import importlib.util
import pkgutil
from pathlib import Path

from rtsim.study.core import Study, StudyError


def names() -> list[str]:
    """Every study module of this package."""
    return sorted(m.name for m in pkgutil.iter_modules(__path__) if not m.name.startswith("_"))


def load(name: str) -> Study:
    """The study NAME of this package, or the `STUDY` of a Python file."""
    if name.endswith(".py"):
        path = Path(name)
        spec = importlib.util.spec_from_file_location(f"rtsim_user_study_{path.stem}", path)
        if spec is None or spec.loader is None or not path.is_file():
            raise StudyError(f"{name}: no such study file")
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
    elif name in names():
        module = importlib.import_module(f"rtsim.studies.{name}")
    else:
        raise StudyError(f"no study named '{name}' (studies: {', '.join(names())})")
    study = getattr(module, "STUDY", None)
    if not isinstance(study, Study):
        raise StudyError(f"{name}: defines no STUDY (an rtsim.study.Study)")
    return study

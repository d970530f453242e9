"""Where scenes come from: built-in procedural scenes and the shared glTF scene folder.

``resolve_scene`` is the one resolver of scene names: the command line, ``rtsim.load_scene``,
``rtsim.trace_scene``, ``rtsim.write_trace``, sweeps and ``rtsim accuracy`` all use it.

The shared folder is ``$RTSIM_SCENES`` if set, else the first ``shared/scenes`` found beside
the current directory or one of its parents (a clone of the repo sits next to ``shared/``), else
``../shared/scenes`` beside the source tree the package was built from.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from rtsim.errors import UnknownSceneError

SCENE_SUFFIXES = (".gltf", ".glb")


@dataclass(frozen=True)
class SceneEntry:
    """A scene the CLI can name: a built-in, or a glTF file under the shared folder."""

    name: str
    kind: str  # "built-in" or "shared"
    path: Path | None = None


def shared_scenes_dir() -> Path | None:
    """The shared scene folder, or None if there is none."""
    env = os.environ.get("RTSIM_SCENES")
    if env:
        path = Path(env).expanduser()
        return path if path.is_dir() else None
    cwd = Path.cwd().resolve()
    for base in (cwd, *cwd.parents):
        for candidate in (base / "shared" / "scenes", base / "scenes"):
            if candidate.is_dir() and any(_scene_files(candidate)):
                return candidate
    from rtsim._core import default_scenes_dir

    built_with = Path(default_scenes_dir).resolve()
    return built_with if built_with.is_dir() else None


def _scene_files(folder: Path) -> list[Path]:
    files = [p for p in folder.iterdir() if p.suffix.lower() in SCENE_SUFFIXES]
    for sub in sorted(p for p in folder.iterdir() if p.is_dir()):
        files += [p for p in sub.iterdir() if p.suffix.lower() in SCENE_SUFFIXES]
    return sorted(files)


def shared_scenes() -> list[SceneEntry]:
    folder = shared_scenes_dir()
    if folder is None:
        return []
    entries = []
    for path in _scene_files(folder):
        name = path.parent.name if path.parent != folder else path.stem
        entries.append(SceneEntry(name=name, kind="shared", path=path))
    return entries


def procedural_scene_names() -> list[str]:
    from rtsim._core import procedural_scene_names as names

    return list(names())


def list_scenes() -> list[SceneEntry]:
    built_in = [SceneEntry(name=n, kind="built-in") for n in procedural_scene_names()]
    return built_in + shared_scenes()


def _scene_in_folder(folder: Path) -> str:
    """The one .gltf/.glb file of a scene folder (a shared scene's folder given as a path)."""
    files = sorted(p for p in folder.iterdir() if p.suffix.lower() in SCENE_SUFFIXES)
    if len(files) == 1:
        return str(files[0])
    found = ", ".join(p.name for p in files) if files else "none"
    raise UnknownSceneError(
        f"{folder}: is a folder; a scene folder holds exactly one .gltf or .glb file "
        f"(found: {found}); give the file's path"
    )


def resolve_scene(name: str | os.PathLike[str]) -> str:
    """A path for an existing file; a built-in name as is; a folder holding one .gltf/.glb (a
    shared scene's folder) as that file; a shared scene's folder or file name (case-insensitive)
    as its glTF path; a path that does not exist unchanged (the loader names it). A bare name
    that is none of these raises UnknownSceneError (a ValueError and an RtsimError) saying where
    it looked."""
    text = os.fspath(name)
    if Path(text).is_file() or text in procedural_scene_names():
        return text
    if Path(text).is_dir():
        return _scene_in_folder(Path(text))
    wanted = text.lower()
    for entry in shared_scenes():
        assert entry.path is not None
        if wanted in (entry.name.lower(), entry.path.stem.lower(), entry.path.name.lower()):
            return str(entry.path)
    if not Path(text).suffix and os.sep not in text:
        # A bare name that is neither built in nor shared: say where we looked.
        folder = shared_scenes_dir()
        where = (
            f"shared scenes in {folder}" if folder else "no shared scene folder (set RTSIM_SCENES)"
        )
        names = ", ".join(procedural_scene_names())
        raise UnknownSceneError(
            f"unknown scene '{text}': not a file, not built in ({names}), {where}"
        )
    return text

"""Defensive readers for ``manifest.json``: the tracer owns its exact keys, so look them up by
a few likely spellings and never fail on a missing one."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any


def walk(node: Any, path: tuple[str, ...] = ()) -> Iterator[tuple[tuple[str, ...], Any]]:
    """Yields (key path, value) for every entry of nested dicts (lists are not entered)."""
    if isinstance(node, dict):
        for key, value in node.items():
            yield (*path, str(key)), value
            yield from walk(value, (*path, str(key)))


def find(manifest: dict[str, Any], *names: str, default: Any = None) -> Any:
    """First value whose dotted key path ends with one of `names` (tried in order)."""
    for name in names:
        parts = tuple(name.split("."))
        for path, value in walk(manifest):
            if path[-len(parts) :] == parts:
                return value
    return default


def image_size(manifest: dict[str, Any]) -> tuple[int, int] | None:
    """(width, height) of the camera image, or None if the manifest does not say."""
    for path, value in walk(manifest):
        if isinstance(value, dict) and isinstance(value.get("width"), int):
            height = value.get("height")
            if isinstance(height, int) and value["width"] > 0 and height > 0:
                return value["width"], height
        is_size = path[-1] in ("resolution", "image_size")
        pair = isinstance(value, (list, tuple)) and len(value) == 2
        if is_size and pair and all(isinstance(v, int) for v in value):
            return int(value[0]), int(value[1])
        if is_size and isinstance(value, str) and "x" in value:
            w, _, h = value.partition("x")
            if w.isdigit() and h.isdigit():
                return int(w), int(h)
    width, height = manifest.get("width"), manifest.get("height")
    if isinstance(width, int) and isinstance(height, int):
        return width, height
    return None

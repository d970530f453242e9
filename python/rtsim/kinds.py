"""Names the C++ side defines once and the Python side needs without loading the extension."""

from __future__ import annotations

#: RayKind values as stored in RayRecord.kind (traces/common/ray.h), by index.
RAY_KINDS = ("primary", "shadow", "reflection", "diffuse", "refraction")

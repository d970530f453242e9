"""Names the C++ side declares once and the Python side needs without loading the extension:
read from names.json, which the build writes into the package (`rtsim-sim --dump-names`), as
config.py reads config_schema.json."""

from __future__ import annotations

import json
from importlib import resources


def _declared() -> dict[str, list[str]]:
    names = resources.files("rtsim").joinpath("names.json")
    if not names.is_file():
        raise ImportError(
            "rtsim/names.json is missing: the package was not built and installed "
            "(bash scripts/setup.sh)"
        )
    return dict(json.loads(names.read_text()))


_NAMES = _declared()
#: RayKind values as stored in RayRecord.kind (traces/common/ray.h), by index.
RAY_KINDS: tuple[str, ...] = tuple(_NAMES["ray_kinds"])
#: Data kinds of memory traffic (traces/common/data_kind.h), by index.
DATA_KINDS: tuple[str, ...] = tuple(_NAMES["data_kinds"])
#: Operation kinds of a step's plan (traces/accel/step_plan.h): the pipelines' names.
OP_KINDS: tuple[str, ...] = tuple(_NAMES["op_kinds"])
#: Traversal unit kinds registered in this build (traversal.model's choices).
UNIT_KINDS: tuple[str, ...] = tuple(_NAMES["unit_kinds"])
#: Acceleration structures registered in this build (`rtsim trace --accel`).
ACCEL_KINDS: tuple[str, ...] = tuple(_NAMES["accel_kinds"])
#: Any-hit rays' child orders (traces/accel/step_options.h: traversal.anyhit_order, rtsim trace
#: --anyhit-order).
ANYHIT_ORDERS: tuple[str, ...] = tuple(_NAMES["anyhit_orders"])

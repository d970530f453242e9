"""The simulator's config tree as typed dataclasses (docs/architecture.md, rule 5).

The tree is built from the C++ declaration itself: each block's ``visit()`` lists its fields
with default, unit, range, choices and doc (rtl_model/*/*_config.h, sim/config/config.h); the
build writes that schema (``rtsim-sim --dump-schema``) into the package as config_schema.json,
and this module makes one dataclass per section (``TraversalConfig``, ``L1Config``, ...) and the
root ``SimConfig`` from it (reading a JSON file: no C++ extension, no numpy). Nothing here
re-types a default, a unit or a range, so Python and rtsim-sim cannot drift apart
(tests/python/test_config_py.py also checks the installed rtsim-sim's schema against this one).

Configs are composed Accel-Sim style from a named preset plus modifiers, e.g.
``compose("base+tu16+l1-64k")``. Presets and modifiers are data (nested dict patches), so a new
one is one dict entry; every patch is checked against this tree when it is applied, so a patch
naming a key the C++ side does not have fails with the key's full path.
"""

from __future__ import annotations

import copy
import dataclasses
import functools
import json
import math
import numbers
from dataclasses import field
from importlib import resources
from typing import Any, ClassVar, TypeVar

from rtsim.errors import RtsimError

T = TypeVar("T")


class ConfigError(RtsimError, ValueError):
    """A config dict, key path or patch that does not fit the tree; the message names the key."""


#: Python type names of the schema's field types (_check_value checks values by them).
_TYPES = {"int": "int", "float": "float", "choice": "str", "bool": "bool"}


def _field(entry: dict[str, Any]) -> Any:
    """A dataclass field from a schema entry: its default and its metadata (unit, doc, range or
    choices), as rtsim-sim declares them."""
    if entry["type"] in ("int", "float"):
        meta = {k: entry[k] for k in ("unit", "doc", "min", "max")}
    elif entry["type"] == "choice":
        meta = {"choices": tuple(entry["choices"]), "doc": entry["doc"]}
    else:
        meta = {"doc": entry["doc"]}
    return field(default=entry["default"], metadata=meta)


def _in_order(fields: dict[str, Any]) -> list[tuple[str, dict[str, Any]]]:
    return sorted(fields.items(), key=lambda item: item[1]["index"])


def _class_name(section: str) -> str:
    return "".join(part.capitalize() for part in section.split("_")) + "Config"


class _Root:
    """What the root of the tree can do besides holding it (SimConfig's methods)."""

    sections: ClassVar[tuple[str, ...]]

    def to_dict(self) -> dict[str, Any]:
        return _as_dict(self)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> SimConfig:
        """A config from a (partial) dict over the defaults; unknown keys and wrong types raise
        ConfigError naming the key's full path (e.g. 'l1.size_kb')."""
        return _read(SimConfig, data, "")

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), indent=2, sort_keys=True)

    def get(self, key: str) -> Any:
        """The value at a dotted key path ('l1.size_kib')."""
        node: Any = self
        for part in key.split("."):
            if not dataclasses.is_dataclass(node) or part not in _names(type(node)):
                raise ConfigError(f"config: unknown key '{key}'")
            node = getattr(node, part)
        if dataclasses.is_dataclass(node):
            raise ConfigError(f"config: '{key}' is a section, not a field")
        return node

    def with_values(self, values: dict[str, Any]) -> SimConfig:
        """A copy with dotted keys set ({'l1.size_kib': 64}); types checked, ranges left to the
        one validate() in rtsim-sim."""
        return apply_patch(self, unflatten(values))  # type: ignore[arg-type]


def _section_class(path: str, fields: dict[str, Any], sections: dict[str, type]) -> type:
    """The dataclass of the section at dotted `path` (its own sections nested, e.g. a unit kind's
    traversal.simt), registered in `sections` under its path."""
    members: list[tuple[str, Any, Any]] = []
    for name, entry in _in_order(fields):
        if entry["type"] == "section":
            inner = _section_class(f"{path}.{name}", entry["fields"], sections)
            members.append((name, inner.__name__, field(default_factory=inner)))
        else:
            members.append((name, _TYPES[entry["type"]], _field(entry)))
    cls = dataclasses.make_dataclass(_class_name(path.replace(".", "_")), members)
    cls.__doc__ = f"Section `{path}` of the config tree (as rtsim-sim declares it)."
    cls.__module__ = __name__
    sections[path] = cls
    return cls


def _build_tree(schema: dict[str, Any]) -> tuple[type, dict[str, type]]:
    """SimConfig and the section classes (by dotted path) from the C++ schema, in declaration
    order."""
    sections: dict[str, type] = {}
    root_fields: list[tuple[str, str, Any]] = []
    for name, entry in _in_order(schema):
        if entry["type"] == "section":
            cls = _section_class(name, entry["fields"], sections)
            root_fields.append((name, cls.__name__, field(default_factory=cls)))
        else:
            root_fields.append((name, _TYPES[entry["type"]], _field(entry)))
    root = dataclasses.make_dataclass("SimConfig", root_fields, bases=(_Root,))
    root.__doc__ = "The whole simulator config: the root of the tree rtsim-sim reads with --config."
    root.__module__ = __name__
    root.sections = tuple(n for n, e in _in_order(schema) if e["type"] == "section")
    return root, sections


def config_schema() -> dict[str, Any]:
    """The schema the build wrote (python/CMakeLists.txt: rtsim-sim --dump-schema)."""
    schema = resources.files("rtsim").joinpath("config_schema.json")
    if not schema.is_file():
        raise ImportError(
            "rtsim/config_schema.json is missing: the package was not built and installed "
            "(bash scripts/setup.sh)"
        )
    return dict(json.loads(schema.read_text()))


SimConfig: Any
SimConfig, SECTIONS = _build_tree(config_schema())
globals().update({cls.__name__: cls for cls in SECTIONS.values()})


def _names(cls: type) -> dict[str, dataclasses.Field[Any]]:
    return {f.name: f for f in dataclasses.fields(cls)}


def _join(prefix: str, name: str) -> str:
    return f"{prefix}.{name}" if prefix else name


def _numpy_bool(value: Any) -> bool:
    return type(value).__module__ == "numpy" and type(value).__name__ in ("bool", "bool_")


def _check_value(f: dataclasses.Field[Any], value: Any, path: str) -> Any:
    kind = f.type if isinstance(f.type, str) else getattr(f.type, "__name__", "")
    # numpy scalars (np.int64, np.float32, np.bool_) count as the Python numbers they hold.
    if kind == "bool":
        if not isinstance(value, bool) and not _numpy_bool(value):
            raise ConfigError(f"config: '{path}' must be true or false, got {value!r}")
        return bool(value)
    if kind == "int":
        is_number = isinstance(value, numbers.Real) and not isinstance(value, bool)
        if is_number and not isinstance(value, numbers.Integral) and float(value).is_integer():
            value = int(value)
        if not is_number or not isinstance(value, numbers.Integral) or value < 0:
            raise ConfigError(f"config: '{path}' must be a non-negative integer, got {value!r}")
        return int(value)
    if kind == "float":
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            raise ConfigError(f"config: '{path}' must be a number, got {value!r}")
        if not math.isfinite(float(value)):
            raise ConfigError(f"config: '{path}' must be a finite number, got {value!r}")
        return float(value)
    if not isinstance(value, str):
        raise ConfigError(f"config: '{path}' must be a string, got {value!r}")
    choices = f.metadata.get("choices")
    if choices and value not in choices:
        raise ConfigError(f"config: '{path}' = '{value}' is not one of: {', '.join(choices)}")
    return value


def _as_dict(value: Any) -> Any:
    """dataclasses.asdict for the config tree, without its deep copy of every leaf (a sweep
    hashes tens of thousands of configs: asdict was most of its planning time)."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: _as_dict(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, list | tuple):
        return [_as_dict(v) for v in value]
    if isinstance(value, dict):
        return {k: _as_dict(v) for k, v in value.items()}
    return value


def _clone(value: Any) -> Any:
    """A copy of a config (sub)tree: sections and containers copied, leaves shared (they are
    immutable scalars and strings)."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        out = copy.copy(value)
        for f in dataclasses.fields(value):
            v = getattr(value, f.name)
            if isinstance(v, list | dict) or dataclasses.is_dataclass(v):
                object.__setattr__(out, f.name, _clone(v))
        return out
    if isinstance(value, list):
        return [_clone(v) for v in value]
    if isinstance(value, dict):
        return {k: _clone(v) for k, v in value.items()}
    return value


def _read(cls: type[T], data: Any, prefix: str, base: Any = None, copied: bool = False) -> T:
    if not isinstance(data, dict):
        raise ConfigError(f"config: '{prefix or '(root)'}' must be a mapping, got {data!r}")
    fields = _names(cls)
    unknown = sorted(set(data) - set(fields))
    if unknown:
        raise ConfigError(
            f"config: unknown key '{_join(prefix, unknown[0])}' (known here: {', '.join(fields)})"
        )
    # The base is copied once, at the root (its sections come with it).
    obj = (base if copied else _clone(base)) if base is not None else cls()
    for name, value in data.items():
        f, path = fields[name], _join(prefix, name)
        current = getattr(obj, name)
        if dataclasses.is_dataclass(current):
            setattr(obj, name, _read(type(current), value, path, current, copied=True))
        else:
            setattr(obj, name, _check_value(f, value, path))
    return obj


def apply_patch(config: SimConfig, patch: dict[str, Any]) -> SimConfig:
    """A copy of config with a nested patch applied (unknown keys raise ConfigError)."""
    return _read(SimConfig, patch, "", config)


def unflatten(values: dict[str, Any]) -> dict[str, Any]:
    """{'l1.size_kib': 64} -> {'l1': {'size_kib': 64}}."""
    out: dict[str, Any] = {}
    for key, value in values.items():
        if not isinstance(key, str):
            raise ConfigError(f"config: keys are dotted names like 'l1.size_kib', got {key!r}")
        node = out
        *parents, leaf = key.split(".")
        for part in parents:
            node = node.setdefault(part, {})
            if not isinstance(node, dict):
                raise ConfigError(f"config: '{key}' conflicts with another key")
        node[leaf] = value
    return out


def flatten(data: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    """{'l1': {'size_kib': 64}} -> {'l1.size_kib': 64}, in tree order."""
    out: dict[str, Any] = {}
    for key, value in data.items():
        path = _join(prefix, key)
        if isinstance(value, dict):
            out.update(flatten(value, path))
        else:
            out[path] = value
    return out


def field_info(key: str) -> dataclasses.Field[Any]:
    """The dataclass field (with unit, doc, range metadata) at a dotted key path."""
    node: Any = SimConfig()
    *parents, leaf = key.split(".")
    for part in parents:
        if not dataclasses.is_dataclass(node) or part not in _names(type(node)):
            raise ConfigError(f"config: unknown key '{key}'")
        node = getattr(node, part)
    if not dataclasses.is_dataclass(node) or leaf not in _names(type(node)):
        raise ConfigError(f"config: unknown key '{key}'")
    if dataclasses.is_dataclass(getattr(node, leaf)):
        raise ConfigError(f"config: unknown key '{key}'")
    return _names(type(node))[leaf]


def _unit_kind_sections() -> tuple[tuple[str, str, Any], ...]:
    """Each unit kind's own section (traversal.<kind>.*) acts only when traversal.model is it."""
    traversal = config_schema()["traversal"]["fields"]
    kinds = traversal["model"]["choices"]
    return tuple(
        (f"traversal.{name}.", "traversal.model", name)
        for name, entry in traversal.items()
        if entry["type"] == "section" and name in kinds
    )


#: Sections whose every other field has no effect unless a switch has a value:
#: (prefix, switch, the value that switches it on).
INACTIVE_UNLESS: tuple[tuple[str, str, Any], ...] = (
    ("treelets.", "treelets.enabled", True),
    *_unit_kind_sections(),
)

#: Fields under an inactive prefix that act without its switch: treelet prefetching also runs
#: without treelet queues (a ray stepping into a treelet triggers it; docs/treelets.md).
ACTIVE_WITHOUT_SWITCH = ("treelets.prefetch",)


def key_inactive(key: str, flat: dict[str, Any]) -> bool:
    """True for a key whose section's switch is off in this flat config (treelets.buffer_kib
    without treelets.enabled, traversal.simt.lanes under traversal.model mimd)."""
    if key.startswith(ACTIVE_WITHOUT_SWITCH):
        return False
    return any(
        key.startswith(prefix) and key != switch and switch in flat and flat[switch] != on
        for prefix, switch, on in INACTIVE_UNLESS
    )


def effective_dict(config: SimConfig) -> dict[str, Any]:
    """The config as the simulator sees it: fields of a switched-off section (a ray-buffer size
    with treelets off) at their defaults, so two configs that differ only there compare equal
    (a sweep simulates them once)."""
    flat, default = flatten(config.to_dict()), _default_flat()
    return unflatten({k: default[k] if key_inactive(k, flat) else v for k, v in flat.items()})


@functools.cache
def _default_flat() -> dict[str, Any]:
    """The default config, flattened (read only: effective_dict takes its values)."""
    return flatten(SimConfig().to_dict())


def config_keys() -> list[str]:
    """Every dotted field key, in tree order."""
    return list(flatten(SimConfig().to_dict()))


# Named presets and composable modifiers (Accel-Sim style: "base+tu16+l1-64k"). Each is a nested
# patch over the C++ defaults; compose() checks every key against the tree above.
PRESETS: dict[str, dict[str, Any]] = {
    "base": {},
    "functional": {"fidelity": "functional"},
    "analytic": {"fidelity": "analytic"},
    "detailed": {"fidelity": "detailed"},
}

# Presets from published machines (docs/presets.md gives each number's source and what has no
# counterpart here). RT units of NVIDIA Turing as Vulkan-Sim models them (Saed et al., MICRO 2022:
# configs/tested-cfgs/SM75_RTX2060/gpgpusim.config): one RT unit per SM with 4 warps of rays
# (128) in flight, 64 MSHRs, the SM's 64 KiB L1 (128-byte lines, 4 banks, 20 cycles), a banked
# L2 (160 cycles), GDDR6 channels of 16 bits at 14 Gbps (28 GB/s each). Chip totals from NVIDIA's
# Turing architecture whitepaper (2018): SMs, clocks, L2 size, memory bus.
_TURING_RT_UNIT: dict[str, Any] = {
    "traversal": {"ray_contexts": 128},
    "l1": {"size_kib": 64, "ways": 16, "line_bytes": 128, "latency": 20, "mshrs": 64, "banks": 4},
    "l2": {"ways": 16, "line_bytes": 128, "latency": 160, "mshrs": 1024},
    "dram": {"latency": 100, "interleave_bytes": 256},
    "energy": {"node_nm": 12.0, "dram_kind": "gddr6"},
}


def _merge(base: dict[str, Any], patch: dict[str, Any]) -> dict[str, Any]:
    out = copy.deepcopy(base)
    for key, value in patch.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = _merge(out[key], value)
        else:
            out[key] = value
    return out


PRESETS.update(
    {
        # RTX 2060 (TU106): 30 SMs at 1365 MHz base, 3 MB L2 (24 ways keeps the sets a power of
        # two), 192-bit GDDR6 at 14 Gbps = 336 GB/s: 12 channels of 20 B/cycle = 328 GB/s.
        "rtx2060": _merge(
            _TURING_RT_UNIT,
            {
                "clock_ghz": 1.365,
                "traversal": {"units": 30},
                "l2": {"size_kib": 3072, "ways": 24, "banks": 24},
                "dram": {"channels": 12, "bytes_per_cycle": 20},
            },
        ),
        # RTX 2080 (TU104): 46 SMs at 1515 MHz base, 4 MB L2, 256-bit GDDR6 at 14 Gbps = 448 GB/s:
        # 16 channels of 18 B/cycle = 436 GB/s.
        "rtx2080": _merge(
            _TURING_RT_UNIT,
            {
                "clock_ghz": 1.515,
                "traversal": {"units": 46},
                "l2": {"size_kib": 4096, "banks": 32},
                "dram": {"channels": 16, "bytes_per_cycle": 18},
            },
        ),
        # The RT unit as Vulkan-Sim models it (Saed et al., MICRO 2022), on rtsim's warp-based unit:
        # gpgpu_rt_max_warps warps of 32 rays in a warp buffer, a warp handed back to the SM only
        # when all its rays are done (refill=warp), over the RTX 2060's memory system above. Trace
        # with --accel cwbvh6 (64-byte 6-wide nodes with 8-bit boxes: Mesa's Intel-style BVH6,
        # which Vulkan-Sim traverses). docs/presets.md lists what differs.
        "vulkansim_rtx2060": _merge(
            _TURING_RT_UNIT,
            {
                "clock_ghz": 1.365,
                "traversal": {
                    "units": 30,
                    "model": "simt",
                    "ray_contexts": 128,
                    "simt": {"lanes": 32, "refill": "warp"},
                },
                "l2": {"size_kib": 3072, "ways": 24, "banks": 24},
                "dram": {"channels": 12, "bytes_per_cycle": 20},
            },
        ),
        # Vulkan-Sim's mobile SoC (configs/tested-cfgs/MOBILE): 2 SMs at 1365 MHz, 16 warps per RT
        # unit, its own 64 KiB RT cache (S:32:128:16, 256 MSHRs), 2 x 128 KiB L2 (S:64:128:16,
        # 192 MSHRs each), two 16-bit GDDR6 channels at 7 Gbps (14 GB/s = 10 B/cycle each).
        "vulkansim_mobile": _merge(
            _TURING_RT_UNIT,
            {
                "clock_ghz": 1.365,
                "traversal": {
                    "units": 2,
                    "model": "simt",
                    "ray_contexts": 512,
                    "simt": {"lanes": 32, "refill": "warp"},
                },
                "l1": {"mshrs": 256},
                "l2": {"size_kib": 256, "ways": 16, "banks": 2, "mshrs": 384},
                "dram": {"channels": 2, "bytes_per_cycle": 10},
            },
        ),
        # STRaTA (Kopta et al., HPG 2013): TRaX thread multiprocessors with treelet ray streams in
        # on-chip SRAM. Numbers from Arches' STRaTA "modern config" (src/arches/strata.hpp): 2 GHz,
        # 128 TMs with one RT core of 256 rays each, 128 KiB 4-way L1 per TM (8 banks, 30 cycles,
        # 256 MSHRs), 512 KiB 8-way L2 (32 banks, 200 cycles, 256 MSHRs), a 4 MiB ray stream
        # buffer (latency L1 + L2), 16 DRAM channels (GDDR5 under Ramulator; 16 B/cycle assumed).
        "strata": {
            "clock_ghz": 2.0,
            "traversal": {"units": 128, "ray_contexts": 256},
            "l1": {"size_kib": 128, "ways": 4, "latency": 30, "mshrs": 256, "banks": 8},
            "l2": {"size_kib": 512, "ways": 8, "latency": 200, "mshrs": 256, "banks": 32},
            "treelets": {"enabled": True, "buffer_kib": 4096, "latency": 230},
            "dram": {"channels": 16, "bytes_per_cycle": 16},
            "energy": {"node_nm": 7.0, "dram_kind": "gddr6"},
        },
    }
)

MODIFIERS: dict[str, dict[str, Any]] = {
    "tu4": {"traversal": {"units": 4}},
    "tu16": {"traversal": {"units": 16}},
    "tu32": {"traversal": {"units": 32}},
    "ctx8": {"traversal": {"ray_contexts": 8}},
    "ctx32": {"traversal": {"ray_contexts": 32}},
    "stack4": {"traversal": {"stack_entries": 4}},
    "stack16": {"traversal": {"stack_entries": 16}},
    "l1-8k": {"l1": {"size_kib": 8}},
    "l1-32k": {"l1": {"size_kib": 32}},
    "l1-64k": {"l1": {"size_kib": 64}},
    "l2-512k": {"l2": {"size_kib": 512}},
    "l2-2m": {"l2": {"size_kib": 2048}},
    "l2-4m": {"l2": {"size_kib": 4096}},
    "dram-half": {"dram": {"bytes_per_cycle": 8}},
    "dram-2x": {"dram": {"bytes_per_cycle": 32}},
    "dram-4x": {"dram": {"bytes_per_cycle": 64}},
    # DDR4-2133's second-order limits (DRAMsim3's DDR4_8Gb_x8_2133.ini: tRAS 36, tRRD_S/L 4/6,
    # tFAW 23, tREFI 8328, tRFC 374, 4 bank groups, tCCD_L 6, tWTR_S/L 3/8 (2.8 and 7.5 ns),
    # tRTW = CL + BL/2 - CWL + 2 = 11 at tCK 0.94 ns; a 32-entry transaction queue per channel)
    # in 1 GHz core cycles (docs/model.md).
    "ddr4": {
        "dram": {
            "t_ras": 34,
            "t_rrd": 4,
            "t_rrd_l": 6,
            "t_faw": 22,
            "t_refi": 7800,
            "t_rfc": 350,
            "bank_groups": 4,
            "t_ccd_l": 6,
            "t_wtr": 3,
            "t_wtr_l": 8,
            "t_rtw": 10,
            "queue_entries": 32,
        }
    },
    "ideal-mem": {"ideal_memory": True},
    "shared-pipes": {"box": {"sharing": "shared"}, "triangle": {"sharing": "shared"}},
    "box-wide": {"box": {"width": 4}},
    "clock-2g": {"clock_ghz": 2.0},
    "functional": PRESETS["functional"],
    "analytic": PRESETS["analytic"],
    "detailed": PRESETS["detailed"],
    "treelets": {"treelets": {"enabled": True}},
    "rb-128k": {"treelets": {"buffer_kib": 128}},
    "rb-1m": {"treelets": {"buffer_kib": 1024}},
    "rb-4m": {"treelets": {"buffer_kib": 4096}},
    "treelet-8k": {"treelets": {"treelet_kib": 8}},
    "treelet-32k": {"treelets": {"treelet_kib": 32}},
    "prefetch": {"treelets": {"prefetch": True}},
    "prefetch-l2": {"treelets": {"prefetch": True, "prefetch_into": "l2"}},
    "sample-1pct": {"sampling": {"fraction": 0.01}},
    "sample-5pct": {"sampling": {"fraction": 0.05}},
    "sample-10pct": {"sampling": {"fraction": 0.1}},
}


def compose(name: str) -> SimConfig:
    """The config named by 'preset+modifier+...' (the first part may also be a modifier, over
    'base'). Unknown names raise ConfigError listing what exists."""
    parts = [p.strip() for p in name.split("+") if p.strip()]
    if not parts:
        raise ConfigError("config: empty preset name")
    config = SimConfig()
    for i, part in enumerate(parts):
        table = PRESETS if i == 0 and part in PRESETS else MODIFIERS
        if part not in table:
            raise ConfigError(
                f"config: unknown preset or modifier '{part}' in '{name}' "
                f"(presets: {', '.join(PRESETS)}; modifiers: {', '.join(MODIFIERS)})"
            )
        try:
            config = apply_patch(config, table[part])
        except ConfigError as err:
            raise ConfigError(f"{err} (in modifier '{part}')") from err
    return config

"""The simulator's config tree as typed dataclasses (docs/architecture.md, rule 5).

Mirrors ``sim/config/config.h`` exactly: the same sections, field names and defaults, with the
unit, range and doc of each field in its metadata. ``tests/python/test_config_py.py`` compares
this tree with ``rtsim-sim --dump-schema`` both ways, so the two cannot drift.

Configs are composed Accel-Sim style from a named preset plus modifiers, e.g.
``compose("base+tu16+l1-64k")``. Presets and modifiers are data (nested dict patches), so a new
one is one dict entry; every patch is checked against this tree when it is applied, so a patch
naming a key the C++ side does not have fails with the key's full path.
"""

from __future__ import annotations

import copy
import dataclasses
import json
from dataclasses import dataclass, field
from typing import Any, ClassVar, TypeVar

T = TypeVar("T")


class ConfigError(ValueError):
    """A config dict, key path or patch that does not fit the tree; the message names the key."""


def _f(default: Any, unit: str, doc: str, lo: float, hi: float) -> Any:
    return field(default=default, metadata={"unit": unit, "doc": doc, "min": lo, "max": hi})


def _choice(default: str, choices: tuple[str, ...], doc: str) -> Any:
    return field(default=default, metadata={"choices": choices, "doc": doc})


def _flag(default: bool, doc: str) -> Any:
    return field(default=default, metadata={"doc": doc})


@dataclass
class PipelineConfig:
    """A ray-box or ray-triangle pipeline (timing only; the arithmetic is traces/isect/)."""

    latency: int = _f(8, "cycles", "Cycles from issue to result", 1, 1000)
    initiation_interval: int = _f(
        1, "cycles", "Cycles between two issues into one pipeline", 1, 1000
    )
    width: int = _f(
        1,
        "tests",
        "Tests per issue (a node's child boxes take ceil(children / width) issues; "
        "width 2 tests a binary node in one issue)",
        1,
        64,
    )
    sharing: str = _choice(
        "private",
        ("private", "shared"),
        "One pipeline per traversal unit, or a pool shared by all units",
    )
    shared_count: int = _f(
        4, "pipelines", "Pipelines in the shared pool (sharing = shared)", 1, 1024
    )


@dataclass
class CacheConfig:
    """One cache level (every L1 has the same config)."""

    size_kib: int = _f(16, "KiB", "Capacity", 1, 1 << 20)
    ways: int = _f(4, "ways", "Associativity (LRU replacement)", 1, 64)
    line_bytes: int = _f(64, "bytes", "Line size (power of two, same at every level)", 16, 1024)
    latency: int = _f(4, "cycles", "Hit latency", 1, 1000)
    mshrs: int = _f(8, "entries", "Outstanding misses; a miss waits for a free MSHR", 1, 1024)
    banks: int = _f(
        1, "banks", "Line-interleaved banks, each serving one access per bank_cycles", 1, 256
    )
    bank_cycles: int = _f(1, "cycles", "Cycles a bank is busy per access", 1, 100)


@dataclass
class DramConfig:
    channels: int = _f(2, "channels", "Independent DRAM channels", 1, 64)
    bytes_per_cycle: int = _f(
        16, "B/cycle", "Peak bandwidth per channel, bytes per core cycle", 1, 4096
    )
    latency: int = _f(
        120,
        "cycles",
        "Unloaded access latency, request to data (model banks: of an access to a closed bank)",
        1,
        100000,
    )
    model: str = _choice(
        "banks",
        ("banks", "bandwidth"),
        "DRAM timing: banks and row buffers (hits, misses, conflicts) or channel bandwidth "
        "calendars only (every access costs latency)",
    )
    interleave_bytes: int = _f(
        256, "bytes", "Channel interleaving granule (power of two, >= line size)", 64, 1 << 20
    )
    # Banks and row buffers: used with model = "banks" (docs/model.md, "DRAM").
    banks: int = _f(16, "banks", "Banks per channel, one row buffer each (model banks)", 1, 256)
    row_bytes: int = _f(
        2048, "bytes", "Row (page) size of a bank (power of two; model banks)", 64, 1 << 20
    )
    page_policy: str = _choice(
        "open",
        ("open", "close"),
        "Row buffer policy: keep rows open (row hits) or precharge after each access (model banks)",
    )
    t_rcd: int = _f(14, "cycles", "Activate to column command, core cycles (model banks)", 0, 10000)
    t_rp: int = _f(14, "cycles", "Precharge time, core cycles (model banks)", 0, 10000)
    t_cas: int = _f(
        14, "cycles", "Column command to first data, core cycles (model banks)", 0, 10000
    )


@dataclass
class TraversalConfig:
    units: int = _f(8, "units", "MIMD traversal units", 1, 4096)
    ray_contexts: int = _f(16, "rays", "Ray contexts per unit (rays in flight)", 1, 4096)
    stack_entries: int = _f(
        8, "entries", "On-chip stack entries per ray; overflow spills to memory", 1, 64
    )
    stack_entry_bytes: int = _f(
        0,
        "bytes",
        "Bytes per stack entry (on-chip stack and spill traffic); 0: the structure's own (a BVH's "
        "8: node and entry distance; a kd-tree's or BIH's 12; an octree's 32), resolved from the "
        "trace",
        0,
        64,
    )
    issue_cycles: int = _f(1, "cycles", "Scheduler cycles per traversal step of one unit", 1, 100)


@dataclass
class MailboxConfig:
    """Mailboxes in the traversal units (docs/accel.md, "Mailboxes")."""

    entries: int = _f(
        0,
        "entries",
        "Mailbox entries per ray context (primitives tested, FIFO); retests of a listed primitive "
        "are skipped in grids, kd-trees and octrees; 0: no mailbox",
        0,
        64,
    )


@dataclass
class DispatchConfig:
    chunk_rays: int = _f(16384, "rays", "Rays streamed from the trace file per chunk", 64, 1 << 24)
    latency: int = _f(
        2, "cycles", "Cycles to assign a ray to a free context, before its fetch", 0, 1000
    )
    policy: str = _choice(
        "interleaved",
        ("interleaved", "on_demand"),
        "interleaved: rays dealt to units in turn, blocks of block_rays, idle units steal; "
        "on_demand: the next ray to whichever unit asks first (depends on quantum_cycles)",
    )
    block_rays: int = _f(
        1, "rays", "Consecutive rays dealt to one unit at a time (interleaved policy)", 1, 1 << 20
    )


@dataclass
class SamplingConfig:
    """Statistical sampling (docs/fidelity.md): a stratified sample of clusters of rays, each
    warm-up then measured, estimating the full run's cycles with a 95% interval (SMARTS)."""

    fraction: float = _f(
        0.0,
        "fraction",
        "Fraction of the trace's rays to simulate, warm-up included (0: no sampling)",
        0.0,
        1.0,
    )
    count: int = _f(
        0, "rays", "Rays to simulate instead of a fraction (0: no sampling)", 0, 2147483647
    )
    clusters: int = _f(
        30,
        "clusters",
        "Strata of the trace, one sampled cluster each (fewer when the sample cannot hold them "
        "with their warm-up)",
        2,
        100000,
    )
    warmup_rays: int = _f(
        0,
        "rays",
        "Warm-up rays simulated before each cluster's measured rays "
        "(0: automatic, docs/fidelity.md)",
        0,
        1 << 24,
    )
    warming_rays: int = _f(
        4096,
        "rays",
        "Skipped rays before each cluster replayed through the L1s and L2 without time "
        "(functional warming, docs/fidelity.md; 0: none); about L2 lines / 4",
        0,
        2147483647,
    )
    seed: int = _f(
        1, "seed", "Seed of each cluster's random offset within its stratum", 0, 2147483647
    )


@dataclass
class AnalyticConfig:
    """The analytic level (docs/fidelity.md): its cache model and how its per-trace analysis
    samples the trace (sim/harness/analytic_config.h)."""

    caches: str = _choice(
        "statistical",
        ("statistical", "functional"),
        "statistical: reuse distances of a sample of rays (StatStack) scaled by the trace's work "
        "counts; functional: every ray through functional caches (exact, slow)",
    )
    whole_trace_rays: int = _f(
        32768,
        "rays",
        "Traces up to this many rays are analysed whole (statistical caches)",
        0,
        1 << 30,
    )
    clusters: int = _f(
        8, "clusters", "Clusters of consecutive rays the analysis steps in larger traces", 1, 4096
    )
    warmup_rays: int = _f(
        0,
        "rays",
        "Warm-up rays per cluster: their accesses only build reuse history; 0: automatic, "
        "max(3072, L2 lines / 4), enough history to see the L2's reuse",
        0,
        1 << 24,
    )
    measured_rays: int = _f(1024, "rays", "Measured rays per cluster", 1, 1 << 24)


@dataclass
class TreeletConfig:
    """Treelet scheduling with ray buffers (docs/treelets.md; Aila & Karras 2010, STRaTA)."""

    enabled: bool = _flag(
        False, "Treelet scheduling: rays queue per treelet in the ray buffer SRAM"
    )
    treelet_kib: int = _f(
        16, "KiB", "Byte budget per treelet (nodes and their leaf triangles)", 1, 1 << 20
    )
    buffer_kib: int = _f(
        512, "KiB", "Ray buffer SRAM capacity; rays beyond it overflow to DRAM", 1, 1 << 22
    )
    policy: str = _choice(
        "largest",
        ("largest", "oldest", "round_robin"),
        "Queue a free unit runs next: largest queue, oldest waiting ray, or round robin",
    )
    threshold: int = _f(
        64,
        "rays",
        "Queues of at least this many rays are preferred (oldest, round_robin); shorter ones run "
        "only when no queue is that long. No effect with largest",
        1,
        1 << 20,
    )
    latency: int = _f(4, "cycles", "Ray buffer SRAM access latency", 1, 1000)
    bytes_per_cycle: int = _f(512, "B/cycle", "Ray buffer SRAM bandwidth", 1, 4096)
    idle_poll_cycles: int = _f(
        32, "cycles", "How often a unit with no rays looks for a queue again", 1, 100000
    )
    admit_outstanding: int = _f(
        16,
        "reads",
        "Ray-record reads the ray buffer keeps in flight while admitting new rays (a streaming "
        "engine, one read issued per cycle)",
        1,
        4096,
    )
    quantum_cycles: int = _f(
        16,
        "cycles",
        "At the approx level with treelets, the units (and the admission engine) run ahead of "
        "each other by at most this many cycles (the smaller of this and quantum_cycles): "
        "treelet queues' dynamics depend on the order of parks and takes, and longer quanta "
        "made approx up to 37% off detailed (docs/fidelity.md)",
        1,
        1 << 20,
    )
    max_rays_in_flight: int = _f(
        0,
        "rays",
        "Rays admitted into the machine at once; beyond what the SRAM holds, queues overflow to "
        "DRAM (0: SRAM capacity plus the ray contexts, never overflows)",
        0,
        1 << 30,
    )


@dataclass
class EnergyConfig:
    """The first-order energy and area model's technology (docs/energy_area.md): 45 nm reference
    figures (Horowitz, ISSCC 2014) scaled to node_nm (Stillmaker & Baas 2017)."""

    node_nm: float = _f(
        7.0,
        "nm",
        "Technology node; 45 nm reference figures are scaled to it (Stillmaker & Baas 2017)",
        7,
        130,
    )
    vdd: float = _f(
        0.0,
        "V",
        "Supply voltage for the energy scaling (0: the node's nominal voltage, "
        "docs/energy_area.md)",
        0,
        2,
    )
    dram_kind: str = _choice(
        "gddr6",
        ("gddr6", "lpddr5", "hbm2", "ddr4"),
        "DRAM kind: picks the energy per bit moved (docs/energy_area.md)",
    )
    dram_pj_per_bit: float = _f(
        0.0,
        "pJ/bit",
        "DRAM energy per bit read or written, overriding the kind's figure (0: the kind's)",
        0,
        1000,
    )
    fp_add_pj: float = _f(0.9, "pJ", "32-bit floating-point add (or subtract) at 45 nm", 0, 1000)
    fp_mul_pj: float = _f(3.7, "pJ", "32-bit floating-point multiply at 45 nm", 0, 1000)
    cmp_pj: float = _f(
        0.1, "pJ", "Compare, min or max of two floats at 45 nm (a 32-bit integer add)", 0, 1000
    )
    fp_add_um2: float = _f(4184.0, "um^2", "32-bit floating-point adder area at 45 nm", 0, 1e7)
    fp_mul_um2: float = _f(7700.0, "um^2", "32-bit floating-point multiplier area at 45 nm", 0, 1e7)
    cmp_um2: float = _f(137.0, "um^2", "Comparator area at 45 nm (a 32-bit integer adder)", 0, 1e7)
    datapath_overhead: float = _f(
        1.5,
        "x",
        "Pipeline registers, operand muxes and control, as a multiple of the arithmetic's "
        "energy and area",
        1,
        100,
    )
    sram_pj_64b: float = _f(
        10.0,
        "pJ",
        "64-bit read of an 8 KiB SRAM at 45 nm (wider accesses scale per bit)",
        0,
        10000,
    )
    sram_size_exponent: float = _f(
        0.5, "", "SRAM access energy grows as (size / 8 KiB) to this power", 0, 2
    )
    sram_mm2_per_mib: float = _f(5.8, "mm^2/MiB", "SRAM area per MiB of data at 45 nm", 0, 1000)
    sram_tag_overhead: float = _f(
        0.08,
        "fraction",
        "Cache tag and state bits as a fraction of data bits (area and access energy)",
        0,
        1,
    )
    leakage_mw_per_mm2: float = _f(
        50.0,
        "mW/mm^2",
        "Static (leakage) power per mm^2 of SRAM and datapath at the configured node",
        0,
        10000,
    )


@dataclass
class SimConfig:
    """The whole simulator config: the root of the tree rtsim-sim reads with --config."""

    clock_ghz: float = _f(1.0, "GHz", "Core clock: converts cycles to seconds", 0.001, 100.0)
    fidelity: str = _choice(
        "approx",
        ("functional", "analytic", "approx", "detailed"),
        "Simulation level: functional (counts only), analytic (cache simulation + roofline), "
        "approx (timed SystemC model) or detailed (per-cycle arbitration, L2 MSHRs)",
    )
    quantum_cycles: int = _f(
        256,
        "cycles",
        "How far a traversal unit may run ahead of the others (temporal decoupling)",
        1,
        1 << 20,
    )
    interconnect_latency: int = _f(
        8, "cycles", "One-way latency between an L1 and the L2", 0, 10000
    )
    ideal_memory: bool = _flag(
        False, "Every access hits in L1 at L1 latency: the upper bound on performance"
    )
    # Sections: the box, triangle, any-hit, cell, transform and plane pipelines and the two cache
    # levels share a struct with per-section defaults, as in config.h.
    dispatch: DispatchConfig = field(default_factory=DispatchConfig)
    traversal: TraversalConfig = field(default_factory=TraversalConfig)
    box: PipelineConfig = field(default_factory=lambda: PipelineConfig(8, 1, 2, "private", 4))
    triangle: PipelineConfig = field(default_factory=lambda: PipelineConfig(20, 1, 1, "private", 4))
    anyhit: PipelineConfig = field(default_factory=lambda: PipelineConfig(10, 1, 1, "private", 4))
    cell: PipelineConfig = field(default_factory=lambda: PipelineConfig(4, 1, 1, "private", 4))
    # Instance transforms of two-level structures (docs/accel.md, "Two-level structures").
    transform: PipelineConfig = field(default_factory=lambda: PipelineConfig(8, 1, 1, "private", 4))
    # Ray/split-plane tests of kd-trees, BIHs and octrees (docs/accel.md).
    plane: PipelineConfig = field(default_factory=lambda: PipelineConfig(4, 1, 2, "private", 4))
    mailbox: MailboxConfig = field(default_factory=MailboxConfig)
    # MSHRs: docs/presets.md, "How the defaults were chosen".
    l1: CacheConfig = field(default_factory=lambda: CacheConfig(16, 4, 64, 4, 16, 1, 1))
    l2: CacheConfig = field(default_factory=lambda: CacheConfig(1024, 16, 64, 20, 64, 8, 1))
    dram: DramConfig = field(default_factory=DramConfig)
    treelets: TreeletConfig = field(default_factory=TreeletConfig)
    sampling: SamplingConfig = field(default_factory=SamplingConfig)
    energy: EnergyConfig = field(default_factory=EnergyConfig)
    analytic: AnalyticConfig = field(default_factory=AnalyticConfig)

    sections: ClassVar[tuple[str, ...]] = (
        "dispatch",
        "traversal",
        "box",
        "triangle",
        "anyhit",
        "cell",
        "transform",
        "plane",
        "mailbox",
        "l1",
        "l2",
        "dram",
        "treelets",
        "sampling",
        "energy",
        "analytic",
    )

    def to_dict(self) -> dict[str, Any]:
        return dataclasses.asdict(self)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> SimConfig:
        """A config from a (partial) dict over the defaults; unknown keys and wrong types raise
        ConfigError naming the key's full path (e.g. 'l1.size_kb')."""
        return _read(cls, data, "")

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
        return apply_patch(self, unflatten(values))

    def sram_bytes(self) -> int:
        """On-chip SRAM of the accelerator: the L1s, the L2, the traversal stacks and, with
        treelet scheduling, the ray buffer."""
        t = self.traversal
        # stack_entry_bytes 0 is the structure's own, known only with a trace: a BVH's 8 here
        # (stats.json "area" has the run's exact figure).
        entry = t.stack_entry_bytes or 8
        stacks = t.units * t.ray_contexts * t.stack_entries * entry
        mailboxes = t.units * t.ray_contexts * self.mailbox.entries * 4
        ray_buffer = self.treelets.buffer_kib * 1024 if self.treelets.enabled else 0
        return (
            (self.l1.size_kib * t.units + self.l2.size_kib) * 1024 + stacks + mailboxes + ray_buffer
        )


def _names(cls: type) -> dict[str, dataclasses.Field[Any]]:
    return {f.name: f for f in dataclasses.fields(cls)}


def _join(prefix: str, name: str) -> str:
    return f"{prefix}.{name}" if prefix else name


def _check_value(f: dataclasses.Field[Any], value: Any, path: str) -> Any:
    kind = f.type if isinstance(f.type, str) else getattr(f.type, "__name__", "")
    if kind == "bool":
        if not isinstance(value, bool):
            raise ConfigError(f"config: '{path}' must be true or false, got {value!r}")
        return value
    if kind == "int":
        if isinstance(value, float) and value.is_integer():
            value = int(value)
        if isinstance(value, bool) or not isinstance(value, int) or value < 0:
            raise ConfigError(f"config: '{path}' must be a non-negative integer, got {value!r}")
        return value
    if kind == "float":
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ConfigError(f"config: '{path}' must be a number, got {value!r}")
        return float(value)
    if not isinstance(value, str):
        raise ConfigError(f"config: '{path}' must be a string, got {value!r}")
    choices = f.metadata.get("choices")
    if choices and value not in choices:
        raise ConfigError(f"config: '{path}' = '{value}' is not one of: {', '.join(choices)}")
    return value


def _read(cls: type[T], data: Any, prefix: str, base: Any = None) -> T:
    if not isinstance(data, dict):
        raise ConfigError(f"config: '{prefix or '(root)'}' must be a mapping, got {data!r}")
    fields = _names(cls)
    unknown = sorted(set(data) - set(fields))
    if unknown:
        raise ConfigError(
            f"config: unknown key '{_join(prefix, unknown[0])}' (known here: {', '.join(fields)})"
        )
    obj = copy.deepcopy(base) if base is not None else cls()
    for name, value in data.items():
        f, path = fields[name], _join(prefix, name)
        current = getattr(obj, name)
        if dataclasses.is_dataclass(current):
            setattr(obj, name, _read(type(current), value, path, current))
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
    cls: type = SimConfig
    *parents, leaf = key.split(".")
    for part in parents:
        fields = _names(cls)
        if part not in fields or part not in SimConfig.sections:
            raise ConfigError(f"config: unknown key '{key}'")
        cls = type(getattr(SimConfig(), part))
    fields = _names(cls)
    if leaf not in fields or (cls is SimConfig and leaf in SimConfig.sections):
        raise ConfigError(f"config: unknown key '{key}'")
    return fields[leaf]


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

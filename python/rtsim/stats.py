"""A simulation's results as Python sees them: `Stats`, a read-only view of RUN/stats.json.

Every key of stats.json is documented in docs/stats.md. `Stats` is a mapping over the whole
file (``stats["model"]["l2"]["read_hits"]``) and gives the headline numbers as attributes: each
key of the ``summary`` group (``stats.mrays_per_second``, ``stats.dram_bytes_per_ray``,
``stats.cycles``, ...) and each top-level group (``stats.validation``, ``stats.latency``,
``stats.model``, ...).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rtsim.errors import RtsimError


@dataclass(frozen=True, eq=False)  # Mapping's __eq__: equal when the stats are
class Stats(Mapping[str, Any]):
    """RUN/stats.json of one simulation (docs/stats.md), with the summary as attributes.

    ``data`` is the parsed file, ``config`` the config the run used (config.resolved.json),
    ``run_dir`` the run folder (None when ``rtsim.simulate`` ran in a temporary folder) and
    ``returncode`` rtsim-sim's exit status (0, or 3 when hits differ from the reference)."""

    data: dict[str, Any]
    config: dict[str, Any] = field(default_factory=dict)
    run_dir: Path | None = None
    returncode: int = 0

    @classmethod
    def load(cls, run_dir: str | Path) -> Stats:
        """The stats of a finished run folder (from `rtsim simulate`, a sweep or simulate())."""
        from rtsim.launcher import read_json

        run = Path(run_dir)
        data = read_json(run / "stats.json")
        if data is None:
            raise RtsimError(f"{run / 'stats.json'}: missing or not a JSON object")
        return cls(data, read_json(run / "config.resolved.json") or {}, run)

    @property
    def summary(self) -> dict[str, Any]:
        summary = self.data.get("summary")
        return summary if isinstance(summary, dict) else {}

    @property
    def ok(self) -> bool:
        """True when every simulated hit and work count equals the reference."""
        s = self.summary
        return s.get("hit_mismatches") == 0 and s.get("work_mismatches") == 0

    def __getitem__(self, key: str) -> Any:
        return self.data[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self.data)

    def __len__(self) -> int:
        return len(self.data)

    def __getattr__(self, name: str) -> Any:
        # Only called when normal lookup fails: summary keys first, then top-level groups.
        if name.startswith("_") or name == "data":
            raise AttributeError(name)
        if name in self.summary:
            return self.summary[name]
        if name in self.data:
            return self.data[name]
        raise AttributeError(
            f"Stats has no '{name}': summary keys are {', '.join(self.summary)}; groups are "
            f"{', '.join(self.data)} (docs/stats.md)"
        )

    def __dir__(self) -> list[str]:
        return sorted({*super().__dir__(), *self.summary, *self.data})

    def __repr__(self) -> str:
        s = self.summary
        rate = s.get("mrays_per_second")
        speed = f"{rate:.1f} Mrays/s" if isinstance(rate, (int, float)) else "no time"
        return (
            f"<Stats {s.get('fidelity', '?')}: {s.get('rays', '?')} rays, {speed}, "
            f"{s.get('hit_mismatches', '?')} hit mismatches"
            + (f", {self.run_dir}>" if self.run_dir else ">")
        )

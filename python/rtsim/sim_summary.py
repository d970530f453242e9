"""The tables `rtsim simulate` prints from RUN/stats.json (keys: docs/stats.md)."""

from __future__ import annotations

from typing import Any

from rich.console import Console
from rich.table import Table

from rtsim.summary import effects_table


def _get(stats: dict[str, Any], path: str) -> Any:
    node: Any = stats
    for part in path.split("."):
        if not isinstance(node, dict) or part not in node:
            return None
        node = node[part]
    return node


def _is_num(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def fmt_int(value: Any) -> str:
    return f"{int(value):,}" if _is_num(value) else "-"


def fmt_float(value: Any, digits: int = 2) -> str:
    return f"{value:,.{digits}f}" if _is_num(value) else "-"


def fmt_pct(value: Any) -> str:
    return f"{value:.1%}" if _is_num(value) else "-"


def fmt_bytes(value: Any) -> str:
    if not _is_num(value):
        return "-"
    for scale, unit in ((1 << 30, "GiB"), (1 << 20, "MiB"), (1 << 10, "KiB")):
        if value >= scale:
            return f"{value / scale:,.2f} {unit}"
    return f"{value:,.0f} B"


def _two_column(title: str) -> Table:
    table = Table(title=title, title_justify="left", show_header=False)
    table.add_column("what")
    table.add_column("value", justify="right")
    return table


def clock_ghz(stats: dict[str, Any]) -> float | None:
    """The simulated clock, from cycles and seconds (stats.json does not repeat the config)."""
    cycles, seconds = _get(stats, "summary.cycles"), _get(stats, "summary.seconds")
    if _is_num(cycles) and _is_num(seconds) and seconds > 0:
        return round(cycles / seconds / 1e9, 6)
    return None


def performance_table(stats: dict[str, Any]) -> Table:
    s = stats.get("summary", {}) or {}
    clock = clock_ghz(stats)
    table = _two_column("performance" + (f" at {clock:g} GHz" if clock else ""))
    table.add_row("fidelity", str(stats.get("fidelity", "-")))
    table.add_row("rays", fmt_int(s.get("rays")))
    if s.get("cycles") is not None:
        table.add_row("cycles", fmt_int(s.get("cycles")))
        table.add_row("simulated time (us)", fmt_float(_scaled(s.get("seconds"), 1e6)))
        table.add_row("Mrays/s", fmt_float(s.get("mrays_per_second")))
        table.add_row("mean ray latency (cycles)", fmt_float(s.get("avg_ray_latency_cycles"), 1))
    table.add_row("hit mismatches", fmt_int(s.get("hit_mismatches")))
    table.add_row("work mismatches", fmt_int(s.get("work_mismatches")))
    table.add_row("wall time (s)", fmt_float(s.get("wall_seconds")))
    table.add_row("simulated rays / wall s", fmt_int(s.get("simulated_rays_per_wall_second")))
    return table


def _scaled(value: Any, factor: float) -> Any:
    return value * factor if _is_num(value) else None


def utilisation_table(stats: dict[str, Any]) -> Table:
    s = stats.get("summary", {}) or {}
    model = stats.get("model", {}) or {}
    table = _two_column("utilisation and memory")
    table.add_row("traversal units busy", fmt_pct(s.get("unit_busy_fraction")))
    if s.get("simd_efficiency") is not None:
        table.add_row(
            "SIMD efficiency (active lanes / lane slots)", fmt_pct(s.get("simd_efficiency"))
        )
    table.add_row("box pipelines", fmt_pct(s.get("box_utilization")))
    table.add_row("triangle pipelines", fmt_pct(s.get("triangle_utilization")))
    anyhit = model.get("anyhit")
    if isinstance(anyhit, dict) and anyhit:
        mean = sum(b.get("utilization", 0.0) for b in anyhit.values()) / len(anyhit)
        table.add_row("any-hit pipelines", fmt_pct(mean))
    if "ideal_memory" in model:
        table.add_row("memory", "ideal (every access hits at L1 latency)")
        return table
    table.add_row("L1 hit rate (merged misses count as hits)", fmt_pct(s.get("l1_hit_rate")))
    table.add_row("L2 hit rate (merged misses count as hits)", fmt_pct(s.get("l2_hit_rate")))
    table.add_row("DRAM bytes", fmt_bytes(s.get("dram_bytes")))
    table.add_row("DRAM bytes / ray", fmt_float(s.get("dram_bytes_per_ray"), 1))
    peak = _get(stats, "model.dram.peak_bandwidth_gbps")
    bw = fmt_float(s.get("dram_bandwidth_gbps"))
    table.add_row("DRAM bandwidth (GB/s)", bw + (f" of {peak:,.1f}" if _is_num(peak) else ""))
    table.add_row("DRAM bandwidth utilisation", fmt_pct(s.get("dram_bandwidth_utilization")))
    dram = model.get("dram") or {}
    outcomes = [dram.get(k) for k in ("row_hits", "row_misses", "row_conflicts")]
    if all(_is_num(x) for x in outcomes) and sum(outcomes) > 0:  # type: ignore[arg-type]
        hits, misses, conflicts = (x / sum(outcomes) for x in outcomes)  # type: ignore[operator,arg-type]
        table.add_row(
            "DRAM row buffers (hit / miss / conflict)",
            f"{fmt_pct(hits)} / {fmt_pct(misses)} / {fmt_pct(conflicts)}",
        )
    return table


def energy_table(stats: dict[str, Any]) -> Table:
    """Energy per ray by block, efficiency, power and area (docs/energy_area.md)."""
    s = stats.get("summary", {}) or {}
    e = stats.get("energy", {}) or {}
    table = _two_column(
        f"energy and area (first-order model at {fmt_float(e.get('node_nm'), 0)} nm, "
        f"{e.get('dram_kind', '?')}; docs/energy_area.md)"
    )
    table.add_row("energy / ray (nJ)", fmt_float(s.get("energy_per_ray_nj"), 2))
    per_ray = e.get("per_ray_nj", {}) or {}
    parts = sorted(
        ((k, v) for k, v in per_ray.items() if k != "total" and _is_num(v) and v > 0),
        key=lambda kv: -kv[1],
    )
    if parts:
        table.add_row("  by block (nJ)", ", ".join(f"{k} {v:.3g}" for k, v in parts))
    table.add_row("Mrays / J", fmt_float(s.get("mrays_per_joule"), 1))
    table.add_row("power (W)", fmt_float(s.get("power_w"), 3))
    table.add_row("area (mm^2)", fmt_float(s.get("area_mm2"), 3))
    return table


def _gain(x: Any) -> str:
    return f"{x:.2f}x" if _is_num(x) else "-"


def _value(v: Any) -> str:
    return ("true" if v else "false") if isinstance(v, bool) else str(v)


def _knob(k: dict[str, Any]) -> str:
    return f"--set {k.get('key')}={_value(k.get('to'))} (now {_value(k.get('from'))})"


def not_estimated(why: Any) -> str:
    """ "not estimated (why)", never "not estimated (not estimated: ...)"."""
    text = str(why or "").strip()
    for lead in ("not estimated: ", "not estimated (", "not estimated"):
        if text.startswith(lead):
            text = text[len(lead) :]
            if lead.endswith("(") and text.endswith(")"):
                text = text[:-1]
            break
    return f"not estimated ({text})" if text else "not estimated"


def verdict_rows(verdict: dict[str, Any]) -> list[tuple[str, str]]:
    """The verdict's top three knobs (estimated, or to be measured), the best gains per mm^2,
    co-limits, what the estimator does not cover and, with --check-verdict, what re-runs
    measured."""
    rows: list[tuple[str, str]] = []
    for i, k in enumerate(verdict.get("top") or []):
        est = (
            f"{_gain(k.get('speedup'))} estimated"
            if _is_num(k.get("speedup"))
            else not_estimated(k.get("why_not"))
        )
        saved = k.get("dram_nj_saved_per_ray")
        if _is_num(saved) and saved > 0.005:
            est += f", saves {saved:.2f} nJ/ray of DRAM energy"
        rows.append(("  try" if i == 0 else "", f"{_knob(k)}: {est}"))
    for i, k in enumerate(verdict.get("top_per_mm2") or []):
        rows.append(
            (
                "  per mm^2" if i == 0 else "",
                f"{_knob(k)}: {_gain(k.get('speedup'))} for {k.get('added_mm2', 0):.3f} mm^2",
            )
        )
    for co in verdict.get("co_limits") or []:
        alone = ", ".join(_gain(a) for a in co.get("alone", []))
        rows.append(
            (
                "  co-limit",
                f"{' + '.join(co.get('sets', []))}: {_gain(co.get('joint'))} jointly "
                f"(alone {alone})",
            )
        )
    for i, k in enumerate(k for k in verdict.get("structural") or [] if not k.get("refused")):
        added = k.get("added_mm2")
        price = f" ({added:+.3f} mm^2)" if _is_num(added) else ""
        rows.append(
            ("  structural" if i == 0 else "", f"{_knob(k)}{price}: measure: {k.get('measure')}")
        )
    coverage = verdict.get("coverage") or {}
    if coverage.get("why_not"):
        rows.append(("  caveat", str(coverage["why_not"])))
    for i, c in enumerate(verdict.get("check") or []):
        rows.append(
            (
                "  re-run" if i == 0 else "",
                f"{' + '.join(c.get('sets', []))}: measured {_gain(c.get('measured'))}, "
                f"estimated {_gain(c.get('estimated'))}",
            )
        )
    return rows


def why_slow_table(stats: dict[str, Any]) -> Table:
    """The verdict, where context time went, and the roofline (docs/stats.md, `verdict`,
    `model.cycle_accounting`, `roofline`)."""
    table = _two_column("why is it slow (docs/model.md)")
    verdict = stats.get("verdict") or {}
    if verdict:
        label = str(verdict.get("label", verdict.get("binding", "-")))
        binding = verdict.get("binding")
        table.add_row(
            "bottleneck", label + (f" ({binding})" if binding and binding != label else "")
        )
        evidence = (verdict.get("evidence") or {}).get("text")
        if evidence:
            table.add_row("  evidence", str(evidence))
        for row, text in verdict_rows(verdict):
            table.add_row(row, text)
    fractions = _get(stats, "model.cycle_accounting.fractions") or {}
    top = sorted(
        ((k, v) for k, v in fractions.items() if _is_num(v) and v >= 0.01), key=lambda kv: -kv[1]
    )[:5]
    if top:
        table.add_row("context time", ", ".join(f"{k} {v:.0%}" for k, v in top))
    roof = stats.get("roofline") or {}
    bound = roof.get("bound_rays_per_second")
    achieved = roof.get("rays_per_second")
    agreement = verdict.get("agreement") or {}
    knob = agreement.get("knob")

    def relaxed(flag: Any) -> str:
        if not knob or flag is None:
            return ""
        return f"; {knob} relaxes it" if flag else f"; {knob} does not relax it"

    if _is_num(bound) and _is_num(achieved) and bound > 0:
        name = roof.get("bound")
        label = roof.get("bound_label") or name
        table.add_row(
            "roofline",
            f"{achieved / 1e6:,.2f} of {bound / 1e6:,.2f} Mrays/s allowed by {label}"
            f"{f' ({name})' if label != name else ''} ({achieved / bound:.0%})"
            f"{relaxed(agreement.get('roofline_relaxed'))}",
        )
    if agreement.get("analytic_binding"):
        table.add_row(
            "analytic binding",
            f"{agreement['analytic_binding']}{relaxed(agreement.get('analytic_relaxed'))}",
        )
    return table


def latency_table(stats: dict[str, Any]) -> Table:
    lat = stats.get("latency", {}) or {}
    table = Table(title="ray latency (cycles)", title_justify="left")
    for column in ("mean", "p50", "p95", "p99", "max"):
        table.add_column(column, justify="right")
    table.add_row(
        fmt_float(lat.get("mean_cycles"), 1),
        fmt_int(lat.get("p50_cycles")),
        fmt_int(lat.get("p95_cycles")),
        fmt_int(lat.get("p99_cycles")),
        fmt_int(lat.get("max_cycles")),
    )
    return table


def instantiated_table(stats: dict[str, Any]) -> Table:
    table = Table(title="instantiated blocks", title_justify="left")
    table.add_column("block")
    table.add_column("built")
    table.add_column("why")
    for entry in stats.get("instantiated", []) or []:
        if isinstance(entry, dict):
            built = entry.get("instantiated")
            table.add_row(
                str(entry.get("block", "?")), "yes" if built else "no", str(entry.get("why", ""))
            )
    return table


def frames_table(stats: dict[str, Any]) -> Table:
    """Each frame of an animated trace (stats.json "frames"), replayed in sequence."""
    table = Table(title="frames (replayed in sequence, caches warm)", title_justify="left")
    for column in (
        "frame",
        "rays",
        "cycles",
        "Mrays/s",
        "DRAM B/ray",
        "L1 hit",
        "L2 hit",
        "TLAS build ms",
    ):
        table.add_column(column, justify="right")
    for f in stats.get("frames", []) or []:
        table.add_row(
            fmt_int(f.get("frame")),
            fmt_int(f.get("rays")),
            fmt_int(f.get("cycles")),
            fmt_float(f.get("mrays_per_second")),
            fmt_float(f.get("dram_bytes_per_ray"), 1),
            fmt_pct(f.get("l1_hit_rate")),
            fmt_pct(f.get("l2_hit_rate")),
            fmt_float(f.get("tlas_build_ms")),
        )
    return table


def resolved_table(stats: dict[str, Any]) -> Table:
    """What the run's resolution step settled (stats.json summary.resolved, docs/capabilities.md):
    the fields the config left to the run, and settings that have no effect on it."""
    r = _get(stats, "summary.resolved") or {}
    table = _two_column("resolved for this run")
    for d in r.get("derived") or []:
        table.add_row(f"{d.get('key')} = {d.get('value')}", f"derived: {d.get('why')}")
    for u in r.get("unused") or []:
        table.add_row(str(u.get("key")), f"no effect: {u.get('why')}")
    return table


def mailbox_table(stats: dict[str, Any]) -> Table:
    """What the mailboxes saved (stats.json "mailbox", docs/accel.md, Mailboxes)."""
    m = stats.get("mailbox", {}) or {}
    per_ray = m.get("per_ray", {}) or {}
    table = _two_column(f"mailboxes ({fmt_int(m.get('entries'))} entries per ray)")
    table.add_row("lookups / ray", fmt_float(per_ray.get("lookups"), 2))
    table.add_row("hit rate", fmt_pct(m.get("hit_rate")))
    table.add_row("triangle tests / ray", fmt_float(per_ray.get("tri_tests"), 2))
    table.add_row("  without the mailbox", fmt_float(per_ray.get("tri_tests_without_mailbox"), 2))
    table.add_row("tests and fetches saved", fmt_pct(m.get("tri_tests_saved_fraction")))
    return table


def short_stack_table(stats: dict[str, Any]) -> Table:
    """A short stack's restarts and re-traversal (stats.json "short_stack", docs/accel.md)."""
    m = stats.get("short_stack", {}) or {}
    per_ray = m.get("per_ray", {}) or {}
    table = _two_column(f"short stack ({fmt_int(m.get('entries'))} entries per ray, restart trail)")
    table.add_row("entries dropped / ray", fmt_float(per_ray.get("stack_drops"), 2))
    table.add_row("restarts / ray", fmt_float(per_ray.get("restarts"), 3))
    table.add_row("nodes revisited / ray", fmt_float(per_ray.get("restart_steps"), 2))
    table.add_row("extra node steps", fmt_pct(m.get("extra_steps_fraction")))
    table.add_row("extra box tests", fmt_pct(m.get("extra_box_tests_fraction")))
    table.add_row("spill bytes avoided", fmt_int(m.get("spill_bytes_avoided")))
    return table


def box_precision_table(stats: dict[str, Any]) -> Table:
    """Reduced-precision box tests: the extra walk and the narrower pipeline's energy and area
    (stats.json "box_precision", docs/accel.md)."""
    m = stats.get("box_precision", {}) or {}
    per_ray = m.get("per_ray", {}) or {}
    table = _two_column(f"reduced-precision box tests ({fmt_int(m.get('bits'))} mantissa bits)")
    table.add_row("extra boxes entered / ray", fmt_float(per_ray.get("box_hits"), 3))
    table.add_row("extra node steps", fmt_pct(m.get("extra_steps_fraction")))
    table.add_row("extra box tests", fmt_pct(m.get("extra_box_tests_fraction")))
    table.add_row("extra triangle tests", fmt_pct(m.get("extra_tri_tests_fraction")))
    table.add_row(
        "box test pJ (fp32)",
        f"{fmt_float(m.get('box_test_pj'), 2)} ({fmt_float(m.get('box_test_pj_fp32'), 2)})",
    )
    table.add_row(
        "box pipelines mm^2 (fp32)",
        f"{fmt_float(m.get('box_mm2'), 3)} ({fmt_float(m.get('box_mm2_fp32'), 3)})",
    )
    return table


def print_sim_summary(stats: dict[str, Any], console: Console | None = None) -> None:
    """Prints the run's headline numbers, utilisation, latency and what was built and why."""
    console = console or Console()
    console.print(performance_table(stats))
    if (_get(stats, "summary.resolved") or {}).get("derived") or (
        _get(stats, "summary.resolved") or {}
    ).get("unused"):
        console.print(resolved_table(stats))
    if len(stats.get("frames", []) or []) > 1:
        console.print(frames_table(stats))
    if _get(stats, "model.shading"):
        from rtsim.frame_summary import frame_table

        console.print(frame_table(stats))
    for key, title in (
        ("summary.study_warnings", "too small to answer its question (docs/treelets.md)"),
        ("summary.fidelity_warnings", "outside the level's measured band (docs/fidelity.md)"),
    ):
        warnings = _get(stats, key) or []
        if warnings:
            table = _two_column(title)
            for w in warnings:
                table.add_row("[bold yellow]warning[/]", str(w))
            console.print(table)
    if _get(stats, "summary.cycles") is not None:
        console.print(utilisation_table(stats))
        if stats.get("verdict") or stats.get("roofline"):
            console.print(why_slow_table(stats))
        console.print(latency_table(stats))
        console.print(instantiated_table(stats))
    if stats.get("mailbox"):
        console.print(mailbox_table(stats))
    if stats.get("short_stack"):
        console.print(short_stack_table(stats))
    if stats.get("box_precision"):
        console.print(box_precision_table(stats))
    if stats.get("energy"):
        console.print(energy_table(stats))
    if stats.get("effects"):
        console.print(effects_table({"effects": stats["effects"]}))


def print_mismatches(stats: dict[str, Any], console: Console | None = None) -> None:
    """The loud message of exit code 3: how many rays differ and the first of them."""
    console = console or Console(stderr=True)
    v = stats.get("validation", {}) or {}
    console.print(
        f"[bold red]MISMATCH: {fmt_int(v.get('hit_mismatches'))} hit(s) and "
        f"{fmt_int(v.get('work_mismatches'))} work count(s) differ from the reference tracer "
        f"(of {fmt_int(v.get('rays_checked'))} rays checked)[/]"
    )
    if v.get("texel_mismatches"):
        console.print(
            f"[bold red]MISMATCH: {fmt_int(v.get('texel_mismatches'))} ray(s)' texel addresses "
            f"differ from the reference tracer's: {v.get('first_texel_mismatch')}[/]"
        )
    for example in (v.get("first_mismatches") or [])[:10]:
        if isinstance(example, dict):
            console.print(
                f"[red]  ray {example.get('ray')}: {example.get('difference')}[/]", highlight=False
            )

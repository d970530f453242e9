"""HTML reports of sweeps: data.py reads the results store, figures.py draws with matplotlib,
html.py assembles one self-contained page (figures embedded as PNG)."""

from rtsim.report.html import render_report, write_report

__all__ = ["render_report", "write_report"]

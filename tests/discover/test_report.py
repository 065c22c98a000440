"""Plots and the HTML page of a discovery (physbench/discover/report.py)."""

from __future__ import annotations

from physbench.discover.report import write_report


def test_report_writes_the_page_and_the_figures(drag_discovery, tmp_path):
    page = write_report(drag_discovery, tmp_path / "rep")
    assert page.is_file() and (tmp_path / "rep" / "trajectories.png").is_file()
    assert (tmp_path / "rep" / "candidates.png").is_file()
    html = page.read_text()
    assert "linear_drag" in html and "<h2>What is wrong with the base model</h2>" in html

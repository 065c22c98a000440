"""Plots and the HTML page of a discovery (physbench/discover/report.py)."""

from __future__ import annotations

import base64
import re
from pathlib import Path

from physbench.discover.report import write_report


def test_report_writes_the_page_and_the_figures(drag_discovery, tmp_path):
    page = write_report(drag_discovery, tmp_path / "rep")
    assert page.is_file() and (tmp_path / "rep" / "trajectories.png").is_file()
    assert (tmp_path / "rep" / "candidates.png").is_file()
    html = page.read_text()
    assert "linear_drag" in html and "<h2>What is wrong with the base model</h2>" in html


def test_the_page_embeds_every_figure_so_it_stands_alone(drag_discovery, tmp_path):
    page = write_report(drag_discovery, tmp_path / "rep")
    html = page.read_text()
    sources = re.findall(r'<img[^>]*\ssrc="([^"]*)"', html)
    pngs = sorted(p.name for p in (tmp_path / "rep").glob("*.png"))
    assert len(sources) == len(pngs) >= 2
    assert all(s.startswith("data:image/png;base64,") for s in sources), [s[:40] for s in sources]
    embedded = {base64.b64decode(s.split(",", 1)[1]) for s in sources}
    assert embedded == {(tmp_path / "rep" / name).read_bytes() for name in pngs}


def test_every_figure_axis_says_its_unit(drag_discovery, tmp_path, monkeypatch):
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    drawn: dict[str, Figure] = {}
    save = Figure.savefig

    def keep(fig: Figure, path, *args, **kwargs):
        drawn[Path(path).name] = fig
        return save(fig, path, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", keep)
    write_report(drag_discovery, tmp_path / "rep")
    traj = drawn["trajectories.png"]
    left, right = traj.axes[0::2], traj.axes[1::2]
    assert all(ax.get_ylabel().endswith(("(m)", "(rad)")) for ax in left + right)
    assert "t (s)" in left[-1].get_xlabel() and right[-1].get_xlabel() == "t (s)"
    assert "engine pymunk" in traj.get_suptitle()
    (cand,) = drawn["candidates.png"].axes
    assert cand.get_xlabel().startswith("held-out error (m)") and cand.get_ylabel()
    (events,) = drawn["events.png"].axes
    assert events.get_ylabel() == "RMS residual (m)" and events.get_xlabel() == "body, event"

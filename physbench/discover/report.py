"""Plots and an HTML page for a discovery: observed vs simulated trajectories (base and extended
model), residuals over time, residuals per event, the candidates' held-out errors, and the verdict.

The page embeds its figures as ``data:`` URIs, so ``index.html`` alone can be mailed or moved; the
PNG files are written next to it too. matplotlib (Agg backend) is imported inside
:func:`write_report` only.
"""

from __future__ import annotations

import html
import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from physbench.discover.phrasing import describe
from physbench.discover.residuals import EVENTS
from physbench.discover.verdict import params_text, text
from physbench.plotting.embed import png_data_uri

if TYPE_CHECKING:
    from physbench.discover.diagnostics import RunView
    from physbench.discover.results import Discovery

#: Runs and bodies drawn at most (the JSON holds every number).
MAX_RUNS, MAX_BODIES = 3, 3
DPI = 80


def _field_series(
    v: RunView, body: str, f: str
) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    assert v.recording is not None
    tr = v.recording.track(body)
    if f not in tr.fields or (v.recording.fields is not None and f not in v.recording.fields):
        return None
    i = v.measured.bodies.index(body)
    col = {"x": 0, "y": 1, "angle": 2}[f]
    return tr.t, tr.values(f), v.measured.states[:, i, col]


def write_report(disc: Discovery, folder: str | Path, *, dpi: int = DPI) -> Path:
    """Write the figures and ``index.html`` into ``folder``; returns the HTML path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    report = _report(disc, plt, out, dpi)
    drawn = (
        _trajectories(report),
        _frame_residuals(report),
        _event_residuals(report),
        _candidates(report),
    )
    figures = [f for f in drawn if f is not None]
    page = out / "index.html"
    page.write_text(_html(disc, [(out / f, cap) for f, cap in figures]), encoding="utf-8")
    return page


@dataclass(frozen=True)
class _Report:
    """What the figures of one report draw from: the discovery, both models' views of its runs,
    where each run's fitted part ends, the runs shown and the extended model's label."""

    disc: Discovery
    plt: Any  # matplotlib.pyplot, imported by write_report only
    out: Path
    dpi: int
    base_v: list[RunView]
    final_v: list[RunView]
    cut: dict[int, float]
    shown: list[int]
    ext: str

    def save(self, fig: Any, name: str, caption: str) -> tuple[str, str]:
        """Lay out (every text inside the figure), write and close ``fig``; returns its file name
        and caption."""
        from physbench.plotting.layout import fit_text

        fig.set_layout_engine("tight")
        fit_text(fig)
        fig.savefig(self.out / name, dpi=self.dpi)
        self.plt.close(fig)
        return name, caption


def _report(disc: Discovery, plt: Any, out: Path, dpi: int) -> _Report:
    """Simulate both models on every run and pick the runs the figures show."""
    from physbench.discover.diagnostics import views

    base_v = views(disc.base.model)
    final_v = views(disc.final.model) if disc.causes else base_v
    split = disc.split
    cut = (
        {p.run: p.t_end for p in split.fit}
        if split.kind == "time"
        else {p.run: p.t_end for p in split.lead}
    )
    # held-out runs first: they show how the models predict data they were not fitted on
    order = list(split.test_runs) + [i for i in range(len(disc.runs)) if i not in split.test_runs]
    shown = order[:MAX_RUNS] if split.kind == "runs" else list(range(min(len(disc.runs), MAX_RUNS)))
    ext = " + ".join(disc.causes) or "base"
    return _Report(disc, plt, out, dpi, base_v, final_v, cut, shown, ext)


def _trajectories(r: _Report) -> tuple[str, str] | None:
    """Observed vs simulated and the residuals of the recorded fields of the runs shown."""
    disc = r.disc
    rec_runs = [i for i in r.shown if disc.runs[i].recording is not None]
    if not rec_runs:
        return None
    rows = []
    for i in rec_runs:
        rec = disc.runs[i].recording
        assert rec is not None
        for body in rec.bodies[:MAX_BODIES]:
            for f in ("x", "y", "angle"):
                if _field_series(r.base_v[i], body, f) is not None:
                    rows.append((i, body, f))
    rows = rows[:9]
    fig, axes = r.plt.subplots(len(rows), 2, figsize=(11, 2.2 * len(rows)), squeeze=False)
    for (i, body, f), (ax, axr) in zip(rows, axes, strict=True):
        _trajectory_row(r, ax, axr, i, body, f)
    axes[0, 0].legend(fontsize=7, loc="best")
    axes[0, 1].legend(fontsize=7, loc="best")
    axes[-1, 0].set_xlabel("t (s); dashed: end of the fitted part", fontsize=8)
    axes[-1, 1].set_xlabel("t (s)", fontsize=8)
    fig.suptitle(f"engine {disc.engine}: {disc.split.describe(disc.runs)}", fontsize=9)
    return r.save(
        fig,
        "trajectories.png",
        "Observed vs simulated (left) and residuals (right), base and extended model.",
    )


def _trajectory_row(r: _Report, ax: Any, axr: Any, i: int, body: str, f: str) -> None:
    """Draw field ``f`` of ``body`` in run ``i``: the data and both models on ``ax``, their
    residuals on ``axr``."""
    disc, split, base_v, final_v = r.disc, r.disc.split, r.base_v, r.final_v
    s_b = _field_series(base_v[i], body, f)
    s_f = _field_series(final_v[i], body, f)
    assert s_b is not None and s_f is not None
    t, obs, sim_b = s_b
    ax.plot(t, obs, ".", ms=2.5, color="k", label="observed")
    ax.plot(base_v[i].measured.times, sim_b, "-", lw=1.0, color="tab:blue", label="base")
    if disc.causes:
        ax.plot(final_v[i].measured.times, s_f[2], "-", lw=1.0, color="tab:red", label=r.ext)
    ax.set_ylabel(f"{body} {f} ({'rad' if f == 'angle' else 'm'})", fontsize=8)
    held = " (held out)" if split.kind == "runs" and i in split.test_runs else ""
    ax.set_title(f"run {disc.runs[i].name}{held}", fontsize=8)
    ax.set_xlim(t[0], t[-1])
    assert base_v[i].simulated is not None and final_v[i].simulated is not None
    rb = base_v[i].simulated.track(body).values(f) - obs
    rf = final_v[i].simulated.track(body).values(f) - obs
    if f == "angle":
        rb, rf = (
            (rb + math.pi) % (2 * math.pi) - math.pi,
            (rf + math.pi) % (2 * math.pi) - math.pi,
        )
    axr.plot(t, rb, "-", lw=0.8, color="tab:blue", label="base")
    if disc.causes:
        axr.plot(t, rf, "-", lw=0.8, color="tab:red", label=r.ext)
    axr.axhline(0, color="0.6", lw=0.5)
    axr.set_ylabel(f"simulated − observed ({'rad' if f == 'angle' else 'm'})", fontsize=8)
    for a in (ax, axr):
        if i in r.cut:
            a.axvline(r.cut[i], color="0.5", ls="--", lw=0.8)
        a.tick_params(labelsize=7)


def _frame_residuals(r: _Report) -> tuple[str, str] | None:
    """The RMS image residual per frame of the filmed runs shown, base and extended model."""
    disc = r.disc
    frame_runs = [i for i in r.shown if disc.runs[i].frames is not None]
    if not frame_runs:
        return None
    fig, ax = r.plt.subplots(figsize=(7, 3))
    for label, scored, color in (("base", disc.base, "tab:blue"), (r.ext, disc.final, "tab:red")):
        if label != "base" and not disc.causes:
            continue
        for n, i in enumerate(frame_runs):
            res = scored.model.residuals("fit" if disc.split.kind == "time" else "held", runs=[i])
            f = disc.runs[i].frames
            assert f is not None
            per = int(np.prod(f.shape[1:]))
            k = res.size // per
            ax.plot(
                np.arange(k) / disc.runs[i].scene.fps,
                np.sqrt(np.mean(res[: k * per].reshape(k, per) ** 2, axis=1)),
                color=color,
                label=label if n == 0 else None,  # one legend entry per model, not per run
            )
    ax.set_xlabel("t (s), fitted part")
    ax.set_ylabel("RMS residual (pixel value, in [0, 1])")
    ax.set_title(f"engine {disc.engine}", fontsize=8)
    ax.legend(fontsize=7)
    return r.save(fig, "frames.png", "Image residual per frame, base and extended model.")


def _event_residuals(r: _Report) -> tuple[str, str] | None:
    """Bars of the residual RMS per body and event, base and extended model."""
    disc = r.disc
    bb, bf = disc.breakdowns.get("base"), disc.breakdowns.get("final")
    if bb is None or not bb.per_event:
        return None
    bodies = list(bb.per_event)[:6]
    labels = [(b, e) for b in bodies for e in EVENTS if e in bb.per_event[b]]
    if not labels:
        return None
    fig, ax = r.plt.subplots(figsize=(max(5, 0.8 * len(labels)), 3))
    x = np.arange(len(labels))
    ax.bar(x - 0.2, [bb.per_event[b][e] for b, e in labels], 0.4, label="base", color="tab:blue")
    if disc.causes and bf is not None:
        ax.bar(
            x + 0.2,
            [bf.per_event.get(b, {}).get(e, np.nan) for b, e in labels],
            0.4,
            label=r.ext,
            color="tab:red",
        )
    ax.set_xticks(x, [f"{b}\n{e}" for b, e in labels], fontsize=7)
    ax.set_xlabel("body, event", fontsize=8)
    ax.set_ylabel(f"RMS residual ({disc.unit})", fontsize=8)
    ax.legend(fontsize=7)
    return r.save(fig, "events.png", "Residual RMS per body and event (whole runs).")


def _candidates(r: _Report) -> tuple[str, str] | None:
    """Bars of the first round's held-out errors, the chosen candidate in red, the base's as a
    line."""
    disc = r.disc
    if not disc.candidates:
        return None
    first = [c for c in disc.candidates if c.round == 1]
    fig, ax = r.plt.subplots(figsize=(7, 0.35 * len(first) + 1.2))
    y = np.arange(len(first))
    ax.barh(
        y,
        [c.heldout_error for c in first],
        color=["tab:red" if c.chosen else "tab:gray" for c in first],
    )
    ax.axvline(disc.base.heldout, color="tab:blue", ls="--", lw=1, label="base")
    ax.set_yticks(y, [c.effect for c in first], fontsize=7)
    ax.set_ylabel("candidate effect added to the base model", fontsize=8)
    ax.set_xlabel(f"held-out error ({disc.unit}), round 1", fontsize=8)
    ax.legend(fontsize=7)
    return r.save(fig, "candidates.png", "Held-out error of base + each candidate (red: chosen).")


def _html(disc: Discovery, figures: list[tuple[Path, str]]) -> str:
    e = html.escape
    rows = [
        "<tr><th>round</th><th>effect</th><th>parameters</th><th>held-out error</th>"
        "<th>gain</th><th>ΔBIC</th><th>verdict</th><th>note</th></tr>",
        f"<tr><td>0</td><td>base</td><td></td><td>{disc.base.heldout:.5g}</td>"
        "<td></td><td></td><td></td><td></td></tr>",
    ]
    for c in disc.candidates:
        verdict = "chosen" if c.chosen else ("significant" if c.significant else "")
        rows.append(
            f"<tr{' class=chosen' if c.chosen else ''}><td>{c.round}</td><td>{e(c.effect)}</td>"
            f"<td>{e(params_text(c))}</td><td>{c.heldout_error:.5g}</td><td>{c.gain:+.1%}</td>"
            f"<td>{c.delta_criterion:+.1f}</td><td>{verdict}</td><td>{e(c.note)}</td></tr>"
        )
    figs = "\n".join(
        f'<figure><img src="{png_data_uri(f)}" alt="{e(cap)}"><figcaption>{e(cap)}</figcaption>'
        "</figure>"
        for f, cap in figures
    )
    findings: dict[str, Any] = disc.findings
    items = "".join(
        f"<li>{e(describe(f))}{' → ' + e(', '.join(f.suggests)) if f.suggests else ''}</li>"
        for f in findings.get("base", [])
    )
    title = "physbench discover: " + (", ".join(disc.causes) if disc.causes else "no cause found")
    style = (
        "body{font-family:sans-serif;max-width:1100px;margin:1em auto;} "
        "pre{background:#f6f6f6;padding:.6em;overflow-x:auto;font-size:12px}\n"
        "table{border-collapse:collapse;font-size:13px} td,th{border:1px solid #ccc;"
        "padding:2px 6px} tr.chosen{background:#fde2e2}\n"
        "img{max-width:100%} figcaption{font-size:12px;color:#555}"
    )
    gain = (
        f"Gain on held-out data: <b>{disc.gain:.1%}</b> (held-out error "
        f"{disc.base.heldout:.5g} → {disc.final.heldout:.5g} {e(disc.unit)})."
    )
    none = "<li>no summary statistic stands out from the noise</li>"
    return f"""<!doctype html>
<html><head><meta charset="utf-8"><title>{e(title)}</title>
<style>{style}</style></head><body>
<h1>{e(title)}</h1>
<p>{gain}
Engine {e(disc.engine)}; {e(disc.split.describe(disc.runs))}.</p>
<h2>What is wrong with the base model</h2><ul>{items or none}</ul>
<h2>Candidates</h2><table>{"".join(rows)}</table>
<h2>Figures</h2>{figs}
<h2>Verdict</h2><pre>{e(text(disc))}</pre>
</body></html>
"""

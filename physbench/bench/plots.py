"""Figures of a sweep, from its long table (matplotlib, Agg backend, imported inside each
function).

- :func:`convergence`: the normalized MSE of the best-so-far iterate by image MSE per iteration,
  mean over seeds and the spread (interquartile band) for every estimator, one panel per unknown
  set (the paper's Fig. 3).
- :func:`trajectories`: the iterates of the first seeds in the plane of two unknowns, as arrows,
  with the truth as a filled circle (Fig. 5).
- :func:`landscape`: image MSE against the deviation of one parameter from its nominal value,
  per body (Fig. 4), with the sweep's engine and renderer; this one simulates.
- :func:`win_rate`: how often each estimator ends closer to the truth than each other one.
- :func:`time_to_accuracy`: the share of seeds whose answer has reached the paper's value, against
  simulations and against wall-clock seconds (:mod:`physbench.bench.time_to_accuracy`).
- :func:`coverage`: for estimators that return a posterior, how often the truth lies inside
  its central intervals against how often it should (:mod:`physbench.posterior.scoring`).

Axes carry units (:mod:`physbench.plotting.units`), legends sit outside the axes, titles name the
engine and blur, and iterations are numbered as in the long table (0: the initial guess).
"""

from __future__ import annotations

import json
import re
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from physbench.bench import tables
from physbench.bench.tables import (
    calibration_scores,
    final_rows,
    has_posteriors,
    paper_value,
    param_frame,
    scene_label,
    unknowns_label,
    upgrade,
    win_rate_table,
)
from physbench.errors import counted
from physbench.plotting.units import DIMENSIONLESS, IMAGE_MSE_UNIT, with_unit
from physbench.render.base import DEFAULT_RENDERER
from physbench.simulators.base import DEFAULT_SIMULATOR

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.figure import Figure

    from physbench.parameter import Parameter

#: Settings that split figures (everything in a configuration but unknowns and estimator).
SETTINGS = ("scene", *tables.SETTINGS)
DPI = 90


def _plt() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _groups(df: pd.DataFrame, cols: Sequence[str]) -> list[tuple[dict[str, Any], pd.DataFrame]]:
    """(values, rows) per distinct ``cols`` in spec order."""
    order = df.sort_values("cell_index").drop_duplicates(list(cols))[list(cols)]
    out = []
    for vals in order.itertuples(index=False):
        cfg = dict(zip(cols, vals, strict=True))
        sel = np.logical_and.reduce([df[c] == v for c, v in cfg.items()])
        out.append((cfg, df[sel]))
    return out


def _varying(df: pd.DataFrame) -> list[str]:
    return [c for c in SETTINGS[1:] if df[c].nunique(dropna=False) > 1]


def _name(prefix: str, cfg: dict[str, Any], varying: Sequence[str], extra: str = "") -> str:
    parts = [
        prefix,
        str(cfg["scene"]),
        *(f"{c}{cfg[c]}" for c in varying),
        *([extra] if extra else []),
    ]
    return re.sub(r"[^A-Za-z0-9_.+-]+", "-", "_".join(parts)) + ".png"


def _title(cfg: dict[str, Any], varying: Sequence[str]) -> str:
    """The scene, its engine and blur (always: a reader needs them), then the other settings
    that vary across the sweep."""
    bits = [f"engine {cfg['engine']}", f"blur {float(cfg['blur']):g} px"]
    bits += [f"{c} {cfg[c]}" for c in varying if c not in ("engine", "blur")]
    return f"{scene_label(str(cfg['scene']))} ({', '.join(bits)})"


def _save(fig: Figure, path: Path) -> Path:
    """PNG with a 128-colour palette: line plots lose nothing visible and shrink 2-4x (committed
    files); every text fitted inside the figure first
    (:func:`~physbench.plotting.layout.fit_text`)."""
    import io

    from PIL import Image

    from physbench.plotting.layout import fit_text

    fit_text(fig)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=DPI)
    _plt().close(fig)
    buf.seek(0)
    with Image.open(buf) as im:
        im.convert("RGB").quantize(colors=128).save(path, optimize=True)
    return path


def convergence(df: pd.DataFrame, out: Path) -> list[Path]:
    """One figure per scene (and setting): a panel per unknown set, a line per estimator."""
    plt = _plt()
    ok = df[(df["status"] == "ok") & df["iteration"].notna()]
    if ok.empty:
        return []
    varying = _varying(df)
    paths = []
    for cfg, rows in _groups(ok, SETTINGS):
        sets = list(dict.fromkeys(rows.sort_values("cell_index")["unknowns"]))
        fig, axes = plt.subplots(
            1, len(sets), figsize=(4.2 * len(sets), 3.8), squeeze=False, layout="constrained"
        )
        for ax, unknowns in zip(axes[0], sets, strict=True):
            sub = rows[rows["unknowns"] == unknowns]
            for est, er in _groups(sub, ["estimator"]):
                y = er.pivot_table(index="seed", columns="iteration", values="best_nmse").to_numpy(
                    dtype=float
                )
                x = np.array(er["iteration"].drop_duplicates().sort_values(), dtype=int)
                lo, hi = np.nanpercentile(y, [25, 75], axis=0)
                (line,) = ax.plot(
                    x,
                    np.nanmean(y, axis=0),
                    marker="o",
                    ms=2.5,
                    lw=1.3,
                    label=f"{est['estimator']}",
                )
                ax.fill_between(x, lo, hi, color=line.get_color(), alpha=0.15, lw=0)
            for which, style in (("NN", "--"), ("Hyperopt", ":")):
                ref = paper_value(str(cfg["scene"]), unknowns, which)
                if ref:
                    ax.axhline(
                        ref[0], color="0.35", ls=style, lw=1, label=f"paper {which} (11 it.)"
                    )
            ax.set_yscale("log")
            ax.set_title(unknowns_label(unknowns), fontsize="medium")
            ax.set_xlabel("iteration (0: initial guess)")
            ax.xaxis.get_major_locator().set_params(integer=True)
            ax.grid(True, which="both", alpha=0.25)
        axes[0, 0].set_ylabel(f"normalized MSE ({DIMENSIONLESS})")
        _legend_below(fig, axes[0])
        n = rows["seed"].nunique()
        fig.suptitle(
            f"{_title(cfg, varying)}\nnormalized MSE of the best-so-far iterate by image MSE: "
            f"mean over {counted(n, 'seed')}, band = interquartile range",
            fontsize="medium",
        )
        paths.append(_save(fig, out / _name("convergence", cfg, varying)))
    return paths


def _legend_below(fig: Figure, axes: Sequence[Any]) -> None:
    """One legend for the figure, below the axes so it covers no data (entries of every axes,
    each label once); needs a constrained layout."""
    entries: dict[str, Any] = {}
    for ax in axes:
        for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
            entries.setdefault(label, handle)
    if entries:
        from physbench.plotting.layout import legend_below

        legend_below(fig, list(entries.values()), list(entries), ncols=5, fontsize="x-small")


def _unknowns(scene: str, seed: int) -> dict[str, Parameter]:
    """The scene's unknowns by key (ranges and units), or nothing for a scene file that moved."""
    try:
        from physbench.scenes import resolve_scene

        return {u.key: u for u in resolve_scene(scene, seed).unknowns}
    except Exception:  # a scene file that moved: fall back to the data's extent, no units
        return {}


def _param_label(key: str, unknowns: Mapping[str, Parameter]) -> str:
    return with_unit(key, unknowns[key].unit) if key in unknowns else key


def trajectories(df: pd.DataFrame, out: Path, *, seeds: int = 3) -> list[Path]:
    """For every configuration with exactly two unknowns: a panel per estimator, the first
    ``seeds`` seeds in colours, iterates joined by arrows, the truth filled, the start hollow,
    the best-by-image iterate starred."""
    plt = _plt()
    ok = df[(df["status"] == "ok") & df["iteration"].notna()]
    varying = _varying(df)
    paths = []
    for cfg, rows in _groups(ok, [*SETTINGS, "unknowns"]):
        keys = set(rows["keys"])
        if len(keys) != 1 or len(json.loads(next(iter(keys)))) != 2:
            continue
        kx, ky = json.loads(next(iter(keys)))
        every = sorted(rows["seed"].unique())
        chosen = every[:seeds]
        ests = _groups(rows, ["estimator"])
        fig, axes = plt.subplots(
            1, len(ests), figsize=(3.3 * len(ests), 4.2), squeeze=False, layout="constrained"
        )
        unknowns = _unknowns(str(cfg["scene"]), int(chosen[0]))
        colors = plt.get_cmap("tab10").colors
        for ax, (est, er) in zip(axes[0], ests, strict=True):
            for i, seed in enumerate(chosen):
                run = er[er["seed"] == seed].sort_values("iteration")
                if run.empty:
                    continue
                p = param_frame(run)
                t = json.loads(run["truth"].iloc[0])
                c = colors[i % len(colors)]
                xs, ys = p[kx].to_numpy(), p[ky].to_numpy()
                for j in range(len(xs) - 1):
                    ax.annotate(
                        "",
                        xy=(xs[j + 1], ys[j + 1]),
                        xytext=(xs[j], ys[j]),
                        arrowprops={"arrowstyle": "->", "color": c, "lw": 0.8, "alpha": 0.8},
                    )
                ax.plot(xs[0], ys[0], "o", mfc="none", mec=c, ms=5)
                b = int(run["best_iteration"].iloc[-1])
                ax.plot(xs[b], ys[b], "*", color=c, ms=8, mec="k", mew=0.4)
                ax.plot(t[kx], t[ky], "o", color=c, ms=8, mec="k", mew=0.6, label=f"seed {seed}")
            if kx in unknowns and ky in unknowns:
                ax.set_xlim(unknowns[kx].low, unknowns[kx].high)
                ax.set_ylim(unknowns[ky].low, unknowns[ky].high)
            ax.set_title(str(est["estimator"]), fontsize="medium")
            ax.set_xlabel(_param_label(kx, unknowns))
        axes[0, 0].set_ylabel(_param_label(ky, unknowns))
        _legend_below(fig, axes[0])
        drawn = (
            f"all {counted(len(every), 'seed')}"
            if len(chosen) == len(every)
            else f"the first {len(chosen)} of {len(every)} seeds (physbench plot --seeds N)"
        )
        fig.suptitle(
            f"{_title(cfg, varying)}, {unknowns_label(str(cfg['unknowns']))}\n"
            f"{drawn}; hollow: start, star: best by image MSE, filled: truth",
            fontsize="small",
        )
        paths.append(_save(fig, out / _name("trajectories", cfg, varying, str(cfg["unknowns"]))))
    return paths


def landscape_data(
    scene: str,
    param: str,
    *,
    engine: str = DEFAULT_SIMULATOR,
    renderer: str = DEFAULT_RENDERER,
    renderer_options: Mapping[str, Any] | None = None,
    resolution: int = 64,
    render_mode: str = "mark",
    seeds: Sequence[int] = (0, 1, 2),
    points: int = 21,
) -> dict[str, np.ndarray]:
    """Image MSE between the scene at nominal parameters and the scene with one unknown
    ``body.param`` moved across its range, per key: ``{"x": Δp grid (points,), key: (seeds,
    points)}``, Δp relative to the nominal value (the range's middle); frames from ``renderer``
    with ``renderer_options``."""
    from physbench.components import create, make_renderer
    from physbench.metrics import image_mse
    from physbench.scenes import resolve_scene

    sim = create("simulator", engine)
    ren = make_renderer(renderer, renderer_options or {}, resolution=resolution, mode=render_mode)
    out: dict[str, Any] = {}
    for si, seed in enumerate(seeds):
        sc = resolve_scene(scene, seed)
        units = [u for u in sc.unknowns if u.name == param]
        nominal = {u.key: 0.5 * (u.low + u.high) for u in sc.unknowns}
        obs = ren.render(sc, sim.simulate(sc, nominal))
        for u in units:
            half = 0.5 * (u.high - u.low)
            grid = np.linspace(-half, half, points)
            out.setdefault("x", grid)
            row = out.setdefault(u.key, np.full((len(seeds), points), np.nan))
            for j, d in enumerate(grid):
                try:
                    frames = ren.render(
                        sc, sim.simulate(sc, {**nominal, u.key: nominal[u.key] + d})
                    )
                    row[si, j] = image_mse(frames, obs)
                except Exception:  # an exploding simulation leaves a gap in the curve
                    pass
    return out


def landscape(df: pd.DataFrame, out: Path, *, seeds: int = 3, points: int = 21) -> list[Path]:
    """Per scene (and renderer, when the sweep has several): a panel per parameter among the
    sweep's unknowns, a line per body (mean over ``seeds`` scene instances, band: min to max),
    with the engine, renderer, resolution and render mode of the first such cell."""
    plt = _plt()
    df = upgrade(df)
    several = df["renderer"].nunique() > 1
    paths = []
    for cfg, rows in _groups(df, ["scene", "renderer"]):
        scene = str(cfg["scene"])
        first = rows.sort_values("cell_index").iloc[0]
        engine, res, mode = (
            str(first["engine"]),
            int(first["resolution"]),
            str(first["render_mode"]),
        )
        renderer, options = str(first["renderer_name"]), json.loads(first["renderer_options"])
        params = list(dict.fromkeys(p for u in rows["unknowns"] for p in u.split("+")))
        fig, axes = plt.subplots(
            1, len(params), figsize=(4 * len(params), 3.6), squeeze=False, layout="constrained"
        )
        unknowns = _unknowns(scene, 0)
        units = {u.name: u.unit for u in unknowns.values()}
        palette, order = plt.get_cmap("tab10").colors, {}  # a colour per body, kept across panels
        try:
            for ax, param in zip(axes[0], params, strict=True):
                data = landscape_data(
                    scene,
                    param,
                    engine=engine,
                    renderer=renderer,
                    renderer_options=options,
                    resolution=res,
                    render_mode=mode,
                    seeds=range(seeds),
                    points=points,
                )
                x = data.pop("x")
                for key, y in data.items():
                    # a line per body, labelled by body so one figure legend serves every panel
                    body = key.rsplit(".", 1)[0]
                    (line,) = ax.plot(
                        x,
                        np.nanmean(y, axis=0),
                        lw=1.3,
                        color=palette[order.setdefault(body, len(order)) % len(palette)],
                        label=f"body {body}",
                    )
                    if y.shape[0] > 1:
                        ax.fill_between(
                            x,
                            np.nanmin(y, axis=0),
                            np.nanmax(y, axis=0),
                            color=line.get_color(),
                            alpha=0.15,
                            lw=0,
                        )
                ax.axvline(0, color="0.5", ls="--", lw=0.8)
                ax.set_xlabel(with_unit(f"Δ{param} from nominal", units.get(param, "")))
                ax.set_title(param, fontsize="medium")
                ax.grid(True, alpha=0.25)
        except Exception:  # e.g. a scene file that moved since the sweep, a renderer now missing
            plt.close(fig)
            continue
        axes[0, 0].set_ylabel(f"image MSE vs nominal ({IMAGE_MSE_UNIT})")
        _legend_below(fig, axes[0])
        shown = f"{cfg['renderer']}, {res} px" if several else f"{res} px"
        fig.suptitle(
            f"{scene_label(scene)}: image-MSE landscape (engine {engine}, {shown}, no blur)\n"
            f"pixel values in [0, 1]; line: mean of {counted(seeds, 'scene instance')}, "
            "band: min to max",
            fontsize="medium",
        )
        name = f"landscape_{scene}" + (f"_renderer{cfg['renderer']}" if several else "")
        paths.append(_save(fig, out / f"{re.sub(r'[^A-Za-z0-9_.-]+', '-', name)}.png"))
    return paths


def win_rate(df: pd.DataFrame, out: Path) -> list[Path]:
    """Heatmap: row estimator's share of matched cells (same configuration and seed, both
    finished) that end with a lower normalized min MSE than the column estimator (ties: half)."""
    plt = _plt()
    wr, n = win_rate_table(final_rows(df))
    if wr.shape[0] < 2:
        return []
    fig, ax = plt.subplots(figsize=(1.1 * len(wr) + 2.6, 0.9 * len(wr) + 1.6), layout="constrained")
    im = ax.imshow(wr.to_numpy(dtype=float), cmap="RdBu", vmin=0, vmax=1)
    for i in range(len(wr)):
        for j in range(len(wr)):
            v = wr.iat[i, j]
            if np.isfinite(v):
                ax.text(
                    j,
                    i,
                    f"{100 * v:.0f}%\n(n={int(n.iat[i, j])})",
                    ha="center",
                    va="center",
                    fontsize="x-small",
                )
    ax.set_xticks(range(len(wr)), wr.columns, rotation=30, ha="right")
    ax.set_yticks(range(len(wr)), wr.index)
    ax.set_xlabel("opponent (column)")
    ax.set_ylabel("estimator (row)")
    ax.set_title("win rate: row beats column (normalized min MSE)", fontsize="medium")
    bar = fig.colorbar(im, ax=ax, fraction=0.046)
    bar.set_label("share won by the row (ties: half)", fontsize="small")
    return [_save(fig, out / "win_rate.png")]


def coverage(df: pd.DataFrame, out: Path) -> list[Path]:
    """One figure per scene (and setting) whose sweep has posteriors: observed against nominal
    coverage of the central intervals, a line per estimator and unknown set (pooled over seeds
    and unknowns) with Clopper-Pearson bars, and the diagonal a calibrated posterior follows.
    Nothing for a table without posteriors."""
    from physbench.posterior.scoring import CONFIDENCE, LEVELS
    from physbench.posterior.scoring import coverage as observed_coverage

    fin = final_rows(df)
    if not has_posteriors(fin):
        return []
    plt = _plt()
    varying = _varying(df)
    paths = []
    for cfg, rows in _groups(fin, SETTINGS):
        lines = [
            (f"{est['estimator']}, {unknowns_label(str(est['unknowns']))}", scores)
            for est, er in _groups(rows, ["estimator", "unknowns"])
            if (scores := calibration_scores(er))
        ]
        if not lines:
            continue
        fig, ax = plt.subplots(figsize=(5.2, 5.0), layout="constrained")
        ax.plot([0, 1], [0, 1], color="0.5", ls="--", lw=1, label="calibrated")
        for i, (label, scores) in enumerate(lines):
            cov = observed_coverage(scores)
            y = np.array([c.observed for c in cov])
            ci = np.array([c.ci() for c in cov])
            # a small horizontal offset per line keeps overlapping bars apart
            x = np.array(LEVELS) + 0.006 * (i - (len(lines) - 1) / 2)
            ax.errorbar(
                x,
                y,
                yerr=[y - ci[:, 0], ci[:, 1] - y],
                marker="o",
                ms=3.5,
                lw=1.2,
                capsize=2.5,
                label=f"{label} (n={len(scores)})",
            )
        ax.set_xlim(0.4, 1.0)
        ax.set_ylim(0.0, 1.02)
        ax.set_xlabel(f"nominal coverage of the central interval ({DIMENSIONLESS})")
        ax.set_ylabel(f"observed coverage ({DIMENSIONLESS})")
        ax.grid(True, alpha=0.25)
        _legend_below(fig, [ax])
        fig.suptitle(
            f"{_title(cfg, varying)}\nshare of truths inside the posteriors' central intervals\n"
            f"bars: {100 * CONFIDENCE:.0f} % Clopper-Pearson, n = seeds × unknowns",
            fontsize="small",
        )
        paths.append(_save(fig, out / _name("coverage", cfg, varying)))
    return paths


def _share_reached(
    ax: Any, costs: np.ndarray, n: int, *, start: float, end: float, **style: Any
) -> None:
    """A step line from ``start`` to ``end``: the share of ``n`` seeds whose cost (+inf: never)
    is at most x."""
    x = np.sort(costs[np.isfinite(costs)])
    y = np.arange(1, x.size + 1) / n
    ax.step(np.r_[start, x, end], np.r_[0.0, y, y[-1] if y.size else 0.0], where="post", **style)


def time_to_accuracy(df: pd.DataFrame, out: Path, *, threshold: float | None = None) -> list[Path]:
    """One figure per scene (and setting) with a threshold for some unknown set: a column per
    unknown set, the share of seeds that reached the threshold (``threshold`` when given, else
    the paper's value for the row) against simulations (top) and against wall-clock seconds
    (bottom, log), a line per estimator. Without ``threshold``, rows without a paper value
    are left out (:func:`physbench.bench.time_to_accuracy.per_seed`); the seconds panel is empty
    for a sweep that recorded no timings."""
    from matplotlib.ticker import NullFormatter

    from physbench.bench.time_to_accuracy import REFERENCE, per_seed

    seeds = per_seed(df, threshold=threshold)
    if seeds.empty:
        return []
    plt = _plt()
    varying = _varying(df)
    # one colour per estimator in every panel, also where one never reached the threshold
    colours = {e: f"C{i}" for i, e in enumerate(dict.fromkeys(seeds["estimator"]))}
    paths = []
    for cfg, rows in _groups(seeds, SETTINGS):
        sets = list(dict.fromkeys(rows.sort_values("cell_index")["unknowns"]))
        fig, axes = plt.subplots(
            2, len(sets), figsize=(4.2 * len(sets), 6.4), squeeze=False, layout="constrained"
        )
        for col, unknowns in enumerate(sets):
            top, bottom = axes[0, col], axes[1, col]
            sub = rows[rows["unknowns"] == unknowns]
            budget = int(sub["iterations"].max())
            timed = sub["seconds"].to_numpy(dtype=float)
            timed = timed[np.isfinite(timed)]
            for est, er in _groups(sub, ["estimator"]):
                label = str(est["estimator"])
                style = {"color": colours[label], "lw": 1.3, "label": label}
                sims = er["simulations"].to_numpy(dtype=float)
                _share_reached(top, sims, len(er), start=0, end=budget, **style)
                secs = er["seconds"].to_numpy(dtype=float)
                if timed.size and not np.isnan(secs).any():
                    lo, hi = 0.8 * float(timed.min()), 1.25 * float(timed.max())
                    _share_reached(bottom, secs, len(er), start=lo, end=hi, **style)
            top.set_xlim(0, budget + 0.5)
            top.xaxis.get_major_locator().set_params(integer=True)
            top.set_title(
                f"{unknowns_label(unknowns)}: threshold {float(sub['threshold'].iloc[0]):.2g}",
                fontsize="medium",
            )
            top.set_xlabel("simulations (1: the initial guess)")
            bottom.set_xlabel("wall-clock time (s)")
            if bottom.lines:
                bottom.set_xscale("log")
                bottom.xaxis.set_minor_formatter(NullFormatter())
            for ax in (top, bottom):
                ax.set_ylim(0, 1.02)
                ax.grid(True, which="both", alpha=0.25)
        for ax in axes[:, 0]:
            ax.set_ylabel(f"share reached ({DIMENSIONLESS})")
        _legend_below(fig, axes.ravel())
        target = (
            f"the paper's {REFERENCE} value (11 it.)" if threshold is None else f"{threshold:.2g}"
        )
        fig.suptitle(
            f"{_title(cfg, varying)}\nshare of seeds whose best-so-far normalized MSE is at or "
            f"below {target}",
            fontsize="medium",
        )
        paths.append(_save(fig, out / _name("time_to_accuracy", cfg, varying)))
    return paths


#: the groups of figures :func:`plot_all` draws, in order (the keys of what it returns)
FIGURE_GROUPS = (
    "convergence",
    "trajectories",
    "win rate",
    "time to accuracy",
    "coverage",
    "landscape",
)


def plot_all(
    df: pd.DataFrame,
    out: Path,
    *,
    seeds: int = 3,
    landscape_seeds: int = 3,
    stage: Callable[[str], None] | None = None,
    threshold: float | None = None,
) -> dict[str, list[Path]]:
    """Every figure into ``out`` (created); ``landscape_seeds=0`` skips the simulating one;
    ``threshold`` is the time to accuracy's (default: the paper's value per row).
    ``stage`` is called with each name of :data:`FIGURE_GROUPS` as that group begins (a progress
    display)."""
    out.mkdir(parents=True, exist_ok=True)
    df = upgrade(df)
    stage = stage or (lambda name: None)
    figs: dict[str, list[Path]] = {}
    stage("convergence")
    figs["convergence"] = convergence(df, out)
    stage("trajectories")
    figs["trajectories"] = trajectories(df, out, seeds=seeds)
    stage("win rate")
    figs["win rate"] = win_rate(df, out)
    stage("time to accuracy")
    figs["time to accuracy"] = time_to_accuracy(df, out, threshold=threshold)
    stage("coverage")
    figs["coverage"] = coverage(df, out)
    stage("landscape")
    figs["landscape"] = landscape(df, out, seeds=landscape_seeds) if landscape_seeds else []
    return figs

"""The sweep's tables: the long per-iteration table, per-configuration statistics, and the summary
in the paper's Table 1 layout (CSV, Markdown, LaTeX).

Long table: one row per cell × iteration (a failed cell has one row with ``iteration`` missing and
its ``error``). Parameters and truths are JSON objects in the ``params`` / ``truth`` columns
(``{"a.mass": 4.2, "b.mass": 6.1}``): the unknown set changes from cell to cell (2 to 6 masses in
``bouncing_balls``), so one column per parameter would make the schema depend on the spec and
fill most of it with nulls; a JSON column keeps one fixed schema for every sweep, round-trips floats
exactly, and :func:`param_frame` spreads it into columns when needed. Columns starting with ``t_``
are wall-clock timings; everything else is identical between runs of the same spec.

A sweep where some estimator returned a posterior also has a ``calibration`` column
(:data:`OPTIONAL`): per unknown, the :mod:`physbench.posterior.scoring` scores of the cell's
posterior against its truth (a JSON object like ``params``), null for cells without one. A sweep
without posteriors lacks the column, so its tables are those written before calibration existed.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from physbench.metrics import format_mean_std
from physbench.render.base import DEFAULT_RENDERER

if TYPE_CHECKING:
    import pandas as pd

    from physbench.posterior.scoring import Score

#: Column -> pandas dtype of the long table.
SCHEMA: dict[str, str] = {
    "cell": "string",
    "cell_index": "int64",
    "scene": "string",
    "unknowns": "string",
    "bodies": "string",
    "keys": "string",
    "estimator": "string",
    "estimator_name": "string",
    "options": "string",
    "engine": "string",
    "observe_engine": "string",
    "renderer": "string",
    "renderer_name": "string",
    "renderer_options": "string",
    "observer": "string",
    "observer_options": "string",
    "blur": "float64",
    "noise": "float64",
    "resolution": "int64",
    "render_mode": "string",
    "iterations": "int64",
    "seed": "int64",
    "status": "string",
    "error": "string",
    "iteration": "Int64",
    "params": "string",
    "truth": "string",
    "image_mse": "float64",
    "nmse": "float64",
    "best_iteration": "Int64",
    "best_image_mse": "float64",
    "best_nmse": "float64",
    "sim_error": "string",
    "t_simulate": "float64",
    "t_render": "float64",
    "t_estimator": "float64",
    "t_start": "float64",
    "t_cell": "float64",
    "versions": "string",
}
#: Columns a table has only when some cell fills them (see the module docstring).
OPTIONAL: dict[str, str] = {"calibration": "string"}
#: Columns that vary between identical runs.
TIMINGS = tuple(c for c in SCHEMA if c.startswith("t_"))
#: What identifies a configuration (a cell without its seed), in display order.
CONFIG = (
    "scene",
    "unknowns",
    "bodies",
    "engine",
    "observe_engine",
    "renderer",
    "renderer_options",
    "observer",
    "observer_options",
    "blur",
    "noise",
    "resolution",
    "render_mode",
    "iterations",
    "estimator",
)
#: What identifies a cell across two sweeps (``compare`` matches on these).
MATCH = (*CONFIG, "options", "seed")
ALL_BODIES = "all"
#: Columns that tables written before they existed lack, and the value such a table implies.
ADDED: dict[str, str] = {
    "renderer": DEFAULT_RENDERER,
    "renderer_name": DEFAULT_RENDERER,
    "renderer_options": "{}",
    "observer": "sharp",
    "observer_options": "{}",
}
#: Configuration columns shown only when they vary within a sweep.
SETTINGS = (
    "bodies",
    "engine",
    "observe_engine",
    "renderer",
    "observer",
    "blur",
    "noise",
    "resolution",
    "render_mode",
    "iterations",
)

#: Link, Schwarz, Behnke (2022), Table 1: normalized min MSE after 11 iterations, mean ± std over
#: 10 runs. "NN" is the paper's learned estimator, "Hyperopt" its TPE baseline.
PAPER: dict[tuple[str, frozenset[str]], dict[str, tuple[float, float]]] = {
    ("three_circles", frozenset({"mass"})): {"NN": (2.6e-3, 0.9e-3), "Hyperopt": (1.1e-2, 0.3e-2)},
    ("three_circles", frozenset({"elasticity"})): {"NN": (8.7e-5, 1.9e-5)},
    ("three_circles", frozenset({"mass", "elasticity"})): {
        "NN": (1.4e-2, 0.5e-2),
        "Hyperopt": (5.2e-2, 0.7e-2),
    },
    ("second_order", frozenset({"mass"})): {"NN": (3e-4, 0.7e-4)},
    ("second_order", frozenset({"elasticity"})): {"NN": (4e-3, 2e-3)},
    ("stacked_boxes", frozenset({"mass"})): {"NN": (2e-3, 0.5e-3)},
    ("stacked_boxes", frozenset({"friction"})): {"NN": (3.9e-3, 1.2e-3)},
    ("bouncing_balls", frozenset({"mass"})): {"NN": (6.3e-3, 0.8e-3)},
}
PAPER_SCENES = {
    "three_circles": "3 circles",
    "second_order": "second order",
    "stacked_boxes": "box scene",
    "bouncing_balls": "bouncing balls",
}
BOOTSTRAP = 4000
#: What the calibration table shows (summary.md and report.html).
CALIBRATION_NOTE = (
    "Posteriors against the truths, pooled over seeds and unknowns (scored: how many): share of "
    "truths inside the central 50/80/90/95 % intervals (calibrated: the nominal share), "
    "Kolmogorov-Smirnov p-value of uniform SBC ranks (small: miscalibrated), mean 90 % interval "
    "width over the range, mean negative log density of the truth in unit-range units (0: the "
    "uniform prior; lower is better)."
)


def dumps(obj: Any) -> str:
    """Canonical JSON for table cells (sorted keys where order carries no meaning)."""
    return json.dumps(obj, sort_keys=True, separators=(",", ":"))


def cell_rows(cell: Mapping[str, Any], data: Mapping[str, Any]) -> list[dict[str, Any]]:
    """Long-table rows of one cell: ``cell`` holds its identity in the spec (key, index, scene,
    estimator ``label``, ``renderer_label``, ``observer_label``); ``data`` is the stored cell
    (:func:`physbench.bench.runner.run_cell`)."""
    from physbench.experiment import RunConfig

    # "case": cells written before the key was renamed; from_dict fills settings added since.
    case = RunConfig.from_dict(data["config"] if "config" in data else data["case"]).to_dict()
    base = {
        "cell": cell["key"],
        "cell_index": cell["index"],
        "scene": cell["scene"],
        "unknowns": "+".join(case["params"]),
        "bodies": ALL_BODIES if case.get("bodies") is None else ",".join(case["bodies"]),
        "estimator": cell["label"],
        "estimator_name": case["estimator"],
        "options": dumps(case["options"]),
        "engine": case["engine"],
        "observe_engine": case["observe_engine"] or case["engine"],
        "renderer": cell["renderer_label"],
        "renderer_name": case["renderer"],
        "renderer_options": dumps(case["renderer_options"]),
        "observer": cell.get("observer_label", "sharp"),
        "observer_options": dumps(case.get("observer_options", {})),
        "blur": case["blur"],
        "noise": case["noise"],
        "resolution": case["resolution"],
        "render_mode": case["render_mode"],
        "iterations": case["iterations"],
        "seed": case["seed"],
        "status": data["status"],
        "error": data.get("error"),
        "t_cell": data.get("t_cell"),
        "versions": dumps(data.get("versions", {})),
    }
    hist = data.get("history")
    if data["status"] != "ok" or not hist:
        return [{**base, "keys": None}]
    keys = list(hist["keys"])
    base.update(
        keys=json.dumps(keys),
        truth=None if hist["truth"] is None else json.dumps(hist["truth"]),
        t_start=hist["meta"].get("t_start"),
    )
    if hist.get("posterior") is not None and hist["truth"] is not None:
        base["calibration"] = _calibration(hist["posterior"], hist["truth"])
    return [
        {
            **base,
            "iteration": r["iteration"],
            "params": json.dumps({k: r["params"][k] for k in keys}),
            "image_mse": r["loss"],
            "nmse": r["nmse"],
            "best_iteration": r["best_iteration"],
            "best_image_mse": r["best_loss"],
            "best_nmse": r["best_nmse"],
            "sim_error": r.get("failed"),
            "t_simulate": r.get("t_simulate"),
            "t_render": r.get("t_render"),
            "t_estimator": r.get("t_estimator"),
        }
        for r in hist.get("iterations", hist.get("records", ()))  # "records": written before 0.2
    ]


def _calibration(posterior: Mapping[str, Any], truth: Mapping[str, float]) -> str:
    """The ``calibration`` cell: the scores of a stored posterior against the truth."""
    from physbench.posterior.samples import Posterior
    from physbench.posterior.scoring import score

    scores = score(Posterior.from_dict(posterior), truth)
    return dumps({k: s.to_dict() for k, s in scores.items()})


def to_frame(rows: Iterable[Mapping[str, Any]]) -> pd.DataFrame:
    """The long table with the fixed :data:`SCHEMA` (columns and dtypes), whatever the rows hold,
    and the columns of :data:`OPTIONAL` that some row fills."""
    import pandas as pd

    rows = list(rows)
    schema = {**SCHEMA, **{c: t for c, t in OPTIONAL.items() if any(r.get(c) for r in rows)}}
    df = pd.DataFrame(rows, columns=list(schema))
    for col, dtype in schema.items():
        if dtype == "string":
            df[col] = df[col].astype("object").where(df[col].notna(), None).astype("string")
        else:
            df[col] = pd.to_numeric(df[col]).astype(dtype)
    return df.reset_index(drop=True)


def upgrade(df: pd.DataFrame) -> pd.DataFrame:
    """``df`` with the columns of :data:`ADDED` that it lacks (a table written before they
    existed), filled with what such a table implies, in :data:`SCHEMA` order; a table that has
    them is returned as it is."""
    missing = [c for c in ADDED if c not in df.columns]
    if not missing:
        return df
    df = df.copy()
    for c in missing:
        df[c] = ADDED[c]
        df[c] = df[c].astype("string")
    known = [c for c in SCHEMA if c in df.columns]
    return df[[*known, *(c for c in df.columns if c not in SCHEMA)]]


def without_timings(df: pd.DataFrame) -> pd.DataFrame:
    """``df`` minus the wall-clock columns: what must agree between executors, workers and
    resumes."""
    return df.drop(columns=[c for c in TIMINGS if c in df.columns])


def param_frame(df: pd.DataFrame, column: str = "params") -> pd.DataFrame:
    """The JSON ``params`` (or ``truth``) column spread into one float column per parameter key."""
    import pandas as pd

    recs = [json.loads(v) if isinstance(v, str) else {} for v in df[column]]
    return pd.DataFrame(recs, index=df.index, dtype=float)


def final_rows(df: pd.DataFrame) -> pd.DataFrame:
    """One row per cell: the last iteration of a finished cell, the single row of a failed one."""
    last = df["iteration"].isna() | (df["iteration"] == df["iterations"] - 1)
    return df[last.fillna(False).astype(bool)]


def unknowns_label(unknowns: str) -> str:
    """``"mass+elasticity"`` -> ``"Mass + Elasticity"`` (the paper's column heads)."""
    return " + ".join(p.capitalize() for p in unknowns.split("+"))


def scene_label(scene: str) -> str:
    return PAPER_SCENES.get(scene, scene)


def paper_value(scene: str, unknowns: str, which: str) -> tuple[float, float] | None:
    """The paper's (mean, std) for ``which`` in {"NN", "Hyperopt"}, if the paper has that cell."""
    return PAPER.get((scene, frozenset(unknowns.split("+"))), {}).get(which)


def _bca(
    data: tuple[np.ndarray, ...], statistic: Any, *, level: float, n: int, seed: int
) -> tuple[float, float]:
    """BCa interval of ``statistic`` over the seeds (resampled together when ``data`` holds more
    than one sample). BCa needs a spread of resampled statistics: where they are all equal (equal
    values, or a ratio that pairing makes constant) it is undefined, and the percentile interval
    of the same resamples, that one value, is returned instead."""
    import warnings

    from scipy.stats import DegenerateDataWarning, bootstrap

    with warnings.catch_warnings(), np.errstate(divide="ignore", invalid="ignore"):
        warnings.simplefilter("ignore", DegenerateDataWarning)
        res = bootstrap(
            data,
            statistic,
            n_resamples=n,
            paired=len(data) > 1,
            vectorized=True,
            confidence_level=level,
            method="BCa",
            rng=np.random.default_rng(seed),
        )
    lo, hi = res.confidence_interval
    if not (np.isfinite(lo) and np.isfinite(hi)):
        a = (1 - level) / 2
        lo, hi = np.quantile(res.bootstrap_distribution, [a, 1 - a])
    return float(lo), float(hi)


def _mean(x: np.ndarray, axis: int = -1) -> np.ndarray:
    return x.mean(axis=axis)


def _ratio_of_means(x: np.ndarray, y: np.ndarray, axis: int = -1) -> np.ndarray:
    return x.mean(axis=axis) / y.mean(axis=axis)


def bootstrap_ci(
    values: Sequence[float], *, level: float = 0.95, n: int = BOOTSTRAP, seed: int = 0
) -> tuple[float, float]:
    """BCa bootstrap interval of the mean, resampling seeds with a fixed generator (the same
    values always give the same interval). BCa rather than percentile: errors here are
    heavy-tailed (std ≈ mean) and the mean's resampling distribution is skewed. No values give
    NaNs; one value, or values all equal, give that value at both ends."""
    v = np.asarray(values, dtype=float)
    if v.size == 0:
        return math.nan, math.nan
    if v.size == 1:
        return float(v[0]), float(v[0])
    return _bca((v,), _mean, level=level, n=n, seed=seed)


def ratio_ci(
    num: Sequence[float],
    den: Sequence[float],
    *,
    level: float = 0.9,
    n: int = BOOTSTRAP,
    seed: int = 0,
) -> tuple[float, float, float]:
    """``mean(num) / mean(den)`` of paired values (the same seeds) and its BCa bootstrap
    interval, resampling the pairs together so shared per-seed difficulty cancels. A single pair,
    or pairs whose resampled ratio never varies (``num`` proportional to ``den``), give the ratio
    at both ends."""
    a, b = np.asarray(num, dtype=float), np.asarray(den, dtype=float)
    point = float(a.mean() / b.mean())
    if a.size == 1:
        return point, point, point
    return (point, *_bca((a, b), _ratio_of_means, level=level, n=n, seed=seed))


def _ordered_groups(df: pd.DataFrame, cols: Sequence[str]) -> list[tuple[Any, ...]]:
    """Distinct values of ``cols`` in the order they first appear in the spec (cell index)."""
    first = df.sort_values("cell_index").drop_duplicates(list(cols))
    return [tuple(r) for r in first[list(cols)].itertuples(index=False)]


def calibration_scores(rows: pd.DataFrame) -> list[Score]:
    """The posterior scores in the ``calibration`` column of finished ``rows``, one per cell and
    unknown (none for a table without the column)."""
    from physbench.posterior.scoring import Score

    if "calibration" not in rows.columns:
        return []
    ok = rows[(rows["status"] == "ok") & rows["calibration"].notna()]
    return [Score.from_dict(d) for v in ok["calibration"] for d in json.loads(v).values()]


def has_posteriors(df: pd.DataFrame) -> bool:
    """Whether any cell of the long table ``df`` has a posterior (and so a calibration)."""
    return "calibration" in df.columns and bool(df["calibration"].notna().any())


def stats(df: pd.DataFrame) -> pd.DataFrame:
    """Per configuration (:data:`CONFIG`): cells, failures, and mean, sample std, median and 95 %
    bootstrap interval (of the mean) of the normalized min MSE after the configuration's
    iterations, plus the initial guess's mean error and the paper's values where it has the cell.
    When some cell has a posterior, also the calibration of the configuration's posteriors
    (:func:`physbench.posterior.scoring.summarize`: ``coverage50`` ... ``coverage95``, ``sbc_p``,
    ``width90``, ``nld``, ``scored``; NaN and 0 scored for a configuration without
    posteriors)."""
    import pandas as pd

    from physbench.posterior.scoring import summarize

    df = upgrade(df)
    fin = final_rows(df)
    init = df[df["iteration"] == 0]
    calibrated = has_posteriors(fin)
    rows = []
    for key in _ordered_groups(fin, CONFIG):
        cfg = dict(zip(CONFIG, key, strict=True))
        sel = np.logical_and.reduce([fin[c] == v for c, v in cfg.items()])
        g = fin[sel]
        ok = g[g["status"] == "ok"]
        v = ok["best_nmse"].to_numpy(dtype=float)
        v = v[np.isfinite(v)]
        isel = np.logical_and.reduce([init[c] == v_ for c, v_ in cfg.items()])
        errors = sorted(set(g.loc[g["status"] != "ok", "error"].dropna()))
        lo, hi = bootstrap_ci(v)
        nn, hy = (paper_value(cfg["scene"], cfg["unknowns"], w) for w in ("NN", "Hyperopt"))
        rows.append(
            {
                **cfg,
                "n": int(v.size),
                "failed": int((g["status"] != "ok").sum()),
                "mean": float(v.mean()) if v.size else math.nan,
                "std": float(v.std(ddof=1)) if v.size > 1 else (0.0 if v.size else math.nan),
                "median": float(np.median(v)) if v.size else math.nan,
                "ci_low": lo,
                "ci_high": hi,
                "initial_mean": float(init.loc[isel, "nmse"].mean()) if isel.any() else math.nan,
                "paper_nn": format_mean_std(*nn) if nn else "",
                "paper_hyperopt": format_mean_std(*hy) if hy else "",
                "error": errors[0] if errors else "",
            }
        )
        if calibrated:
            rows[-1].update(summarize(calibration_scores(g)))
    return pd.DataFrame(rows)


def _varying(st: pd.DataFrame, cols: Sequence[str]) -> list[str]:
    return [c for c in cols if st[c].nunique(dropna=False) > 1]


def _cell_text(row: Mapping[str, Any]) -> str:
    if row["n"] == 0:
        return f"failed ({row['failed']})"
    text = format_mean_std(row["mean"], row["std"])
    return text + (f" [{row['failed']} failed]" if row["failed"] else "")


def paper_layout(st: pd.DataFrame) -> pd.DataFrame:
    """Table 1's layout: a row per scene (plus any varying setting) and estimator, a column per
    unknown set, cells "(mean ± std)e-XX"; the paper's own rows ("paper NN", "paper Hyperopt")
    precede each scene's rows."""
    import pandas as pd

    extra = _varying(st, SETTINGS)
    sets = list(dict.fromkeys(st["unknowns"]))
    sets.sort(key=lambda u: len(u.split("+")))  # single parameters first, as in the paper
    heads = [unknowns_label(u) for u in sets]
    rows: list[dict[str, Any]] = []
    for scene in dict.fromkeys(st["scene"]):
        sst = st[st["scene"] == scene]
        for which in ("NN", "Hyperopt"):
            vals = {h: paper_value(scene, u, which) for u, h in zip(sets, heads, strict=True)}
            if any(
                v is not None
                for u, v in zip(sets, vals.values(), strict=True)
                if u in set(sst["unknowns"])
            ):
                rows.append(
                    {
                        "scene": scene_label(scene),
                        **dict.fromkeys(extra, ""),
                        "estimator": f"paper {which}",
                        **{h: format_mean_std(*v) if v else "-" for h, v in vals.items()},
                    }
                )
        for key in dict.fromkeys(
            tuple(r) for r in sst[[*extra, "estimator"]].itertuples(index=False)
        ):
            sel = np.logical_and.reduce(
                [sst[c] == v for c, v in zip([*extra, "estimator"], key, strict=True)]
            )
            by_set = {r["unknowns"]: r for r in sst[sel].to_dict("records")}
            rows.append(
                {
                    "scene": scene_label(scene),
                    **dict(zip([*extra, "estimator"], key, strict=True)),
                    **{
                        h: _cell_text(by_set[u]) if u in by_set else "-"
                        for u, h in zip(sets, heads, strict=True)
                    },
                }
            )
    return pd.DataFrame(rows, columns=["scene", *extra, "estimator", *heads])


def side_by_side(st: pd.DataFrame) -> pd.DataFrame:
    """A row per scene × unknown set (× varying setting), the paper's NN and Hyperopt values next
    to every estimator's mean ± std: the easiest view for comparing with the paper."""
    import pandas as pd

    extra = _varying(st, SETTINGS)
    ests = list(dict.fromkeys(st["estimator"]))
    rows = []
    for key in dict.fromkeys(
        tuple(r) for r in st[["scene", "unknowns", *extra]].itertuples(index=False)
    ):
        sel = np.logical_and.reduce(
            [st[c] == v for c, v in zip(["scene", "unknowns", *extra], key, strict=True)]
        )
        g = st[sel]
        first = g.iloc[0]
        row = {
            "scene": scene_label(str(key[0])),
            "unknowns": unknowns_label(str(key[1])),
            **dict(zip(extra, key[2:], strict=True)),
            "paper NN": first["paper_nn"] or "-",
            "paper Hyperopt": first["paper_hyperopt"] or "-",
        }
        by_est = {r["estimator"]: r for r in g.to_dict("records")}
        row.update({e: _cell_text(by_est[e]) if e in by_est else "-" for e in ests})
        rows.append(row)
    return pd.DataFrame(rows)


def detail(st: pd.DataFrame) -> pd.DataFrame:
    """Per configuration, formatted: mean ± std, median, 95 % bootstrap interval, cells, failures,
    the initial guess's error and the paper's values."""
    import pandas as pd

    extra = _varying(st, SETTINGS)
    rows = []
    for r in st.to_dict("records"):
        rows.append(
            {
                "scene": r["scene"],
                "unknowns": r["unknowns"],
                **{c: r[c] for c in extra},
                "estimator": r["estimator"],
                "n": r["n"],
                "failed": r["failed"],
                "mean ± std": format_mean_std(r["mean"], r["std"]) if r["n"] else "-",
                "median": f"{r['median']:.2e}" if r["n"] else "-",
                "95% CI of mean": f"[{r['ci_low']:.2e}, {r['ci_high']:.2e}]" if r["n"] else "-",
                "initial guess": f"{r['initial_mean']:.2e}"
                if math.isfinite(r["initial_mean"])
                else "-",
                "paper NN": r["paper_nn"] or "-",
                "paper Hyperopt": r["paper_hyperopt"] or "-",
            }
        )
    return pd.DataFrame(rows)


def calibration(st: pd.DataFrame) -> pd.DataFrame:
    """Per configuration with posteriors, formatted: observed coverage of each central interval,
    the SBC p-value, mean 90 % width over the range and the truth's mean negative log density.
    Empty when no configuration has posteriors."""
    import pandas as pd

    from physbench.posterior.scoring import LEVELS

    if "scored" not in st.columns:
        return pd.DataFrame()
    extra = _varying(st, SETTINGS)
    rows = []
    for r in st[st["scored"] > 0].to_dict("records"):
        rows.append(
            {
                "scene": r["scene"],
                "unknowns": r["unknowns"],
                **{c: r[c] for c in extra},
                "estimator": r["estimator"],
                "scored": int(r["scored"]),
                **{
                    f"{round(100 * lv)} %": f"{100 * r[f'coverage{round(100 * lv)}']:.0f}%"
                    for lv in LEVELS
                },
                "SBC p": f"{r['sbc_p']:.2g}",
                "90 % width": f"{r['width90']:.3f}",
                "NLD": f"{r['nld']:.2f}",
            }
        )
    return pd.DataFrame(rows)


def win_rate_table(fin: pd.DataFrame) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(rate, n): for each ordered estimator pair, the share of matched finished cells (same
    configuration and seed) where the row estimator's normalized min MSE is lower than the
    column's (ties count half), and the number of matched cells."""
    import pandas as pd

    fin = upgrade(fin)
    ok = fin[fin["status"] == "ok"]
    ests = list(dict.fromkeys(ok.sort_values("cell_index")["estimator"]))
    idx = [c for c in MATCH if c not in ("estimator", "options")]
    wide = ok.pivot_table(
        index=idx, columns="estimator", values="best_nmse", aggfunc="first", observed=True
    )
    rate = pd.DataFrame(np.nan, index=ests, columns=ests)
    n = pd.DataFrame(0, index=ests, columns=ests)
    for a in ests:
        for b in ests:
            if a == b:
                continue
            both = wide[[a, b]].dropna()
            if len(both):
                wins = (both[a] < both[b]).sum() + 0.5 * (both[a] == both[b]).sum()
                rate.loc[a, b], n.loc[a, b] = wins / len(both), len(both)
    return rate, n


def markdown(df: pd.DataFrame) -> str:
    """A GitHub Markdown table (no extra dependency)."""
    cols = [str(c) for c in df.columns]
    body = [[str(v) for v in row] for row in df.itertuples(index=False)]
    lines = ["| " + " | ".join(cols) + " |", "|" + "|".join("---" for _ in cols) + "|"]
    lines += ["| " + " | ".join(c.replace("|", "\\|") for c in row) + " |" for row in body]
    return "\n".join(lines) + "\n"


def _latex_cell(text: str) -> str:
    # As the paper prints it:
    # "(2.6 ± 0.9)e-03 [1 failed]" -> "$(2.6 \pm 0.9) \times 10^{-3}$ [1 failed]"
    head, sep, tail = text.partition(")e")
    if sep and head.startswith("("):
        exp, _, rest = tail.partition(" ")
        mant = head[1:].replace("±", r"\pm")
        return f"$({mant}) \\times 10^{{{int(exp)}}}$" + (" " + _latex_escape(rest) if rest else "")
    return _latex_escape(text.replace("±", "+/-"))


def _latex_escape(text: str) -> str:
    for a, b in (
        ("\\", r"\textbackslash{}"),
        ("&", r"\&"),
        ("%", r"\%"),
        ("_", r"\_"),
        ("#", r"\#"),
    ):
        text = text.replace(a, b)
    return text


def latex(df: pd.DataFrame, *, caption: str) -> str:
    """A booktabs ``table*`` like the paper's Table 1 (needs ``\\usepackage{booktabs}``)."""
    ncol = len(df.columns)
    lines = [
        r"\begin{table*}",
        r"\centering",
        f"\\caption{{{_latex_escape(caption)}}}",
        r"\begin{tabular}{" + "l" * (ncol - _n_value_cols(df)) + "r" * _n_value_cols(df) + "}",
        r"\toprule",
        " & ".join(_latex_escape(str(c)) for c in df.columns) + r" \\",
        r"\midrule",
    ]
    for row in df.itertuples(index=False):
        lines.append(" & ".join(_latex_cell(str(v)) for v in row) + r" \\")
    lines += [r"\bottomrule", r"\end{tabular}", r"\end{table*}"]
    return "\n".join(lines) + "\n"


def _n_value_cols(df: pd.DataFrame) -> int:
    return len(df.columns) - 1 - list(df.columns).index("estimator")


def read_results(path: str | Path) -> pd.DataFrame:
    """A finished sweep's long table from its folder or its ``results.parquet``, with the columns
    :func:`upgrade` adds; called by the commands that read a sweep (``plot``, ``compare``). A file
    that is not Parquet, or lacks a column of :data:`SCHEMA`, is a :class:`PhysbenchError` that
    names it."""
    import pandas as pd

    from physbench.bench.store import RESULTS
    from physbench.errors import PhysbenchError

    p = Path(path)
    f = p / RESULTS if p.is_dir() else p
    if not f.is_file():
        raise PhysbenchError(
            f"{str(p)!r}: no {RESULTS} there; expected the --out folder of a finished "
            "`physbench bench` run"
        )
    try:
        df = pd.read_parquet(f)
    except Exception as exc:  # pyarrow raises several types for a file that is not Parquet
        raise PhysbenchError(
            f"{str(f)!r}: not a Parquet table ({type(exc).__name__}: {exc}); expected the "
            f"{RESULTS} that `physbench bench` writes"
        ) from None
    missing = [c for c in SCHEMA if c not in ADDED and c not in df.columns]
    if missing:
        raise PhysbenchError(
            f"{str(f)!r}: not a sweep's results table: no column {', '.join(missing[:5])}"
            f"{', ...' if len(missing) > 5 else ''} ({len(missing)} of {len(SCHEMA)} missing); "
            f"expected the {RESULTS} that `physbench bench` writes"
        )
    return upgrade(df)

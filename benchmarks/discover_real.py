"""Discovery on the real data sets: writes the committed results under results/discover/.

    python benchmarks/discover_real.py                    # all but hidden_table (~15 min)
    python benchmarks/discover_real.py ball_drops         # 11 balls, 2 drops each (~1.5 min)
    python benchmarks/discover_real.py ball_drops_check   # the drag law by direct scipy fits
    python benchmarks/discover_real.py billiards          # 6 rolling segments of shots 0, 3, 4
    python benchmarks/discover_real.py billiards_slow     # the same below 0.8 m/s
    python benchmarks/discover_real.py billiards_cushions # cushion bounces measured directly
    python benchmarks/discover_real.py pendulum_kaheman   # single pendulum, 4 windows of 3 s
    python benchmarks/discover_real.py pendulum_benard    # 3 free swings
    python benchmarks/discover_real.py pendulum_peaks     # both pendulums' loss laws from peaks
    python benchmarks/discover_real.py hidden_table       # tabulate hidden_effects.jsonl
    python benchmarks/discover_real.py billiards --out out/discover    # elsewhere

Each discovery writes ``<dataset>/verdict.json`` (the ``--json`` layout), ``verdict.txt`` and a
``report/`` folder (PNGs + index.html); ball drops writes one folder per ball and a summary table.
The checks (``ball_drops_check``, ``billiards_cushions``, ``pendulum_peaks``) use no simulation:
they fit the measurements directly (``physbench.datasets``), as an independent check of the
verdicts. Runs are deterministic. Summarised in docs/discover.md; ``tests/results/test_discover.py``
checks the committed claims.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, replace
from pathlib import Path
from typing import Any

import numpy as np

from physbench.components import create
from physbench.datasets import DatasetRun, load
from physbench.datasets.ball_drops import BALLS, check_drag_laws
from physbench.datasets.billiards import cushion_bounces, rolling_segments, straight_stretches
from physbench.datasets.oscillation import LOSS_LAWS, fit_loss_laws, half_swing_amplitudes
from physbench.datasets.pendulum_benard import first_extreme
from physbench.datasets.pendulum_benard import read as read_benard
from physbench.datasets.pendulum_kaheman import read as read_kaheman
from physbench.discover import Discovery, Settings, discover, runs_from_dataset
from physbench.discover.report import write_report
from physbench.discover.verdict import text, to_dict
from physbench.errors import PhysbenchError
from physbench.scene import body_unknown

DEFAULT_OUT = Path(__file__).resolve().parents[1] / "results" / "discover"
#: The balls whose discovery also gets a report folder.
REPORTED_BALLS = ("whiffle_ball_1", "golf_ball", "blue_basketball")
#: Billiards discovery: the first 6 rolling segments of shots 0-39, at 25 fps with 8 substeps.
BILLIARD_SHOTS = tuple(range(0, 40))
SEGMENTS = 6
#: The billiards_slow segments start when the ball is slower than this (m/s): the speeds at which
#: the provenance measured 0.047 m/s².
SLOW = 0.8


def save(out: Path, name: str, disc: Discovery, *, report: bool = True) -> dict:
    """Write ``disc`` as ``<out>/<name>/verdict.json``, ``verdict.txt`` and ``report/``."""
    folder = out / name
    folder.mkdir(parents=True, exist_ok=True)
    d = to_dict(disc)
    (folder / "verdict.json").write_text(json.dumps(d, indent=1) + "\n")
    (folder / "verdict.txt").write_text(text(disc) + "\n")
    if report:
        write_report(disc, folder / "report", dpi=70)
    print(text(disc), flush=True)
    print(
        f"[{name}] {disc.seconds:.0f} s, {disc.base.model.problem.simulations} simulations",
        flush=True,
    )
    return d


def write_table(path: Path, lines: list[str]) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(lines) + "\n")
    print("\n".join(lines), flush=True)


def write_json(path: Path, value: object) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(value, indent=1) + "\n")


# --------------------------------------------------------------------------- ball drops


def _per_mass(by: dict, effect: str, key: str, mass: Any) -> list[float] | None:
    c = by.get(effect)
    if c is None:
        return None
    return [c["params"][key] / mass, c["stderr"].get(key, float("nan")) / mass]


def _pm(v: list[float] | None, fmt: str) -> str:
    return "-" if v is None else f"{v[0]:{fmt}} ± {v[1]:.1g}"


def ball_drops(out: Path) -> None:
    """Each ball on its own (its 2 drops are the runs; the last 30 % of each drop is held out, so
    the fit must extrapolate to higher speeds, where the drag laws differ most)."""
    sim = create("simulator", "pymunk")
    rows = []
    for stem in BALLS:
        drops = load("ball_drops", balls=[stem])
        disc = discover(
            runs_from_dataset(drops), sim, settings=Settings(split="time", shortlist=10)
        )
        d = save(out, f"ball_drops/{stem}", disc, report=stem in REPORTED_BALLS)
        by = {c["effect"]: c for c in d["candidates"] if c["round"] == 1}
        mass = drops[0].notes["mass_kg"]
        rows.append(
            {
                "ball": stem,
                "mass_kg": mass,
                "mass_assumed": drops[0].notes["mass_and_size_assumed"],
                "causes": d["causes"],
                "gain": d["gain"],
                "alternatives": d["alternatives"],
                "chosen": [
                    {"effect": c["effect"], "params": c["params"], "stderr": c["stderr"]}
                    for c in d["candidates"]
                    if c["chosen"]
                ],
                "heldout": {
                    "base": d["base"]["heldout_error"],
                    "final": d["final"]["heldout_error"],
                    **{e: c["heldout_error"] for e, c in by.items()},
                },
                "gain_round1": {e: c["gain"] for e, c in by.items()},
                # drag per unit mass: linear c/m (1/s), quadratic k = c/m (1/m);
                # constant force fy/m (m/s²)
                "linear_c_per_m": _per_mass(by, "linear_drag", "c", mass),
                "quadratic_k": _per_mass(by, "quadratic_drag", "c", mass),
                "constant_accel": _per_mass(by, "constant_force", "fy", mass),
            }
        )
    write_json(out / "ball_drops" / "summary.json", rows)
    lines = [
        "| ball | mass (kg) | causes | gain "
        "| held-out base / linear / quadratic / constant force (m) "
        "| linear c/m (1/s) | quadratic k = c/m (1/m) | constant force / m (m/s²) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        h = r["heldout"]
        heldout = " / ".join(
            f"{v:.3f}"
            for v in (
                h["base"],
                h.get("linear_drag", math.nan),
                h.get("quadratic_drag", math.nan),
                h.get("constant_force", math.nan),
            )
        )
        assumed = " (assumed)" if r["mass_assumed"] else ""
        lines.append(
            f"| {r['ball']} | {r['mass_kg']:.3f}{assumed} | {', '.join(r['causes']) or 'none'} "
            f"| {r['gain']:.0%} | {heldout} | {_pm(r['linear_c_per_m'], '.3g')} "
            f"| {_pm(r['quadratic_k'], '.3g')} | {_pm(r['constant_accel'], '.3g')} |"
        )
    write_table(out / "ball_drops" / "summary.md", lines)


def ball_drops_check(out: Path) -> None:
    """The drag law without physbench's fitter (:func:`~physbench.datasets.ball_drops.
    check_drag_laws`): ODE fits of g plus linear drag, quadratic drag or a constant force per
    drop, scored (a) on each drop's last 30 % after fitting its first 70 % and (b) on each drop
    with the drag fitted on the other drop; and the exponent of the excess deceleration."""
    rows = []
    for stem in BALLS:
        drops = [
            (r.recording.tracks["ball"].t, r.recording.tracks["ball"].y)
            for r in load("ball_drops", balls=[stem])
        ]
        row = {"ball": stem, **asdict(check_drag_laws(drops))}
        rows.append(row)
        print(stem, row, flush=True)
    write_json(out / "ball_drops" / "direct_check.json", rows)
    lines = [
        "| ball | held-out, last 30 % (m): base / linear / quadratic / constant "
        "| held-out, other drop (m): base / linear / quadratic / constant "
        "| linear c/m (1/s) | quadratic k (1/m) | exponent n of the excess deceleration |",
        "|---|---|---|---|---|---|",
    ]
    for r in rows:
        a, b = r["time_split"], r["run_split"]
        lines.append(
            f"| {r['ball']} | {' / '.join(f'{v:.2f}' for v in a.values())} "
            f"| {' / '.join(f'{v:.2f}' for v in b.values())} "
            f"| {' , '.join(f'{k:.3g}' for k in r['k']['linear'])} "
            f"| {' , '.join(f'{k:.3g}' for k in r['k']['quadratic'])} "
            f"| {' , '.join(f'{n:.2f}' for n in r['exponent'])} |"
        )
    write_table(out / "ball_drops" / "direct_check.md", lines)


# --------------------------------------------------------------------------- billiards


def billiards(out: Path, *, slow: bool = False) -> None:
    """The rolling segments of the first shots; the cushion restitution is the base model's
    unknown, shared by all runs."""
    shots = load("billiards", shots=BILLIARD_SHOTS, fps=25.0, substeps=8)
    segments = rolling_segments(shots, count=SEGMENTS, max_speed=SLOW if slow else None)
    runs = runs_from_dataset(segments)
    print("segments:", [(r.name, round(r.t_end, 1)) for r in runs], flush=True)
    sim = create("simulator", "pymunk")
    disc = discover(runs, sim, settings=Settings(split="runs", holdout=0.34, shortlist=10))
    save(out, "billiards_slow" if slow else "billiards", disc)


def billiards_slow(out: Path) -> None:
    """As :func:`billiards`, from when each ball is slower than :data:`SLOW`."""
    billiards(out, slow=True)


def billiards_cushions(out: Path) -> None:
    """What the cushions do, measured directly (no simulation): every cushion bounce in the
    rolling segments of all 182 shots, and the rolling deceleration on straight stretches away
    from the cushions, to compare with the discovered rolling resistance."""
    shots = load("billiards", shots=range(182), fps=25.0, substeps=8)
    bounces, stretches = [], []
    for seg in rolling_segments(shots, count=1000):
        track = seg.recording.tracks["ball"]
        bounces += [asdict(b) for b in cushion_bounces(seg.name, track)]
        stretches += [asdict(s) for s in straight_stretches(seg.name, track)]
    write_json(out / "billiards" / "cushions.json", {"bounces": bounces, "stretches": stretches})
    vn = np.array([b["vn_in"] for b in bounces])
    lines = [
        f"{len(bounces)} cushion bounces in {len({b['run'] for b in bounces})} rolling segments "
        "(all 182 shots)",
        "",
        "| normal impact speed (m/s) | bounces | restitution e_n (median, IQR) "
        "| tangential speed kept | speed kept |",
        "|---|---|---|---|---|",
    ]
    for a, c in ((0.05, 0.3), (0.3, 0.6), (0.6, 1.0), (1.0, 3.0)):
        sel = [b for b, v in zip(bounces, vn, strict=True) if a <= v < c]
        if not sel:
            continue
        cells = []
        for k in ("e_n", "t_kept", "speed_kept"):
            q = np.percentile([b[k] for b in sel], [25, 50, 75])
            cells.append(f"{q[1]:.2f} ({q[0]:.2f}-{q[2]:.2f})")
        lines.append(f"| {a:.2f}-{c:.2f} | {len(sel)} | {' | '.join(cells)} |")
    e = np.array([b["e_n"] for b in bounces])
    slope = np.polyfit(vn, e, 1) if len(bounces) > 2 else [math.nan, math.nan]
    lines += ["", f"least-squares line: e_n = {slope[1]:.3f} {slope[0]:+.3f} · v_n (m/s)"]
    dec = np.array([x["deceleration"] for x in stretches])
    q = np.percentile(dec, [25, 50, 75])
    lines += [
        "",
        f"rolling deceleration on {len(stretches)} straight stretches (>= 1 s, >= 5 cm from the "
        f"cushions): median {q[1]:.4f} m/s² (IQR {q[0]:.4f}-{q[2]:.4f}), mu = {q[1] / 9.81:.5f}",
    ]
    write_table(out / "billiards" / "cushions.md", lines)


# --------------------------------------------------------------------------- pendulums


def _with_unknown_moment(runs: list[DatasetRun], low: float, high: float) -> list[DatasetRun]:
    """``runs`` with their first body's moment of inertia unknown in ``low``..``high`` times its
    value."""
    out = []
    for r in runs:
        body = r.scene.bodies[0]
        unknown = body_unknown(body.name, "moment", low * body.inertia(), high * body.inertia())
        out.append(replace(r, scene=replace(r.scene, unknowns=(unknown,))))
    return out


def pendulum_kaheman(out: Path) -> None:
    """4 windows of 3 s across the 55 s record (amplitudes from about 1.6 rad down to 0.35 rad),
    at 100 fps with 20 substeps (0.5 ms; the pivot's own numerical loss, see docs/discover.md).

    The arm's inertia is the authors' fit; it is an unknown (+-50 %, +-1.7 % of the inertia about
    the pivot) of the base model here, so that a small error of the period is not taken for a
    missing effect. The last run is held out: the 28 s window (amplitude about 0.7 rad), inside
    the range of the fitted ones (1.6 rad at 0 s down to 0.35 rad at 42 s), so that held-out data
    neither favour nor penalise a loss law by lying beyond the amplitudes it was fitted on."""
    windows: list[DatasetRun] = []
    for start in (0.0, 14.0, 42.0, 28.0):
        windows += load(
            "pendulum_kaheman", arms=1, start=start, duration=3.0, windows=1, substeps=20
        )
    runs = runs_from_dataset(_with_unknown_moment(windows, 0.5, 1.5))
    sim = create("simulator", "pymunk")
    disc = discover(runs, sim, settings=Settings(split="runs", holdout=0.25, shortlist=10))
    save(out, "pendulum_kaheman", disc)


def pendulum_benard(out: Path) -> None:
    """The 3 free swings; free_swing_01 (amplitudes 1.6 to 0.6 rad) is held out: it lies between
    the other two (2.1 to 0.8 and 1.0 to 0.2 rad), see :func:`pendulum_kaheman`. The rod's
    inertia is uncertain (the author added 0.08 kg to match the period)."""
    swings = load("pendulum_benard", files=(3, 2, 1), every=5, substeps=5)
    runs = runs_from_dataset(_with_unknown_moment(swings, 0.5, 4.0))
    sim = create("simulator", "pymunk")
    disc = discover(runs, sim, settings=Settings(split="runs", holdout=0.34, shortlist=10))
    save(out, "pendulum_benard", disc)


def pendulum_peaks(out: Path) -> None:
    """The loss law of each pendulum measured directly (no simulation): the half-swing
    amplitudes and least-squares fits of the loss per half swing to each law of
    :data:`~physbench.datasets.oscillation.LOSS_LAWS`."""
    # record -> (angle in rad, fewest samples between extremes: 0.15 s at 1 kHz, 0.3 s at 100 Hz)
    records = {}
    for n in (1, 2, 3):
        deg, _ = read_benard(n)
        a = np.deg2rad(deg)
        records[f"pendulum_benard/free_swing_{n:02d}"] = (a[first_extreme(a) :], 150)
    k = read_kaheman(1)
    records["pendulum_kaheman/single"] = (k[:, 3] - np.median(k[:, 3]), 30)
    result = {}
    lines = [
        "| record | half swings | amplitude (rad) | "
        + " | ".join(f"{f}: rms of dA (rad)" for f in LOSS_LAWS)
        + " | viscous + coulomb: b (rad), a |",
        "|---|---|---|" + "---|" * len(LOSS_LAWS) + "---|",
    ]
    for name, (x, distance) in records.items():
        amp = half_swing_amplitudes(x, distance)
        fits = fit_loss_laws(amp)
        result[name] = {
            "amplitudes": amp.tolist(),
            "fits": {law: asdict(f) for law, f in fits.items()},
        }
        b, a = fits["viscous + coulomb"].coef
        lines.append(
            f"| {name} | {amp.size} | {amp[0]:.2f} to {amp[-1]:.2f} | "
            + " | ".join(f"{fits[f].rms:.4f}" for f in LOSS_LAWS)
            + f" | {b:.4f}, {a:.4f} |"
        )
    write_json(out / "pendulum_peaks.json", result)
    write_table(out / "pendulum_peaks.md", lines)


# --------------------------------------------------------------------------- hidden effects


def hidden_table(out: Path) -> None:
    """The table of hidden-effect results in docs/discover.md, from ``<out>/hidden_effects.jsonl``,
    which the hidden-effect tests write with ``PHYSBENCH_DISCOVERY_SEEDS=0,1,2
    PHYSBENCH_DISCOVERY_LOG=results/discover/hidden_effects.jsonl
    pytest tests/discover/test_hidden_effects.py``."""
    log = out / "hidden_effects.jsonl"
    if not log.is_file():
        raise FileNotFoundError(
            f"{log} not found: hidden_table tabulates the log the hidden-effect tests write "
            "(see docs/discover.md); copy it into --out or run the tests with "
            "PHYSBENCH_DISCOVERY_LOG set"
        )
    rows = [json.loads(line) for line in log.read_text().splitlines() if line.strip()]
    by: dict[str, list[dict]] = {}
    for r in rows:
        by.setdefault(r["effect"] or "", []).append(r)
    lines = [
        "| effect | cases (seeds × scenes × engines) | named first "
        "| worst magnitude error (case) | median error | lowest gain |",
        "|---|---|---|---|---|---|",
    ]
    for effect, rs in by.items():
        if not effect:
            continue
        ok = [r for r in rs if r["error"] is not None]
        worst = max(ok, key=lambda r: r["error"])
        errs = sorted(r["error"] for r in ok)
        lines.append(
            f"| {effect} | {len(rs)} | {len(ok)}/{len(rs)} "
            f"| {worst['error']:.1%} ({worst['scene']}, {worst['engine']}, seed {worst['seed']}) "
            f"| {errs[len(errs) // 2]:.1%} | {min(r['gain'] for r in rs):.0%} |"
        )
    controls = by.get("", [])
    alarms = [r for r in controls if r["causes"]]
    lines += [
        "",
        f"Controls: {len(controls)} ({len({r['scene'] for r in controls})} scenes × 2 engines × "
        f"{len({r['seed'] for r in controls})} seeds), false alarms: {len(alarms)}.",
    ]
    write_table(out / "hidden_effects.md", lines)


# --------------------------------------------------------------------------- command line

STEPS: dict[str, Callable[[Path], None]] = {
    "ball_drops": ball_drops,
    "ball_drops_check": ball_drops_check,
    "billiards": billiards,
    "billiards_slow": billiards_slow,
    "billiards_cushions": billiards_cushions,
    "pendulum_kaheman": pendulum_kaheman,
    "pendulum_benard": pendulum_benard,
    "pendulum_peaks": pendulum_peaks,
    "hidden_table": hidden_table,
}
#: What runs when no step is named: everything but hidden_table, which needs the tests' log.
DEFAULT_STEPS = [s for s in STEPS if s != "hidden_table"]


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        description=(__doc__ or "").splitlines()[0],
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="steps: " + ", ".join(STEPS),
    )
    ap.add_argument(
        "steps",
        nargs="*",
        metavar="STEP",
        help=f"what to run, in this order (default: {' '.join(DEFAULT_STEPS)})",
    )
    ap.add_argument(
        "--out",
        type=Path,
        default=DEFAULT_OUT,
        help="folder to write into (default: results/discover in the repository)",
    )
    args = ap.parse_args(argv)
    unknown = [s for s in args.steps if s not in STEPS]
    if unknown:
        ap.error(f"unknown step(s) {', '.join(map(repr, unknown))}; steps: {', '.join(STEPS)}")
    steps = args.steps or DEFAULT_STEPS
    t_all = time.perf_counter()
    for i, step in enumerate(steps, start=1):
        print(f"== [{i}/{len(steps)}] {step} -> {args.out}", flush=True)
        t0 = time.perf_counter()
        try:
            STEPS[step](args.out)
        except (PhysbenchError, OSError) as e:
            print(f"discover_real.py: {step} failed: {e}", file=sys.stderr)
            return 1
        print(f"== {step} done in {time.perf_counter() - t0:.0f} s", flush=True)
    print(f"done in {time.perf_counter() - t_all:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())

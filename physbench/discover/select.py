"""Selecting the cause: fit base + each candidate effect jointly, compare them on held-out data and
with an information criterion (:mod:`physbench.discover.significance`), and add effects greedily
while that helps (:func:`select_causes`); then drop causes a later one made redundant
(:func:`prune_causes`).

The most useful significant candidate (lowest held-out error) is added; the next round refits the
``shortlist`` best remaining candidates of this round, plus whatever the new model's residual
statistics point at, on top of it, until nothing is significant or ``max_causes`` effects were
added. Defaults were calibrated on control recordings (no hidden effect, both engines): see
``docs/discover.md``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace

from physbench.discover.candidates import CandidateSpec
from physbench.discover.diagnostics import findings, views
from physbench.discover.fit import fit_model, is_rough, score
from physbench.discover.results import CandidateResult, Scored, Selection, Skipped
from physbench.discover.settings import Settings
from physbench.discover.significance import floored_gain, judge, measurement_floor
from physbench.discover.trial import refit, try_effect


def select_causes(
    base: Scored,
    specs: Sequence[CandidateSpec],
    settings: Settings,
    skipped: Sequence[tuple[str, str]] = (),
) -> Selection:
    """Greedy forward selection from the fitted ``base`` over the candidates ``specs``. Before a
    candidate is accepted, the model it extends is refitted from the candidate's optimum (a
    candidate may win only because its fit escaped a valley the current fit is stuck in); the
    better refit replaces that model (the base, or the last cause's fit). ``skipped``: candidates
    already left out, with the reason; the ones that cannot be fitted in round 1 are added."""
    left_out = list(skipped)
    current = base
    results: list[CandidateResult] = []
    causes: list[str] = []
    alternatives: dict[str, list[str]] = {}
    last: CandidateResult | None = None  # the cause added last
    pool = list(specs)
    rough = is_rough(base.model.problem.runs)
    for rnd in range(1, settings.max_causes + 1):
        tried = [
            try_effect(current, spec, settings, base=base, round=rnd, quick=rough) for spec in pool
        ]
        if rnd == 1:
            left_out += [(s.effect, s.reason) for s in tried if isinstance(s, Skipped)]
        round_results = [c for c in tried if isinstance(c, CandidateResult)]
        if rough:
            round_results = _screen(round_results, pool, current, base, rnd, settings)
        best = None
        for _ in range(3):
            good = [c for c in round_results if c.significant]
            if not good:
                break
            best = min(good, key=lambda c: (c.heldout_error, c.criterion))
            assert best.scored is not None
            # A candidate can beat the current model only because its fit escaped a valley the
            # current fit is stuck in: refit the current model from the candidate's optimum and
            # judge again against whichever fit of the current model is better.
            better = refit(current, best.scored.model, settings)
            if better is None:
                break
            if current is base:
                base = better
            elif last is not None:  # the current model is the last cause's fit: report the better
                i = _index(results, last)
                last = results[i] = _refitted(last, better, base, settings)
            current, best = better, None
            round_results = [judge(c, current, base, settings) for c in round_results]
        if best is None:
            results += round_results
            break
        i = _index(round_results, best)
        best = round_results[i] = replace(best, chosen=True)
        results += round_results
        last = best
        causes.append(best.effect)
        alternatives[best.effect] = [
            c.effect
            for c in round_results
            if c is not best
            and c.significant
            and c.heldout_error <= best.heldout_error * (1 + settings.ambiguity)
        ]
        assert best.scored is not None
        current = best.scored
        pool = _next_pool(pool, round_results, best, current, settings)
        if not pool:
            break
    return Selection(base, current, results, causes, alternatives, left_out)


def _screen(
    round_results: list[CandidateResult],
    pool: Sequence[CandidateSpec],
    current: Scored,
    base: Scored,
    rnd: int,
    settings: Settings,
) -> list[CandidateResult]:
    """Rough scenes: every candidate got a quick fit from the current optimum; the most promising
    ones (by fitted error, never by held-out error) and the ones the current model's residual
    statistics point at get the full, restarted fit, kept where it fits better."""
    out = list(round_results)
    suggested = {e for f in findings(views(current.model)) for e in f.suggests}
    ranked = sorted((c for c in out if c.delta_criterion < 0), key=lambda c: c.criterion)
    top = ranked[: settings.screen]
    full_fit = top + [c for c in out if c.name in suggested and c not in top]
    for c in full_fit:
        spec = next(sp for sp in pool if sp.label == c.effect)
        full = try_effect(current, spec, settings, base=base, round=rnd, quick=False)
        if isinstance(full, CandidateResult) and full.criterion < c.criterion:
            out[_index(out, c)] = full
    return [
        replace(c, note="; ".join(filter(None, [c.note, "quick fit only (screened out)"])))
        if c.quick
        else c
        for c in out
    ]


def _next_pool(
    pool: Sequence[CandidateSpec],
    round_results: Sequence[CandidateResult],
    best: CandidateResult,
    current: Scored,
    settings: Settings,
) -> list[CandidateSpec]:
    """The candidates of the next round: the ``shortlist`` with the best held-out gains this round,
    and whatever the new model's residual statistics still point at."""
    ranked = sorted(
        (c for c in round_results if c is not best and c.gain > 0), key=lambda c: -c.gain
    )
    names = {c.effect for c in ranked[: settings.shortlist]}
    names |= {e for f in findings(views(current.model)) for e in f.suggests} - {best.name}
    return [s for s in pool if s.label in names or s.name in names]


def _refitted(
    c: CandidateResult, scored: Scored, base: Scored, settings: Settings
) -> CandidateResult:
    """A chosen candidate with its fit replaced by a better refit of the same model."""
    m, key = scored.model, c.effect
    out = replace(
        c,
        params={k: m.values[f"{key}.{k}"] for k in c.params},
        stderr={k: scored.fit.stderr.get(f"{key}.{k}", math.nan) for k in c.params},
        intervals={
            k: scored.fit.intervals[f"{key}.{k}"]
            for k in c.params
            if f"{key}.{k}" in scored.fit.intervals
        },
        interval_method=scored.fit.interval_method,
        heldout_error=scored.heldout,
        criterion=scored.bic,
        scored=scored,
        at_bound=tuple(k for k in c.params if f"{key}.{k}" in scored.fit.at_bound),
    )
    if out.previous is not None:
        out = judge(out, out.previous, base, settings)
    return replace(out, significant=True)


def _index(items: Sequence[CandidateResult], item: CandidateResult) -> int:
    return next(i for i, c in enumerate(items) if c is item)


def prune_causes(selection: Selection, settings: Settings) -> Selection:
    """Backward check after the greedy additions: drop a cause whose removal (and a refit of the
    rest) costs less than ``min_gain`` of held-out error, e.g. one added first that a later,
    better cause made redundant; repeated until every remaining cause is needed."""
    current, causes = selection.final, list(selection.causes)
    results = list(selection.candidates)
    changed = True
    while changed and len(causes) > 1:
        changed = False
        for key in list(causes):
            m = current.model.without(key)
            free = [k for k in current.fit.free if k in m.values]
            fr = fit_model(m, settings, base=False, free=free)
            reduced = score(current.label, tuple(c for c in causes if c != key), m, fr)
            floor = measurement_floor(current.model.problem, settings)
            loss = floored_gain(current.heldout, reduced.heldout, floor)
            if loss < settings.min_gain:
                results = [
                    replace(c, chosen=False, note=_dropped(c, loss))
                    if c.chosen and c.effect == key
                    else c
                    for c in results
                ]
                causes = [c for c in causes if c != key]
                current, changed = reduced, True
                break
    return replace(selection, final=current, causes=causes, candidates=results)


def _dropped(c: CandidateResult, loss: float) -> str:
    return (
        f"added in round {c.round}, then dropped: without it the other causes predict the "
        f"held-out data within {loss:+.1%}"
    )

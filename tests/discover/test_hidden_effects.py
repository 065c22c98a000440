"""Hidden-effect tests: for every effect in the library, synthetic recordings made with that effect
at a random magnitude plus tracking noise, in two scenes each and in both engines, must be
diagnosed with that effect named first and its magnitude within 15 %; control recordings without a
hidden effect must produce no cause.

Synthetic runs come from seeds (:func:`physbench.discover.synthetic.make_case`).
``PHYSBENCH_DISCOVERY_SEEDS`` (e.g. ``0,1,2,3``) runs more seeds; the default, one seed, keeps the
suite within its CI budget. ``PHYSBENCH_DISCOVERY_LOG=FILE`` appends one JSON line per case
(causes, magnitude error, gain) to ``FILE``, for the table in docs/discover.md.
"""

from __future__ import annotations

import json
import os

import pytest

from physbench.discover import discover
from physbench.discover.synthetic import EFFECT_SCENES, SCENES, magnitude_error, make_case
from physbench.effects import BUILTIN_EFFECTS
from physbench.simulators.box2d_sim import Box2DSimulator
from physbench.simulators.pymunk_sim import PymunkSimulator

SEEDS = [int(s) for s in os.environ.get("PHYSBENCH_DISCOVERY_SEEDS", "0").split(",") if s.strip()]
ENGINES = {"pymunk": PymunkSimulator, "box2d": Box2DSimulator}
TOLERANCE = 0.15

HIDDEN = [
    (e, sc, eng, seed)
    for e, scenes in EFFECT_SCENES.items()
    for sc in scenes
    for eng in ENGINES
    for seed in SEEDS
]
CONTROLS = [(sc, eng, seed) for sc in sorted(SCENES) for eng in ENGINES for seed in SEEDS]


#: (effect, scene) pairs that take 10-30 s a case: ``nox -s extended`` runs them on both engines,
#: and CI the effect's other scene on both.
SLOW = {
    ("velocity_dependent_restitution", "drops"),
    ("joint_viscous_damping", "double_pendulum"),
    ("joint_coulomb_friction", "double_pendulum"),
}


def _alternate(cases: list[tuple], scene_at: int) -> list:
    """``cases`` as pytest params, where CI runs each effect's scenes (and the controls) on the
    engines in turn and ``nox -s extended`` the other engine's case (marked ``extended``): every
    effect, scene and engine stays in CI, in half its time (:data:`SLOW` aside)."""
    scenes: dict[tuple, int] = {}
    slow_effects = {effect for effect, _ in SLOW}
    params = []
    for case in cases:
        group = case[: scene_at + 1]
        turn = scenes.setdefault(group, len(scenes))
        engine = case[scene_at + 1]
        in_ci = list(ENGINES).index(engine) == turn % len(ENGINES)
        if scene_at and group in SLOW:
            in_ci = False
        elif scene_at and group[0] in slow_effects:
            in_ci = True
        marks = () if in_ci else (pytest.mark.extended,)
        params.append(pytest.param(*case, marks=marks, id="/".join(map(str, case))))
    return params


def _log(**row: object) -> None:
    path = os.environ.get("PHYSBENCH_DISCOVERY_LOG")
    if path:
        with open(path, "a") as f:
            f.write(json.dumps(row) + "\n")


def test_every_effect_in_the_library_has_hidden_effect_scenes():
    assert {c.name for c in BUILTIN_EFFECTS} == set(EFFECT_SCENES)
    assert all(len(s) >= 2 for s in EFFECT_SCENES.values())
    assert len(CONTROLS) >= 20


@pytest.mark.parametrize(("effect", "scene", "engine", "seed"), _alternate(HIDDEN, 1))
def test_hidden_effect_is_named_with_its_magnitude(effect, scene, engine, seed):
    sim = ENGINES[engine]()
    synthetic = make_case(effect, scene, seed, sim)
    disc = discover([synthetic.run], sim, diagnose=False)
    found = disc.cause_results[0] if disc.causes[:1] == [effect] else None
    err = magnitude_error(effect, synthetic.truth, found.params) if found is not None else None
    _log(
        effect=effect,
        scene=scene,
        engine=engine,
        seed=seed,
        causes=disc.causes,
        error=err,
        gain=disc.gain,
        truth=synthetic.truth,
        fitted=found.params if found is not None else None,
        seconds=disc.seconds,
    )
    assert disc.causes[:1] == [effect], (
        f"{synthetic.name} [{engine}]: causes {disc.causes}, truth {synthetic.truth}"
    )
    assert found is not None and err is not None
    assert err <= TOLERANCE, (
        f"{synthetic.name} [{engine}]: fitted {found.params}, truth {synthetic.truth} "
        f"({err:.1%} off)"
    )
    assert disc.gain > 0.5


@pytest.mark.parametrize(("scene", "engine", "seed"), _alternate(CONTROLS, 0))
def test_control_without_a_hidden_effect_produces_no_cause(scene, engine, seed):
    sim = ENGINES[engine]()
    synthetic = make_case(None, scene, seed, sim)
    disc = discover([synthetic.run], sim, diagnose=False)
    _log(
        effect=None,
        scene=scene,
        engine=engine,
        seed=seed,
        causes=disc.causes,
        gain=disc.gain,
        seconds=disc.seconds,
    )
    assert disc.causes == [], (
        f"{synthetic.name} [{engine}]: false alarm {disc.causes} "
        + ", ".join(
            f"{c.effect} gain {c.gain:+.1%} ΔBIC {c.delta_criterion:+.1f}"
            for c in disc.cause_results
        )
    )

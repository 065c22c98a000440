"""Every built-in simulator, renderer, effect and estimator passes its kind's conformance kit:
one test per component x check (``pytest -k RasterRenderer`` runs one component's)."""

from __future__ import annotations

from typing import Any

from physbench.effects import BUILTIN_EFFECTS
from physbench.estimators.resnet3d.weights import SHIPPED
from physbench.kinds import KINDS as ALL_KINDS
from physbench.plugins import build_registry
from physbench.testing import Check, Subject, parametrize_with_checks
from physbench.testing.kit import kind_of

#: The kinds with a contract class (scenes are plain callables, without a kit).
KINDS = tuple(k.name for k in ALL_KINDS if k.base)

#: Kit settings, options and optional modules of the built-ins that need them (by registered name).
SETTINGS: dict[str, dict[str, Any]] = {
    "tpe": {"kit": {"bad_options": [{"startup": -1}, {"candidates": 0}, {"gamma": 1.5}]}},
    "cmaes": {"kit": {"bad_options": [{"sigma": 0.0}, {"popsize": 1}, {"elitist": "yes"}]}},
    "nevergrad": {"kit": {"bad_options": [{"optimizer": "NoSuchOptimizer"}]}},
    "optuna": {"kit": {"bad_options": [{"sampler": "grid"}, {"startup": 2.5}]}},
    "gp": {
        "kit": {"bad_options": [{"startup": 0}, {"design": "sobol"}]},
        "requires": ("torch",),
    },
    "resnet3d": {
        # Shipped weights for mass; the toy task's frames are resampled to the network's input.
        "options": {
            "weights": str(SHIPPED / "three_circles__mass.safetensors"),
            "any_renderer": True,  # the kit's toy renderer, not the one the weights know
        },
        "kit": {"unknowns": ("mass",), "bad_options": [{"weights": "no_such.safetensors"}]},
        "requires": ("torch", "safetensors"),
    },
}


#: Built-ins the kit cannot run, and why; their own tests cover the protocol instead.
NOT_ON_THE_TOY_TASK = {
    "npe": "its weights hold one scene's ranges (three_circles mass in [2, 8] kg) and it refuses "
    "a task with others, as the toy task's [1, 10] kg: tests/estimators/npe/test_estimator.py "
    "runs it on the rows it has weights for",
}


def builtins() -> list[Subject]:
    """The components physbench itself registers (not those of installed plugins)."""
    reg = build_registry(env=False)
    out = []
    for kind in KINDS:
        for name in reg.names(kind):
            info = reg.info(kind, name)
            if info.package == "physbench" and name not in NOT_ON_THE_TOY_TASK:
                out.append(Subject(info.obj, **SETTINGS.get(name, {})))
    return out


BUILTINS = builtins()


def test_every_kind_has_builtins() -> None:
    # Guards the parametrized test below against an empty registry (it would pass vacuously).
    by_kind = {kind: {s.cls.name for s in BUILTINS if kind_of(s.cls) == kind} for kind in KINDS}
    assert by_kind["simulator"] == {"pymunk", "box2d"} and by_kind["renderer"] == {
        "raster",
        "camera",
    }
    assert by_kind["effect"] == {cls.name for cls in BUILTIN_EFFECTS}
    assert {"random", "tpe", "cmaes", "nevergrad", "optuna", "gp", "resnet3d"} <= by_kind[
        "estimator"
    ]
    assert "scipy" not in by_kind["estimator"]  # the example plugin tests itself
    assert set(SETTINGS) <= by_kind["estimator"]
    registered = build_registry(env=False).names("estimator")
    assert set(NOT_ON_THE_TOY_TASK) <= set(registered)  # an exclusion names a real estimator


@parametrize_with_checks(BUILTINS)
def test_builtin_conforms(component: Subject, check: Check) -> None:
    check(component)

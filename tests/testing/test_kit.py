"""The shared kit machinery: checks chosen by kind, pytest ids, skips and expected failures."""

from __future__ import annotations

from collections.abc import Callable

import pytest

from physbench.effects import LinearDrag, VelocityDependentRestitution
from physbench.estimators.random_search import RandomSearch
from physbench.render.raster import RasterRenderer
from physbench.simulators.pymunk_sim import PymunkSimulator
from physbench.testing import (
    ConformanceError,
    Subject,
    checks_for,
    parametrize_with_checks,
)


def params_of(components: list[type | Subject]) -> list[tuple[str, list[str]]]:
    """(id, mark names) of every test ``parametrize_with_checks`` generates."""
    mark = parametrize_with_checks(components)
    assert mark.args[0] == ("component", "check")
    return [(p.id, [m.name for m in p.marks]) for p in mark.args[1]]


def test_one_id_per_component_and_check_chosen_by_kind() -> None:
    ids = [i for i, _ in params_of([RasterRenderer, PymunkSimulator, LinearDrag, RandomSearch])]
    assert "RasterRenderer-check_marking" in ids
    assert "PymunkSimulator-check_free_fall" in ids
    assert "LinearDrag-check_neutral" in ids
    assert "RandomSearch-check_respects_ranges" in ids
    assert len(ids) == len(set(ids))
    assert [i for i in ids if i.startswith("RandomSearch-")] == [
        "RandomSearch-check_protocol",
        "RandomSearch-check_respects_ranges",
        "RandomSearch-check_deterministic",
        "RandomSearch-check_bad_input",
        "RandomSearch-check_deterministic_in_subprocess",
    ]


def test_traits_and_settings_choose_the_checks() -> None:
    names = [c.name for c in checks_for(VelocityDependentRestitution)]
    assert "check_neutral" not in names  # a contact law has no neutral values
    quick = Subject(RandomSearch, kit={"subprocess": False})
    assert "check_deterministic_in_subprocess" not in [c.name for c in checks_for(quick)]


def test_subject_ids_and_options() -> None:
    ids = [i for i, _ in params_of([Subject(PymunkSimulator, {"iterations": 20}, id="pm20")])]
    assert ids[0] == "pm20-check_protocol"


def test_missing_requirements_skip_and_expected_failures_xfail() -> None:
    subject = Subject(
        RasterRenderer,
        requires=("no_such_module_xyz",),
        expected_failures={"check_out": "known bug"},
    )
    marks = dict(params_of([subject]))
    assert marks["RasterRenderer-check_marking"] == ["skip"]
    assert marks["RasterRenderer-check_out"] == ["skip", "xfail"]
    mark = parametrize_with_checks([subject]).args[1][0].marks[0]
    assert mark.kwargs["reason"] == "RasterRenderer needs no_such_module_xyz, not installed"


def test_mistakes_in_the_subject_are_named() -> None:
    with pytest.raises(ConformanceError, match=r"unknown renderer kit settings \['bad_options'\]"):
        checks_for(Subject(RasterRenderer, kit={"bad_options": []}))
    with pytest.raises(ConformanceError, match=r"expected_failures names \['check_typo'\]"):
        parametrize_with_checks([Subject(RasterRenderer, expected_failures={"check_typo": "x"})])
    with pytest.raises(ConformanceError, match="subclasses none of the component base classes"):
        checks_for(int)


def test_a_class_outside_the_contract_is_named() -> None:
    from physbench.testing import check_effect, check_renderer, check_simulator

    for check, base in (
        (check_simulator, "physbench.simulators.base.Simulator"),
        (check_renderer, "physbench.render.base.Renderer"),
        (check_effect, "physbench.effects.base.Effect"),
    ):
        with pytest.raises(ConformanceError, match=f"does not subclass {base}"):
            check(dict)


def test_importing_the_kits_imports_no_optimiser(heavy_imports: Callable[..., list[str]]) -> None:
    # the kits run every built-in estimator: each imports its library when a run starts
    assert heavy_imports("physbench.testing") == []

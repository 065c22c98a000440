"""The component factory: one sentence for a bad option of any kind, and only for the refusal of
the call itself."""

from __future__ import annotations

from collections.abc import Callable
from types import ModuleType

import pytest

from physbench.components import create, make_estimator, make_observer, make_renderer, origin
from physbench.errors import OptionError, UnknownNameError
from physbench.plugins import ComponentError

#: Components whose constructors fail in ways that are not the user's options.
FAULTY = """
from typing import ClassVar

from physbench.estimators.base import CorrectionEstimator
from physbench.hookspecs import hookimpl


class Inner(CorrectionEstimator):
    name: ClassVar[str] = "inner_typeerror"

    def __init__(self, step=1):
        super().__init__()
        len(step)  # a TypeError raised inside the constructor: the plugin's fault


class Needs(CorrectionEstimator):
    name: ClassVar[str] = "needs_option"

    def __init__(self, table):
        super().__init__()
        self.table = table


class Picky(CorrectionEstimator):
    name: ClassVar[str] = "picky"

    def __init__(self, step=1.0):
        super().__init__()
        if step <= 0:
            raise ValueError(f"step = {step!r}: expected a number > 0")


@hookimpl
def register_estimators():
    return [Inner, Needs, Picky]
"""


@pytest.mark.parametrize(
    ("kind", "name", "standard", "takes"),
    [
        ("simulator", "pymunk", {}, "its options: iterations, velocity_threshold"),
        ("renderer", "raster", {"resolution": 16, "mode": "mark"}, "its options: none (besides"),
        ("estimator", "random", {}, "its options: none"),
        ("effect", "linear_drag", {}, "its options: bodies, label, c"),
    ],
)
def test_every_kind_gets_the_same_sentence(
    kind: str, name: str, standard: dict[str, object], takes: str
) -> None:
    with pytest.raises(OptionError) as info:
        create(kind, name, {"colour": "red"}, **standard)
    message = str(info.value)
    assert message.startswith(f"{kind} {name!r} (physbench's own) does not take option 'colour'; ")
    assert takes in message


def test_the_sentence_lists_what_the_component_takes() -> None:
    with pytest.raises(OptionError, match=r"options 'x', 'y'; its options: startup, design"):
        make_estimator("tpe", {"x": 1, "y": 2})


def test_unknown_names_list_the_known_ones() -> None:
    with pytest.raises(UnknownNameError, match="unknown estimator 'nope'; known estimators: "):
        create("estimator", "nope")
    with pytest.raises(Exception, match="unknown component kind 'engine'"):
        create("engine", "pymunk")


def test_a_typeerror_inside_a_constructor_is_the_components_fault(
    plugin: Callable[..., ModuleType],
) -> None:
    plugin("pb_faulty", FAULTY)
    with pytest.raises(ComponentError, match=r"inner_typeerror.*failed in __init__\(\): TypeError"):
        create("estimator", "inner_typeerror")
    with pytest.raises(OptionError, match=r"'needs_option' \(plugin 'pb_faulty', registered by "):
        create("estimator", "needs_option")
    with pytest.raises(OptionError, match="needs option 'table'; its options: table"):
        create("estimator", "needs_option")
    with pytest.raises(OptionError, match=r"refused options \{'step': -1\}: step = -1: expected"):
        create("estimator", "picky", {"step": -1})
    assert create("estimator", "picky", {"step": 2.0}).name == "picky"
    assert origin("estimator", "picky") == "plugin 'pb_faulty', registered by PHYSBENCH_PLUGINS"


def test_renderer_keywords_the_framework_sets_are_refused_as_options() -> None:
    with pytest.raises(OptionError, match="set it with --resolution / --render-mode"):
        make_renderer("raster", {"mode": "mask"}, resolution=32, mode="mark")
    assert make_renderer("raster", resolution=16, mode=None).mode == "mark"


def test_an_observer_must_be_a_camera() -> None:
    pytest.importorskip("av")
    assert make_observer("camera", {"resolution": 64}).image_size() == (48, 64)
    with pytest.raises(Exception, match="observer 'raster' is a RasterRenderer; an observer"):
        make_observer("raster")

"""A component's optional dependencies: checked before it is built, named with what installs
them."""

from __future__ import annotations

import sys
from typing import ClassVar

import pytest

from physbench.components import create
from physbench.estimators.base import CorrectionEstimator
from physbench.requirements import MissingDependencyError, Requirements, missing_of, require


class _NeedsTwo(CorrectionEstimator):
    name: ClassVar[str] = "needs_two"
    requires: ClassVar[dict[str, str]] = {
        "json": "stdlib",
        "pb_no_such_module.sub": "pb-extra",
        "pb_other_absent": "pb-extra",
    }


def test_only_the_modules_that_cannot_be_imported_are_missing() -> None:
    assert _NeedsTwo.missing() == {
        "pb_no_such_module.sub": "pb-extra",
        "pb_other_absent": "pb-extra",
    }
    assert CorrectionEstimator.missing() == {}
    assert missing_of(lambda seed: seed) == {}  # scene generators declare nothing
    assert issubclass(CorrectionEstimator, Requirements)


def test_the_error_names_every_missing_module_and_one_install_command() -> None:
    with pytest.raises(MissingDependencyError) as info:
        require("estimator", "needs_two", _NeedsTwo)
    assert str(info.value) == (
        "estimator 'needs_two' needs pb_no_such_module.sub, pb_other_absent, which are not "
        "installed: pip install 'pb-extra'"
    )


def test_create_refuses_resnet3d_without_torch_before_building_it(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setitem(sys.modules, "torch", None)
    with pytest.raises(MissingDependencyError, match=r"pip install 'physbench\[learn\]'"):
        create("estimator", "resnet3d")

"""``physbench plugins``: every component with its package, and the plugins that failed."""

from __future__ import annotations

import json
import sys

import pytest

from physbench.cli import main


def test_table_and_json_list_every_kind_and_the_failures(
    capsys: pytest.CaptureFixture[str], squares_renderer, monkeypatch: pytest.MonkeyPatch
) -> None:  # type: ignore[no-untyped-def]
    from physbench.plugins import reset_registry

    monkeypatch.setenv("PHYSBENCH_PLUGINS", "pb_squares,pb_not_installed")
    reset_registry()
    assert main(["plugins"]) == 0
    out = capsys.readouterr().out
    assert out.splitlines()[0].split() == ["KIND", "NAME", "PLUGIN", "PACKAGE", "VERSION", "STATUS"]
    for kind, name in [
        ("simulator", "pymunk"),
        ("renderer", "raster"),
        ("renderer", "squares"),
        ("estimator", "tpe"),
        ("scene", "three_circles"),
        ("effect", "linear_drag"),
    ]:
        assert any(line.split()[:2] == [kind, name] for line in out.splitlines()), (kind, name)
    assert "Failed to load (skipped):" in out and "pb_not_installed" in out
    assert main(["plugins", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    squares = next(c for c in data["components"] if c["name"] == "squares")
    assert squares["package"] == "PHYSBENCH_PLUGINS" and squares["kind"] == "renderer"
    assert [f["plugin"] for f in data["failed"]] == ["pb_not_installed"]


def test_a_component_whose_extra_is_missing_is_marked_unavailable(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setitem(sys.modules, "torch", None)  # as if the learn extra were not installed
    assert main(["plugins"]) == 0
    rows = {tuple(line.split()[:2]): line for line in capsys.readouterr().out.splitlines()}
    assert (
        "unavailable: needs torch (pip install 'physbench[learn]')" in rows["estimator", "resnet3d"]
    )
    assert rows["estimator", "tpe"].split()[-1] == "ok"
    assert main(["plugins", "--json"]) == 0
    data = {c["name"]: c for c in json.loads(capsys.readouterr().out)["components"]}
    assert data["resnet3d"]["available"] is False
    assert data["resnet3d"]["missing"] == {"torch": "physbench[learn]"}
    assert data["cmaes"]["available"] is True and data["cmaes"]["missing"] == {}

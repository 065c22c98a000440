"""``physbench plugins``: every component with its package, and the plugins that failed."""

from __future__ import annotations

import json

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
    assert out.splitlines()[0].split() == ["KIND", "NAME", "PLUGIN", "PACKAGE", "VERSION"]
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

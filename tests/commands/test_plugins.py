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


#: An estimator named ``{name}`` that raises ``{error}`` in ``{where}`` (``start`` or ``propose``).
ESTIMATOR = """
from physbench.estimators.base import CorrectionEstimator
from physbench.hookspecs import hookimpl


class Plugged(CorrectionEstimator):
    name = "{name}"

    def start(self, task, *, seed):
        if "{where}" == "start":
            raise {error}

    def propose(self, step):
        if "{where}" == "propose":
            raise {error}
        return dict(step.params)


@hookimpl
def register_estimators():
    return [Plugged]
"""

FAST = ["--iterations", "2", "--resolution", "32", "-q"]


def test_a_plugin_claiming_a_builtin_name_is_reported_and_the_builtin_kept(
    capsys: pytest.CaptureFixture[str], plugin, monkeypatch: pytest.MonkeyPatch
) -> None:  # type: ignore[no-untyped-def]
    from physbench.plugins import get_registry

    plugin("pb_dup", ESTIMATOR.format(name="tpe", where="start", error="RuntimeError('mine')"))
    assert main(["plugins"]) == 0
    out = capsys.readouterr().out
    assert "Name conflicts:" in out
    assert (
        "estimator 'tpe' is physbench's own; the one of plugin 'pb_dup' (PHYSBENCH_PLUGINS -) is "
        "ignored" in out
    )
    assert main(["plugins", "--json"]) == 0
    (conflict,) = json.loads(capsys.readouterr().out)["conflicts"]
    assert conflict["kept"]["package"] == "physbench"
    assert [i["plugin"] for i in conflict["ignored"]] == ["pb_dup"]
    assert get_registry().info("estimator", "tpe").package == "physbench"
    assert main(["run", "--estimator", "cmaes", *FAST]) == 0
    assert main(["run", "--estimator", "tpe", *FAST]) == 0  # the built-in, which does not raise


def test_two_plugins_claiming_one_name_are_both_refused_by_name(
    capsys: pytest.CaptureFixture[str], plugin
) -> None:  # type: ignore[no-untyped-def]
    plugin("pb_twin_a", ESTIMATOR.format(name="twin", where="none", error="None"))
    plugin("pb_twin_b", ESTIMATOR.format(name="twin", where="none", error="None"))
    assert main(["plugins"]) == 0
    out = capsys.readouterr().out
    assert "estimator 'twin' is provided by plugin 'pb_twin_a'" in out
    assert "and by plugin 'pb_twin_b'" in out and "none of them is used" in out
    assert not any(line.split()[:2] == ["estimator", "twin"] for line in out.splitlines())
    assert main(["run", "--estimator", "twin", *FAST]) == 2
    assert "none of them is used" in capsys.readouterr().err
    assert main(["run", "--estimator", "random", *FAST]) == 0


@pytest.mark.parametrize("where", ["start", "propose"])
@pytest.mark.parametrize(
    ("error", "shown"),
    [("RuntimeError('kaput')", "RuntimeError: kaput"), ("SystemExit(3)", "SystemExit: 3")],
)
def test_an_estimator_that_raises_is_named_with_its_plugin_and_package(
    capsys: pytest.CaptureFixture[str], plugin, where: str, error: str, shown: str
) -> None:  # type: ignore[no-untyped-def]
    plugin("pb_boom", ESTIMATOR.format(name="boom", where=where, error=error))
    assert main(["run", "--estimator", "boom", *FAST]) == 2
    err = capsys.readouterr().err
    assert err == (
        f"physbench run: error: estimator 'boom' of plugin 'pb_boom' (PHYSBENCH_PLUGINS -) failed "
        f"in {where}(): {shown}; this is a fault of that plugin: report it to its authors (rerun "
        "with --debug for the traceback)\n"
    )


SIMULATOR = """
from physbench.hookspecs import hookimpl
from physbench.simulators.base import Simulator


class Broken(Simulator):
    name = "broken"

    def simulate(self, scene, params=None, *, effects=()):
        return {}["no such key"]


@hookimpl
def register_simulators():
    return [Broken]
"""


@pytest.mark.parametrize("observe", ["broken", "pymunk"])  # outside the loop, and in it
def test_a_simulator_that_raises_is_named_with_its_plugin(
    capsys: pytest.CaptureFixture[str], plugin, observe: str
) -> None:  # type: ignore[no-untyped-def]
    plugin("pb_broken_sim", SIMULATOR)
    argv = ["run", "--engine", "broken", "--observe-engine", observe, *FAST]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith(
        "physbench run: error: simulator 'broken' of plugin 'pb_broken_sim' (PHYSBENCH_PLUGINS -) "
        "failed in simulate(): KeyError: 'no such key'; this is a fault of that plugin"
    )
    assert err.count("\n") == 1


def test_a_scene_generator_that_raises_is_named_with_its_plugin(
    capsys: pytest.CaptureFixture[str], plugin
) -> None:  # type: ignore[no-untyped-def]
    plugin(
        "pb_bad_scene",
        """
        from physbench.hookspecs import hookimpl
        from physbench.scenes.generator import scene_generator

        @scene_generator("bad_scene", "divides by zero")
        def generate(seed=0):
            return 1 / 0

        @hookimpl
        def register_scenes():
            return [generate]
        """,
    )
    assert main(["run", "--scene", "bad_scene", *FAST]) == 2
    assert capsys.readouterr().err.startswith(
        "physbench run: error: scene 'bad_scene' of plugin 'pb_bad_scene' (PHYSBENCH_PLUGINS -) "
        "failed in the call for seed 0: ZeroDivisionError: division by zero"
    )


def test_a_plugin_calling_sys_exit_at_import_is_recorded_as_failed(
    capsys: pytest.CaptureFixture[str], tmp_path, monkeypatch: pytest.MonkeyPatch
) -> None:  # type: ignore[no-untyped-def]
    from physbench.plugins import reset_registry

    (tmp_path / "pb_quitter.py").write_text("import sys\nsys.exit(0)\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setenv("PHYSBENCH_PLUGINS", "pb_quitter")
    reset_registry()
    try:
        assert main(["plugins", "--json"]) == 0
        failed = json.loads(capsys.readouterr().out)["failed"]
        assert [(f["plugin"], f["error"]) for f in failed] == [("pb_quitter", "SystemExit: 0")]
        assert main(["run", "--estimator", "cmaes", *FAST]) == 0
    finally:
        reset_registry()
        sys.modules.pop("pb_quitter", None)


# ------------------------------------------------ issue 28: failures shown where they matter


@pytest.fixture
def fresh_registry(monkeypatch: pytest.MonkeyPatch):  # type: ignore[no-untyped-def]
    """Rebuild the registry for the environment a test sets, and after it."""
    from physbench.plugins import reset_registry

    reset_registry()
    yield monkeypatch
    reset_registry()


def test_an_unknown_name_says_which_plugin_failed_to_load_and_why(
    capsys: pytest.CaptureFixture[str], fresh_registry: pytest.MonkeyPatch
) -> None:
    """``PHYSBENCH_PLUGINS=badsq physbench run --renderer badsq`` said only "unknown renderer"."""
    fresh_registry.setenv("PHYSBENCH_PLUGINS", "badsq")
    assert main(["run", "--renderer", "badsq", "--iterations", "1"]) == 2
    err = capsys.readouterr().err
    assert "unknown renderer 'badsq'; known renderers: camera, raster" in err
    assert (
        "1 plugin failed to load and may have provided it: badsq (named in PHYSBENCH_PLUGINS): "
        "ModuleNotFoundError: No module named 'badsq' (see `physbench plugins`)"
    ) in err


def test_no_failure_no_hint(
    capsys: pytest.CaptureFixture[str], fresh_registry: pytest.MonkeyPatch
) -> None:
    fresh_registry.delenv("PHYSBENCH_PLUGINS", raising=False)
    assert main(["run", "--renderer", "badsq", "--iterations", "1"]) == 2
    assert "failed to load" not in capsys.readouterr().err


SHADOW = """
from physbench.hookspecs import hookimpl
from physbench.render.raster import RasterRenderer

class Shadow(RasterRenderer):
    name = "raster"

@hookimpl
def register_renderers():
    return [Shadow]
"""


def test_a_plugin_shadowed_by_a_builtin_is_named_once_in_run(
    capsys: pytest.CaptureFixture[str],
    plugin,  # type: ignore[no-untyped-def]
) -> None:
    """A plugin's renderer called ``raster`` was silently ignored by ``run``."""
    plugin("pb_shadow", SHADOW)
    assert main(["run", "--iterations", "2", "--resolution", "16", "--estimator", "random"]) == 0
    warned = [line for line in capsys.readouterr().err.splitlines() if "warning" in line]
    assert warned == [
        "physbench run: warning: renderer 'raster' is physbench's own; the one of plugin "
        "'pb_shadow' (PHYSBENCH_PLUGINS -) is ignored: rename it in that package or uninstall it"
    ]


@pytest.mark.parametrize("json_flag", [[], ["--json"]])
def test_plugins_check_fails_on_a_failed_plugin_or_a_conflict(
    capsys: pytest.CaptureFixture[str],
    fresh_registry: pytest.MonkeyPatch,
    plugin,  # type: ignore[no-untyped-def]
    json_flag: list[str],
) -> None:
    fresh_registry.delenv("PHYSBENCH_PLUGINS", raising=False)
    assert main(["plugins", "--check", *json_flag]) == 0  # built-ins alone pass
    capsys.readouterr()
    fresh_registry.setenv("PHYSBENCH_PLUGINS", "badsq")
    from physbench.plugins import reset_registry

    reset_registry()
    assert main(["plugins", *json_flag]) == 0  # a listing without --check
    assert main(["plugins", "--check", *json_flag]) == 1
    err = capsys.readouterr().err
    assert "physbench plugins: check failed: 1 plugin failed to load, 0 name conflicts" in err
    plugin("pb_shadow", SHADOW)  # a conflict alone, with no failure
    assert main(["plugins", "--check", *json_flag]) == 1
    assert "0 plugins failed to load, 1 name conflict" in capsys.readouterr().err

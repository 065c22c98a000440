"""Plugin discovery through real entry points: a throwaway distribution is written to a temp
folder on sys.path, exactly as pip would install one."""

from __future__ import annotations

import importlib
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from physbench import hookspecs
from physbench.errors import PluginError, UnknownNameError
from physbench.kinds import KINDS
from physbench.plugins import build_registry

GOOD = """
from physbench.estimators.base import CorrectionEstimator
from physbench.hookspecs import hookimpl

class EchoEstimator(CorrectionEstimator):
    name = "echo_{tag}"
    def start(self, task, *, seed):
        self.initial = task.initial
    def propose(self, step):
        return dict(step.params)

@hookimpl
def register_estimators():
    return [EchoEstimator]
"""


def make_dist(
    root: Path, dist: str, version: str, entry_points: dict[str, str], modules: dict[str, str]
) -> None:
    """Write an installed-looking distribution (dist-info + modules) under ``root``."""
    info = root / f"{dist.replace('-', '_')}-{version}.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {dist}\nVersion: {version}\n")
    eps = "\n".join(f"{k} = {v}" for k, v in entry_points.items())
    (info / "entry_points.txt").write_text(f"[physbench]\n{eps}\n")
    for name, src in modules.items():
        (root / f"{name}.py").write_text(textwrap.dedent(src))


@pytest.fixture
def site(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.syspath_prepend(str(tmp_path))
    importlib.invalidate_caches()
    yield tmp_path
    for mod in list(sys.modules):
        if mod.startswith("pbtest_"):
            del sys.modules[mod]


def test_builtins_register_through_entry_points() -> None:
    reg = build_registry(env=False)
    assert not reg.failed, reg.failed
    assert not reg.conflicts, reg.conflicts
    assert {"pymunk", "box2d"} <= set(reg.names("simulator"))
    assert "raster" in reg.names("renderer")
    assert {
        "three_circles",
        "second_order",
        "stacked_boxes",
        "bouncing_balls",
        "pendulum",
        "ball_drop",
    } <= set(reg.names("scene"))
    info = reg.info("simulator", "pymunk")
    assert info.package == "physbench" and info.plugin == "pymunk"


def test_third_party_plugin_is_discovered_with_its_package(site: Path) -> None:
    make_dist(
        site,
        "pbtest-good",
        "1.2.3",
        {"good": "pbtest_good"},
        {"pbtest_good": GOOD.format(tag="good")},
    )
    reg = build_registry(env=False)
    comp = reg.info("estimator", "echo_good")
    assert (comp.package, comp.version, comp.plugin) == ("pbtest-good", "1.2.3", "good")
    assert comp.obj.__name__ == "EchoEstimator"


def test_plugin_failing_to_import_is_reported_and_skipped(site: Path) -> None:
    make_dist(
        site,
        "pbtest-broken",
        "0.1",
        {"broken": "pbtest_broken"},
        {"pbtest_broken": "raise RuntimeError('boom at import')\n"},
    )
    make_dist(
        site, "pbtest-good", "1.0", {"good": "pbtest_good"}, {"pbtest_good": GOOD.format(tag="ok")}
    )
    reg = build_registry(env=False)
    failed = {f.plugin: f for f in reg.failed}
    assert "broken" in failed
    assert failed["broken"].package == "pbtest-broken"
    assert "boom at import" in failed["broken"].error
    assert "echo_ok" in reg.names("estimator")  # the rest still loads
    assert "pymunk" in reg.names("simulator")


def test_hook_that_matches_no_spec_is_reported(site: Path) -> None:
    src = (
        "from physbench.hookspecs import hookimpl\n"
        "@hookimpl\ndef register_simulator():\n    return []\n"
    )
    make_dist(site, "pbtest-typo", "0.1", {"typo": "pbtest_typo"}, {"pbtest_typo": src})
    reg = build_registry(env=False)
    err = {f.plugin: f.error for f in reg.failed}["typo"]
    assert "register_simulator" in err


def test_hook_that_raises_is_reported(site: Path) -> None:
    src = (
        "from physbench.hookspecs import hookimpl\n"
        "@hookimpl\ndef register_estimators():\n    raise ValueError('bad hook')\n"
    )
    make_dist(site, "pbtest-raise", "0.1", {"raiser": "pbtest_raise"}, {"pbtest_raise": src})
    reg = build_registry(env=False)
    assert "bad hook" in {f.plugin: f.error for f in reg.failed}["raiser"]


def test_a_component_outside_its_contract_is_reported_and_skipped(site: Path) -> None:
    src = GOOD.format(tag="duck").replace("(CorrectionEstimator)", "")
    make_dist(site, "pbtest-duck", "0.1", {"duck": "pbtest_duck"}, {"pbtest_duck": src})
    reg = build_registry(env=False)
    err = {f.plugin: f.error for f in reg.failed}["duck"]
    assert "does not subclass physbench.estimators.base.CorrectionEstimator" in err
    assert "echo_duck" not in reg.names("estimator")


DUP_PYMUNK = (
    "from physbench.hookspecs import hookimpl\nfrom physbench.simulators.base import "
    "Simulator\n"
    "class S(Simulator):\n    name = 'pymunk'\n@hookimpl\ndef register_simulators():\n    "
    "return [S]\n"
)


def test_a_third_party_claiming_a_builtin_name_is_a_conflict_and_the_builtin_is_kept(
    site: Path,
) -> None:
    make_dist(site, "pbtest-dup", "0.1", {"dup": "pbtest_dup"}, {"pbtest_dup": DUP_PYMUNK})
    reg = build_registry(env=False)
    assert reg.info("simulator", "pymunk").package == "physbench"
    (conflict,) = reg.conflicts
    assert conflict.kept is not None and conflict.kept.package == "physbench"
    assert [(c.plugin, c.package, c.version) for c in conflict.ignored] == [
        ("dup", "pbtest-dup", "0.1")
    ]
    assert "simulator 'pymunk' is physbench's own" in conflict.describe()
    assert "plugin 'dup' (pbtest-dup 0.1) is ignored" in conflict.describe()


def test_third_parties_sharing_a_name_are_all_refused(site: Path) -> None:
    for tag in ("one", "two"):
        make_dist(
            site,
            f"pbtest-{tag}",
            "1.0",
            {tag: f"pbtest_{tag}"},
            {f"pbtest_{tag}": GOOD.format(tag="twin")},
        )
    reg = build_registry(env=False)
    assert "echo_twin" not in reg.names("estimator")
    (conflict,) = reg.conflicts
    assert conflict.kept is None
    assert sorted(c.package for c in conflict.ignored) == ["pbtest-one", "pbtest-two"]
    with pytest.raises(PluginError, match=r"estimator 'echo_twin' is provided by .*none of them"):
        reg.get("estimator", "echo_twin")


def test_registry_add_still_refuses_a_taken_name() -> None:
    reg = build_registry(env=False)
    with pytest.raises(PluginError, match=r"duplicate simulator name 'pymunk'"):
        reg.add(reg.info("simulator", "pymunk"))


def test_sys_exit_at_import_or_in_a_hook_is_a_failed_plugin(site: Path) -> None:
    hook = (
        "import sys\nfrom physbench.hookspecs import hookimpl\n"
        "@hookimpl\ndef register_scenes():\n    sys.exit('no scenes today')\n"
    )
    make_dist(site, "pbtest-quit", "0.1", {"quit": "pbtest_quit"}, {"pbtest_quit": "exit(4)\n"})
    make_dist(site, "pbtest-hook", "0.1", {"hook": "pbtest_hook"}, {"pbtest_hook": hook})
    reg = build_registry(env=False)
    errors = {f.plugin: (f.package, f.error) for f in reg.failed}
    assert errors["quit"] == ("pbtest-quit", "SystemExit: 4")
    assert errors["hook"] == ("pbtest-hook", "register_scenes raised SystemExit: no scenes today")
    assert "three_circles" in reg.names("scene")


def test_what_an_installed_plugin_raises_names_its_distribution(
    site: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from physbench.cli import main
    from physbench.plugins import reset_registry

    src = GOOD.format(tag="boom").replace("return dict(step.params)", "raise OSError('disk')")
    make_dist(site, "pbtest-boom", "0.3", {"boomer": "pbtest_boom"}, {"pbtest_boom": src})
    reset_registry()
    try:
        assert main(["run", "--estimator", "echo_boom", "--iterations", "1", "-q"]) == 2
    finally:
        reset_registry()
    assert capsys.readouterr().err.startswith(
        "physbench run: error: estimator 'echo_boom' of plugin 'boomer' (pbtest-boom 0.3) failed "
        "in propose(): OSError: disk"
    )


def test_explicit_module_fallback_via_environment(
    site: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (site / "pbtest_env.py").write_text(textwrap.dedent(GOOD.format(tag="env")))
    monkeypatch.setenv("PHYSBENCH_PLUGINS", "pbtest_env, pbtest_missing_module")
    reg = build_registry()
    assert reg.info("estimator", "echo_env").package == "PHYSBENCH_PLUGINS"
    assert any(f.plugin == "pbtest_missing_module" for f in reg.failed)


def test_unknown_name_lists_known_ones() -> None:
    reg = build_registry(env=False)
    with pytest.raises(
        UnknownNameError, match="unknown simulator 'bullet'; known simulators: box2d, pymunk"
    ):
        reg.get("simulator", "bullet")


def test_every_hookspec_is_documented_and_mapped_to_a_kind() -> None:
    specs = [n for n in dir(hookspecs) if n.startswith("register_")]
    assert sorted(specs) == sorted(k.hook for k in KINDS)
    for name in specs:
        doc = getattr(hookspecs, name).__doc__ or ""
        assert "Called" in doc, f"hookspec {name} must say when it is called"


def test_plugins_command_lists_components_and_failures(site: Path) -> None:
    make_dist(
        site,
        "pbtest-broken",
        "0.1",
        {"broken": "pbtest_broken"},
        {"pbtest_broken": "import not_a_module_xyz\n"},
    )
    out = subprocess.run(
        [sys.executable, "-m", "physbench.cli", "plugins"],
        capture_output=True,
        text=True,
        check=True,
        env={**__import__("os").environ, "PYTHONPATH": str(site)},
    ).stdout
    assert "simulator  pymunk" in out and "physbench" in out
    assert "Failed to load" in out and "pbtest-broken" in out and "not_a_module_xyz" in out

"""Run settings as data: the round trip, old settings, fail-fast checks, and one run."""

from __future__ import annotations

import pytest

from physbench.errors import PhysbenchError
from physbench.experiment import RunConfig, check_config, config_space, run_config


def test_settings_round_trip_and_old_settings_take_the_defaults() -> None:
    config = RunConfig(
        params=("mass", "elasticity"),
        options={"startup": 3},
        renderer_options={"x": 1},
        bodies=("a",),
    )
    assert RunConfig.from_dict(config.to_dict()) == config
    old = config.to_dict()
    del old["renderer"], old["renderer_options"]  # settings written before the renderer axis
    back = RunConfig.from_dict(old)
    assert back.renderer == "raster" and back.renderer_options == {}
    with pytest.raises(PhysbenchError, match=r"unknown keys \['colour'\]"):
        RunConfig.from_dict({**config.to_dict(), "colour": "red"})


def test_checks_fail_fast_naming_the_bad_choice() -> None:
    assert config_space(RunConfig()).keys == ("a.mass", "b.mass")
    assert check_config(RunConfig(params=("elasticity",))).keys == ("a.elasticity", "b.elasticity")
    for bad, message in [
        (RunConfig(engine="ode"), "unknown simulator 'ode'"),
        (RunConfig(estimator="nope"), "unknown estimator 'nope'"),
        (RunConfig(options={"startup": -1}), "startup = -1"),
        (RunConfig(renderer="nope"), "unknown renderer 'nope'"),
        (RunConfig(render_mode="rgb"), "supports modes"),
        (RunConfig(params=("volume",)), "unknown parameter 'volume'"),
        (RunConfig(observation="x.npz", blur=1.0), "cannot apply to --observation frames"),
    ]:
        with pytest.raises(PhysbenchError, match=message):
            check_config(bad)


def test_a_run_is_a_pure_function_of_its_settings() -> None:
    config = RunConfig(estimator="random", iterations=3, resolution=32, blur=1.0, noise=0.01)
    a, b = run_config(config), run_config(config)
    assert a.to_dict(timings=False) == b.to_dict(timings=False)
    assert a.meta["renderer"] == "raster" and a.meta["blur"] == 1.0
    sharp = run_config(RunConfig(estimator="random", iterations=3, resolution=32))
    assert [r.params for r in sharp.iterations] == [r.params for r in a.iterations]
    assert [r.loss for r in sharp.iterations] != [r.loss for r in a.iterations]

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


def test_effects_are_run_settings_that_leave_earlier_cell_keys_alone() -> None:
    from physbench.bench.spec import config_key

    plain = RunConfig(params=("mass",))
    assert "effects" not in plain.to_dict()  # so every earlier sweep's cell keys stay valid
    assert config_key(plain) == config_key(RunConfig.from_dict(plain.to_dict()))
    drag = RunConfig(params=("mass", "linear_drag.c=0:50"), effects=("linear_drag:c=0.2",))
    assert drag.to_dict()["effects"] == ["linear_drag:c=0.2"]
    assert RunConfig.from_dict(drag.to_dict()) == drag
    assert config_key(drag) != config_key(plain)


def test_an_effect_given_a_wider_range_accepts_it_and_bad_effects_are_named() -> None:
    from physbench.experiment import config_effects

    config = RunConfig(params=("linear_drag.c=0:50", "gravity"), effects=("linear_drag:c=0.2",))
    effects = config_effects(config)
    space = config_space(config, None, effects)
    assert space.keys == ("linear_drag.c", "gravity")
    assert effects[0].declared["c"].high == 50.0 and effects[0].values["c"] == 0.2
    effects[0].setup(space_scene(), {"c": 40.0})  # inside the widened range: accepted
    for bad, message in [
        (RunConfig(effects=("drag",)), "unknown effect 'drag'"),
        (RunConfig(effects=("linear_drag:c",)), r"--effect 'linear_drag:c': expected NAME\[:KEY"),
        (RunConfig(params=("linear_drag.c",)), "unknown parameter 'linear_drag.c'"),
        (
            RunConfig(params=("gravity",), observer="camera"),
            None,  # gravity is the scene's own physics: an observer films it
        ),
        (
            RunConfig(params=("camera.scale",), observer="camera"),
            "an observer camera films the scene's own physics with its true calibration; it "
            "cannot show camera.scale",
        ),
    ]:
        if message is None:
            check_config(bad)
            continue
        with pytest.raises(PhysbenchError, match=message):
            check_config(bad)


def space_scene():  # type: ignore[no-untyped-def]
    from physbench.scenes import resolve_scene

    return resolve_scene("three_circles", 0)


def test_a_simulated_observation_is_seen_as_the_model_sees_its_truth() -> None:
    from physbench.components import create
    from physbench.experiment import config_effects, make_observation, model_renderer
    from physbench.loop import draw_problem, image_objective

    config = RunConfig(
        params=("gravity", "camera.scale", "camera.clock", "linear_drag.c=0:2"),
        effects=("linear_drag",),
        resolution=32,
    )
    scene, effects = space_scene(), config_effects(config)
    space = config_space(config, scene, effects)
    truth, _ = draw_problem(space, 0)
    renderer = model_renderer(config)
    obs = make_observation(config, scene, truth, (), renderer, effects)
    assert obs.truth == truth and obs.scene.gravity == (0.0, truth["gravity"])
    assert "LinearDrag" in obs.effects[0]
    sim = create("simulator", "pymunk")
    loss = image_objective(obs, scene, space, sim, renderer, per_object=False, effects=effects)
    assert loss(truth).loss == 0.0
    for key in truth:  # each value shows: 2 % of its range away is another picture
        moved = dict(truth)
        u = next(u for u in space.unknowns if u.key == key)
        moved[key] += 0.02 * (u.high - u.low) * (1 if truth[key] < u.high - u.width / 2 else -1)
        assert loss(moved).loss > 0.0, key

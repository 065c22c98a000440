"""The observation model (blur, then noise, of observed frames of any renderer) and its image
filters."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.render.base import RenderError
from physbench.render.raster import RasterRenderer
from physbench.render.sensor import SensorModel, add_noise, gaussian_blur
from physbench.scene import Body, Circle, Scene
from physbench.trajectory import Trajectory


def test_blur_acts_on_image_axes_only() -> None:
    frames = np.zeros((3, 2, 16, 16), np.float32)
    frames[1, 0, 8, 8] = 1.0
    out = gaussian_blur(frames, 1.0)
    assert not out[0].any() and not out[2].any() and not out[1, 1].any()
    assert out[1, 0].sum() == pytest.approx(1.0, rel=1e-5)


def test_noise_is_clipped_float32_and_seeded() -> None:
    clean = np.full((2, 1, 8, 8), 0.5, np.float32)
    a = add_noise(clean, 0.1, np.random.default_rng(3))
    b = add_noise(clean, 0.1, np.random.default_rng(3))
    assert a.dtype == np.float32 and a.shape == clean.shape and 0 <= a.min() <= a.max() <= 1
    np.testing.assert_array_equal(a, b)
    assert 0.005 < float(((a - clean) ** 2).mean()) < 0.02
    assert np.array_equal(add_noise(clean, 0.0, np.random.default_rng(3)), clean)


@pytest.mark.parametrize(
    "fn", [lambda f: gaussian_blur(f, -1.0), lambda f: add_noise(f, -1.0, None)]
)
def test_negative_sigma_is_refused(fn) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(ValueError, match="expected a number >= 0"):
        fn(np.zeros((1, 1, 4, 4), np.float32))


def make_scene(*bodies: Body) -> Scene:
    return Scene(name="t", bodies=bodies, bounds=(0.0, 0.0, 4.0, 4.0), test_body=bodies[0].name)


def still(scene: Scene) -> Trajectory:
    states = np.zeros((1, len(scene.bodies), 6))
    for i, b in enumerate(scene.bodies):
        states[0, i, :3] = (*b.position, b.angle)
    return Trajectory(scene.body_names, np.zeros(1), states)


def test_blur_preserves_the_mass_of_a_centred_body() -> None:
    scene = make_scene(Body("c", Circle(0.4), (2.0, 2.0)))
    sharp = RasterRenderer(mode="mask").render(scene, still(scene))
    blurred = SensorModel(blur=2.0).apply(sharp.copy())
    assert blurred.sum() == pytest.approx(sharp.sum(), rel=1e-4)
    assert blurred.max() < sharp.max() and (blurred > 0).sum() > (sharp > 0).sum()
    np.testing.assert_allclose(gaussian_blur(sharp, 2.0), blurred)


def test_noise_is_a_pure_function_of_the_seed() -> None:
    scene = make_scene(Body("test", Circle(0.3), (0.8, 2.5)), Body("a", Circle(0.3), (2.0, 1.0)))
    clean = RasterRenderer().render(scene, still(scene), focus="a")
    model = SensorModel(noise=0.1, seed=3)
    a, b = model.apply(clean.copy()), model.apply(clean.copy())
    c = SensorModel(noise=0.1, seed=4).apply(clean.copy())
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)
    assert a.min() >= 0 and a.max() <= 1 and a.dtype == np.float32
    assert 0.002 < float(((a - clean) ** 2).mean()) < 0.01
    assert SensorModel().identity and SensorModel().apply(clean) is clean


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"blur": -1.0}, "blur = -1.0"),
        ({"noise": float("nan")}, "noise = nan"),
        ({"seed": "x"}, "seed = 'x'"),
    ],
)
def test_bad_observation_models_are_refused(kwargs: dict[str, object], match: str) -> None:
    with pytest.raises(RenderError, match=match):
        SensorModel(**kwargs)  # type: ignore[arg-type]

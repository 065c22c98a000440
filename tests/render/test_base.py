"""The renderer contract's defaults (resolution and mode checks, ``shape`` from a still) and the
observation model (blur, noise) that the framework applies to observed frames of any renderer."""

from __future__ import annotations

from typing import ClassVar

import numpy as np
import pytest

from physbench.render.base import (
    MODES,
    ObservationModel,
    Renderer,
    RenderError,
    check_resolution,
)
from physbench.render.observe import gaussian_blur
from physbench.render.raster import RasterRenderer
from physbench.scene import Body, Box, Circle, Scene
from physbench.trajectory import Trajectory


def make_scene(*bodies: Body) -> Scene:
    return Scene(name="t", bodies=bodies, bounds=(0.0, 0.0, 4.0, 4.0), test_body=bodies[0].name)


def still(scene: Scene) -> Trajectory:
    states = np.zeros((1, len(scene.bodies), 6))
    for i, b in enumerate(scene.bodies):
        states[0, i, :3] = (*b.position, b.angle)
    return Trajectory(scene.body_names, np.zeros(1), states)


class Dots(Renderer):
    """A renderer without its own ``shape``: one channel, a dot per body."""

    name: ClassVar[str] = "dots"
    modes: ClassVar[tuple[str, ...]] = ("mask",)

    def render(self, scene, traj, *, focus=None, out=None):  # type: ignore[no-untyped-def]
        n = int(self.resolution)  # type: ignore[arg-type]
        frames = np.zeros((traj.frames, 1, n // 2, n), np.float32)
        frames[:, 0, 0, : len(traj.bodies)] = 1.0
        return frames


def test_shape_defaults_to_a_rendered_still() -> None:
    scene = make_scene(Body("a", Circle(0.3), (1.0, 1.0)), Body("b", Box(0.4, 0.2), (2.0, 1.0)))
    assert Dots(resolution=10, mode="mask").shape(scene) == (scene.frames, 1, 5, 10)
    assert Dots(resolution=10, mode="mask").shape(scene, frames=3) == (3, 1, 5, 10)


def test_modes_and_resolution_are_checked_for_every_renderer() -> None:
    assert MODES == ("mark", "instance", "mask")
    with pytest.raises(RenderError, match="renderer 'dots' supports modes mask"):
        Dots(mode="mark")
    assert check_resolution(32) == 32 and check_resolution([48, 64]) == (48, 64)
    for bad in (0, True, 2.5, (64,), "64"):
        with pytest.raises(RenderError, match="resolution = "):
            check_resolution(bad)


def test_blur_preserves_the_mass_of_a_centred_body() -> None:
    scene = make_scene(Body("c", Circle(0.4), (2.0, 2.0)))
    sharp = RasterRenderer(mode="mask").render(scene, still(scene))
    blurred = ObservationModel(blur=2.0).apply(sharp.copy())
    assert blurred.sum() == pytest.approx(sharp.sum(), rel=1e-4)
    assert blurred.max() < sharp.max() and (blurred > 0).sum() > (sharp > 0).sum()
    np.testing.assert_allclose(gaussian_blur(sharp, 2.0), blurred)


def test_noise_is_a_pure_function_of_the_seed() -> None:
    scene = make_scene(Body("test", Circle(0.3), (0.8, 2.5)), Body("a", Circle(0.3), (2.0, 1.0)))
    clean = RasterRenderer().render(scene, still(scene), focus="a")
    model = ObservationModel(noise=0.1, seed=3)
    a, b = model.apply(clean.copy()), model.apply(clean.copy())
    c = ObservationModel(noise=0.1, seed=4).apply(clean.copy())
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)
    assert a.min() >= 0 and a.max() <= 1 and a.dtype == np.float32
    assert 0.002 < float(((a - clean) ** 2).mean()) < 0.01
    assert ObservationModel().identity and ObservationModel().apply(clean) is clean


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
        ObservationModel(**kwargs)  # type: ignore[arg-type]

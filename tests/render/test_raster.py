"""The raster renderer on hand-made trajectories (no engine): shapes, coverage, modes, speed
caches and clear errors."""

from __future__ import annotations

import math
import pickle

import numpy as np
import pytest

from physbench.errors import PhysbenchError, UnknownNameError
from physbench.render.raster import RasterRenderer, RenderError, register_renderers
from physbench.scene import Body, Box, Circle, Polygon, Scene, Segment
from physbench.trajectory import Trajectory

BOUNDS = (0.0, 0.0, 4.0, 4.0)
PX = 4.0 / 64  # world size of one pixel at the default resolution


def make_scene(*bodies: Body, bounds: tuple[float, float, float, float] = BOUNDS) -> Scene:
    return Scene(
        name="t",
        bodies=bodies,
        bounds=bounds,
        statics=(Segment((0, 0), (4, 0)),),
        test_body=bodies[0].name,
    )


def traj_of(scene: Scene, poses: np.ndarray) -> Trajectory:
    """``poses (T, N, 3)`` of x, y, angle -> a trajectory (velocities zero)."""
    poses = np.asarray(poses, dtype=float)
    states = np.zeros((*poses.shape[:2], 6))
    states[:, :, :3] = poses
    return Trajectory(scene.body_names, np.arange(len(poses)) / scene.fps, states)


def still(scene: Scene, frames: int = 1) -> Trajectory:
    pose = [(*b.position, b.angle) for b in scene.bodies]
    return traj_of(scene, np.repeat(np.asarray(pose, dtype=float)[None], frames, axis=0))


@pytest.fixture
def three() -> Scene:
    return make_scene(
        Body("test", Circle(0.3), (0.8, 2.5)),
        Body("a", Box(0.6, 0.4), (2.0, 1.0), angle=0.3),
        Body("b", Polygon(((0.0, 0.4), (-0.35, -0.2), (0.35, -0.2))), (2.5, 1.2)),
    )


def moving(scene: Scene, frames: int = 12) -> Trajectory:
    t = np.linspace(0, 1, frames)[:, None]
    x0 = np.array([b.position[0] for b in scene.bodies])
    y0 = np.array([b.position[1] for b in scene.bodies])
    poses = np.stack([x0 + 0.8 * t, y0 + 0.3 * np.sin(3 * t), 2.0 * t + np.zeros_like(x0)], axis=-1)
    return traj_of(scene, poses)


# ------------------------------------------------------------------ shape, dtype, range, modes


@pytest.mark.parametrize(("mode", "channels"), [("mark", 2), ("instance", 3), ("mask", 1)])
def test_shape_dtype_range(three: Scene, mode: str, channels: int) -> None:
    r = RasterRenderer(mode=mode)
    traj = moving(three)
    f = r.render(three, traj, focus="a")
    assert f.shape == (12, channels, 64, 64) == r.shape(three, 12)
    assert r.channels(three) == channels
    assert f.dtype == np.float32
    assert f.min() >= 0.0 and f.max() <= 1.0
    assert f.max() == 1.0  # interiors are fully covered
    # Anti-aliased: edge pixels take values strictly between 0 and 1.
    assert ((f > 0.05) & (f < 0.95)).any()


def test_resolution_sets_square_pixels() -> None:
    wide = make_scene(Body("c", Circle(0.3), (1.0, 1.0)), bounds=(0.0, 0.0, 8.0, 2.0))
    r = RasterRenderer(resolution=80)
    assert r.image_size(wide) == (20, 80)
    f = r.render(wide, still(wide))
    assert f.shape == (1, 2, 20, 80)
    assert f[0, 0].sum() == pytest.approx(math.pi * 0.3**2 / 0.1**2, rel=0.02)


def test_tuple_resolution_non_square_pixels() -> None:
    scene = make_scene(Body("c", Box(1.0, 1.0), (2.0, 2.0)))
    f = RasterRenderer(resolution=(40, 80), mode="mask").render(scene, still(scene))
    assert f.shape == (1, 1, 40, 80)
    assert f.sum() == pytest.approx(1.0 / (0.1 * 0.05), rel=0.02)


def test_y_up_row_zero_is_top() -> None:
    scene = make_scene(Body("c", Circle(0.2), (0.5, 3.5)))
    f = RasterRenderer(mode="mask").render(scene, still(scene))[0, 0]
    rows, cols = np.nonzero(f > 0.5)
    assert rows.mean() == pytest.approx((4.0 - 3.5) / PX - 0.5, abs=0.1)
    assert cols.mean() == pytest.approx(0.5 / PX - 0.5, abs=0.1)


# ------------------------------------------------------------------ coverage = area


@pytest.mark.parametrize("r", [0.1, 0.3, 0.77])
@pytest.mark.parametrize("offset", [(0.0, 0.0), (0.013, 0.041), (0.031, -0.02)])
def test_circle_coverage_is_area(r: float, offset: tuple[float, float]) -> None:
    scene = make_scene(Body("c", Circle(r), (2.0 + offset[0], 2.0 + offset[1])))
    f = RasterRenderer(mode="mask").render(scene, still(scene))
    assert f.sum() == pytest.approx(math.pi * r**2 / PX**2, rel=0.02)


@pytest.mark.parametrize("angle", [0.0, 0.3, math.pi / 4, 1.0, 2.5, -0.7])
def test_box_coverage_is_area(angle: float) -> None:
    scene = make_scene(Body("b", Box(0.9, 0.35), (2.02, 1.97), angle=angle))
    f = RasterRenderer(mode="mask").render(scene, still(scene))
    assert f.sum() == pytest.approx(0.9 * 0.35 / PX**2, rel=0.02)


def test_polygon_coverage_is_area() -> None:
    tri = Polygon(((0.0, 0.5), (-0.4, -0.25), (0.45, -0.3)))
    scene = make_scene(Body("p", tri, (2.0, 2.0), angle=0.4))
    f = RasterRenderer(mode="mask").render(scene, still(scene))
    assert f.sum() == pytest.approx(tri.area() / PX**2, rel=0.02)


def test_rotation_by_quarter_turn_swaps_box_sides() -> None:
    turned = make_scene(Body("b", Box(1.0, 0.5), (2.0, 2.0), angle=math.pi / 2))
    upright = make_scene(Body("b", Box(0.5, 1.0), (2.0, 2.0)))
    r = RasterRenderer(mode="mask")
    np.testing.assert_allclose(
        r.render(turned, still(turned)), r.render(upright, still(upright)), atol=1e-4
    )


# ------------------------------------------------------------------ smoothness


@pytest.mark.parametrize("shape", [Circle(0.3), Box(0.6, 0.4)])
def test_subpixel_motion_changes_loss_smoothly(shape: Circle | Box) -> None:
    scene = make_scene(Body("o", shape, (2.0, 2.0), angle=0.2))
    r = RasterRenderer(mode="mask")
    ref = r.render(scene, still(scene))
    shifts = np.linspace(0.1, 1.0, 10) * PX
    poses = np.array([[[2.0 + s, 2.0 + 0.5 * s, 0.2]] for s in shifts])
    frames = r.render(scene, traj_of(scene, poses))
    mse = ((frames - ref) ** 2).mean(axis=(1, 2, 3))
    assert mse[0] > 0
    assert np.all(np.diff(mse) > 0), mse
    # Piecewise constant masks would give equal losses for several shifts; coverage gives a
    # quadratic-ish rise for sub-pixel motion.
    assert mse[4] / mse[0] > 4


# ------------------------------------------------------------------ channels


def test_channels_are_consistent(three: Scene) -> None:
    traj = moving(three)
    inst = RasterRenderer(mode="instance").render(three, traj)
    mask = RasterRenderer(mode="mask").render(three, traj)
    mark = RasterRenderer(mode="mark").render(three, traj, focus="a")
    np.testing.assert_array_equal(mask[:, 0], inst.max(axis=1))
    np.testing.assert_array_equal(mark[:, 1], inst[:, 1])
    np.testing.assert_array_equal(mark[:, 0], np.maximum(inst[:, 0], inst[:, 2]))
    np.testing.assert_array_equal(mark.max(axis=1), mask[:, 0])
    unmarked = RasterRenderer(mode="mark").render(three, traj)
    assert not unmarked[:, 1].any()
    np.testing.assert_array_equal(unmarked[:, 0], mask[:, 0])


def test_each_body_renders_as_it_does_alone() -> None:
    # Bodies of similar size are rasterised together; that must not mix up their parameters.
    bodies = (
        Body("c1", Circle(0.30), (1.0, 1.0)),
        Body("c2", Circle(0.31), (2.0, 1.0)),
        Body("k1", Box(0.5, 0.3), (1.0, 2.5), angle=0.4),
        Body("k2", Box(0.32, 0.48), (2.2, 2.5), angle=-1.1),
        Body("p", Polygon(((0.0, 0.4), (-0.35, -0.2), (0.35, -0.2))), (3.2, 3.0), angle=2.0),
    )
    scene = make_scene(*bodies)
    traj = moving(scene, frames=4)
    together = RasterRenderer(mode="instance").render(scene, traj)
    for i, b in enumerate(bodies):
        alone = make_scene(b)
        single = traj_of(alone, traj.states[:, i : i + 1, :3])
        np.testing.assert_array_equal(
            together[:, i], RasterRenderer(mode="mask").render(alone, single)[:, 0]
        )
    mark = RasterRenderer(mode="mark").render(scene, traj, focus="c2")
    np.testing.assert_array_equal(mark[:, 1], together[:, 1])
    np.testing.assert_array_equal(mark[:, 0], together[:, [0, 2, 3, 4]].max(axis=1))


def test_overlapping_bodies_combine_with_max() -> None:
    scene = make_scene(Body("a", Circle(0.4), (2.0, 2.0)), Body("b", Circle(0.4), (2.3, 2.0)))
    mask = RasterRenderer(mode="mask").render(scene, still(scene))
    assert mask.max() == 1.0
    single = make_scene(Body("a", Circle(0.4), (2.0, 2.0)))
    one = RasterRenderer(mode="mask").render(single, still(single)).sum()
    assert one < mask.sum() < 2 * one


def test_static_geometry_is_not_drawn() -> None:
    scene = make_scene(Body("c", Circle(0.3), (2.0, 2.0)))
    f = RasterRenderer(mode="mask").render(scene, still(scene))
    assert not f[0, 0, -1].any()  # the floor segment lies on the bottom row's edge


# ------------------------------------------------------------------ borders, buffers


def test_bodies_outside_the_image_are_clipped() -> None:
    scene = make_scene(Body("c", Circle(0.5), (2.0, 2.0)), Body("d", Box(0.6, 0.6), (2.0, 2.0)))
    area = math.pi * 0.25 / PX**2
    poses = np.array(
        [
            [[0.0, 2.0, 0.0], [4.0, 4.0, 0.3]],  # centred on the left edge; box on a corner
            [[2.0, -0.1, 0.0], [9.0, 2.0, 0.0]],  # mostly below the floor; box far right
            [[-7.0, -3.0, 0.0], [2.0, 50.0, 0.0]],  # both far away
        ]
    )
    f = RasterRenderer(mode="instance").render(scene, traj_of(scene, poses))
    assert f[0, 0].sum() == pytest.approx(area / 2, rel=0.03)
    assert f[0, 1].sum() == pytest.approx(0.36 / PX**2 / 4, rel=0.1)
    assert 0 < f[1, 0].sum() < area / 2
    assert not f[1, 1].any() and not f[2].any()


def test_out_buffer_is_filled_and_results_are_fresh(three: Scene) -> None:
    r = RasterRenderer()
    t1, t2 = moving(three), still(three, frames=12)
    first = r.render(three, t1, focus="b")
    keep = first.copy()
    out = np.full(r.shape(three, 12), 7.0, np.float32)
    got = r.render(three, t2, focus="b", out=out)
    assert got is out
    np.testing.assert_array_equal(out, r.render(three, t2, focus="b"))
    again = r.render(three, t1, focus="b")
    np.testing.assert_array_equal(first, keep)  # a returned array is never reused internally
    np.testing.assert_array_equal(again, keep)  # nothing left behind by the previous renders
    assert again is not first


def test_non_contiguous_out_buffer(three: Scene) -> None:
    r = RasterRenderer()
    traj = moving(three)
    out = np.full((12, 2, 64, 128), 5.0, np.float32)[..., ::2]
    assert r.render(three, traj, out=out) is out
    np.testing.assert_array_equal(out, r.render(three, traj))


def test_blocks_larger_than_the_image_use_a_padded_buffer() -> None:
    # At 4x4 pixels a 1.2 m circle's block (7 px) is wider than the image.
    scene = make_scene(Body("c", Circle(1.2), (2.0, 2.0)), Body("d", Circle(0.4), (1.0, 1.0)))
    r = RasterRenderer(resolution=4, mode="instance")
    centred = still(scene)
    moved = traj_of(scene, [[[0.3, 3.9, 0.0], [3.5, 0.2, 0.0]]])
    first = r.render(scene, centred)
    assert r._layouts and next(iter(r._layouts.values())).buf is not None
    assert first[0, 0].sum() == pytest.approx(math.pi * 1.2**2, rel=0.05)
    np.testing.assert_array_equal(
        r.render(scene, moved), RasterRenderer(resolution=4, mode="instance").render(scene, moved)
    )
    np.testing.assert_array_equal(r.render(scene, centred), first)  # earlier blocks were cleared


def test_out_buffer_of_the_wrong_shape_is_refused(three: Scene) -> None:
    r = RasterRenderer()
    with pytest.raises(RenderError, match=r"expected \(12, 2, 64, 64\) float32"):
        r.render(three, moving(three), out=np.zeros((12, 2, 64, 63), np.float32))
    with pytest.raises(RenderError, match="float32"):
        r.render(three, moving(three), out=np.zeros((12, 2, 64, 64)))


def test_renderer_pickles_without_its_buffers(three: Scene) -> None:
    r = RasterRenderer(mode="instance")
    expected = r.render(three, moving(three))
    clone = pickle.loads(pickle.dumps(r))
    assert clone._layouts == {}
    np.testing.assert_array_equal(clone.render(three, moving(three)), expected)


# ------------------------------------------------------------------ errors


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"resolution": 0}, "resolution = 0"),
        ({"resolution": (64,)}, r"pair \(height, width\)"),
        ({"resolution": True}, "resolution = True"),
        ({"resolution": 32.5}, "resolution = 32.5"),
        ({"mode": "rgb"}, "supports modes mark, instance, mask"),
    ],
)
def test_bad_options_raise_clear_errors(kwargs: dict[str, object], match: str) -> None:
    with pytest.raises(RenderError, match=match) as info:
        RasterRenderer(**kwargs)  # type: ignore[arg-type]
    assert isinstance(info.value, PhysbenchError) and isinstance(info.value, ValueError)


def test_unknown_focus_lists_bodies(three: Scene) -> None:
    with pytest.raises(UnknownNameError, match="known bodies: a, b, test"):
        RasterRenderer().render(three, moving(three), focus="c")


def test_trajectory_for_another_scene_is_refused(three: Scene) -> None:
    other = make_scene(Body("x", Circle(0.3), (2.0, 2.0)))
    with pytest.raises(RenderError, match="do not match the scene's bodies"):
        RasterRenderer().render(three, still(other))


def test_non_finite_pose_is_refused(three: Scene) -> None:
    traj = moving(three)
    traj.states[5, 2, 1] = np.nan
    with pytest.raises(RenderError, match="body 'b' at frame 5 is not finite"):
        RasterRenderer().render(three, traj)


def test_registered_through_the_hook() -> None:
    from physbench.render.base import Renderer

    assert register_renderers() == [RasterRenderer]
    assert RasterRenderer.name == "raster"
    assert isinstance(RasterRenderer(), Renderer)

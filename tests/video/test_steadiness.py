"""Whether the camera stayed put (``physbench/video/steadiness.py``): a frame's shift against the
background, measured on textured walls in another light, and a clip whose camera was knocked
said to be one, where a steady clip says nothing."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy import ndimage

from physbench.errors import PhysbenchWarning
from physbench.scene import Body, Circle, Scene
from physbench.simulators.pymunk_sim import PymunkSimulator
from physbench.testing.field_camera import FieldCamera
from physbench.video import steadiness
from physbench.video.photometry import LightMeter
from physbench.video.spheres import expose, wall
from physbench.video.steadiness import COARSE, SEARCH, ShiftMeter
from physbench.video.track import BodyNotFoundError, TrackLostError, track_video
from physbench.video.writer import write_video


@pytest.mark.parametrize("seed", [4, 7, 9])
def test_a_frame_shifted_against_the_background_is_measured(seed: int) -> None:
    """Walls of tiles, stains and grain (three seeds), each frame 6 % brighter in red, with
    sensor noise: no shift, a fraction of a pixel and a few pixels, each within 0.12 px
    (measured at most 0.082 px)."""
    rng = np.random.default_rng(seed)
    plate = wall((240, 320), seed)
    background = expose(plate.astype(np.float64), rng, noise=0.0)
    for du, dv in [(0.0, 0.0), (0.4, -0.3), (1.5, 0.7), (-3.2, 2.6)]:
        moved = ndimage.shift(plate, (dv, du, 0), order=1, mode="nearest")
        frame = expose(moved, rng, gain=[1.06, 1.04, 0.98], noise=0.01)
        got = ShiftMeter(background).measure(frame, LightMeter(background).measure(frame))
        assert got is not None
        assert np.hypot(got.du - du, got.dv - dv) < 0.12, (du, dv, got)


def test_a_meter_anew_keeps_its_samples_and_forgets_the_clip() -> None:
    """A meter used on a clip, taken anew for another tracking, measures the next clip's frames
    as a meter just built on the same background does, and shares its samples."""
    rng = np.random.default_rng(5)
    plate = wall((240, 320), 5)
    background = expose(plate.astype(np.float64), rng, noise=0.0)

    def frame(du: float, dv: float) -> np.ndarray:
        moved = ndimage.shift(plate, (dv, du, 0), order=1, mode="nearest")
        return expose(moved, rng, gain=[1.03, 1.0, 0.97], noise=0.01)

    used = ShiftMeter(background)
    for du, dv in [(2.6, -1.4), (3.1, -1.9)]:  # leaves its walk at a shift of about 3 px
        shot = frame(du, dv)
        used.measure(shot, LightMeter(background).measure(shot))
    assert used.last != (0, 0) and np.isfinite(used.best)
    again, fresh = used.anew(), ShiftMeter(background)
    assert again.bank is used.bank and (again.best, again.last) == (np.inf, (0, 0))
    for du, dv in [(0.0, 0.0), (0.3, 0.2)]:
        shot = frame(du, dv)
        light = LightMeter(background).measure(shot)
        assert again.measure(shot, light) == fresh.measure(shot, light)


def test_a_plain_wall_shows_no_shift_and_needs_none() -> None:
    background = np.full((120, 160, 3), 100, np.uint8)
    meter = ShiftMeter(background)
    assert not meter.usable
    assert meter.measure(background, LightMeter(background).measure(background)) is None


def _numpy_residuals(  # type: ignore[no-untyped-def]
    meter: ShiftMeter, seen: np.ndarray, shifts, nth: int, clip2: np.float32
):
    """The residuals at ``shifts``, where they are read and each shift's cost, as
    :meth:`ShiftMeter.measure` computed them in NumPy before its loops were compiled."""
    du = np.array([s[0] for s in shifts])[:, None]
    dv = np.array([s[1] for s in shifts])[:, None]
    rows, cols = meter.rows[None, ::nth], meter.cols[None, ::nth]
    r = np.minimum(np.maximum(rows - dv, 0), meter.h - 1)
    c = np.minimum(np.maximum(cols - du, 0), meter.w - 1)
    where = r * meter.w + c
    e = meter.grey.take(where).astype(np.float32)
    mine = seen[::nth]
    em, sm = e.mean(axis=1, keepdims=True), mine.mean()
    de = e - em
    gain = (de * (mine - sm)).sum(axis=1, keepdims=True) / np.maximum(
        (de * de).sum(axis=1, keepdims=True), 1e-6
    )
    d = gain * de + sm - mine
    return d, where, np.minimum(d * d, clip2).mean(axis=1)


def _numpy_step(  # type: ignore[no-untyped-def]
    meter: ShiftMeter, d: np.ndarray, where: np.ndarray, seen: np.ndarray, clip2: np.float32
):
    """:meth:`ShiftMeter._between` as it was in NumPy."""
    spread = 1.4826 * float(np.median(np.abs(d)))
    ok = d * d < min(float(clip2), (3.0 * max(spread, 1.0)) ** 2)
    if ok.sum() < 20:
        return None
    where = where[ok]
    e = meter.grey.take(where).astype(np.float64)
    gu = meter.gu.take(where).astype(np.float64)
    gv = meter.gv.take(where).astype(np.float64)
    uu, uv, vv = float(gu @ gu), float(gu @ gv), float(gv @ gv)
    if not uu * vv - uv * uv > 1e-6 * (uu + vv) ** 2:
        return None
    a = np.column_stack([e, np.ones_like(e), -gu, -gv])
    try:
        gain, _, pu, pv = np.linalg.solve(a.T @ a, a.T @ seen[ok].astype(np.float64))
    except np.linalg.LinAlgError:
        return None
    if not gain > 0.1:
        return None
    return min(max(pu / gain, -1.0), 1.0), min(max(pv / gain, -1.0), 1.0)


def test_the_compiled_loops_compute_what_numpy_did() -> None:
    """On a wall moved by a fraction of a pixel: the frame's box means, the residuals and the
    costs (every shift within SEARCH px, read from the meter's bank, and one beyond it, on all
    samples and on every COARSE-th) are NumPy's to the bit; each shift's Lucas-Kanade step
    within 1e-9 px of NumPy's (to the bit where BLAS sums as the loop does)."""
    rng = np.random.default_rng(4)
    plate = wall((240, 320), 4)
    background = expose(plate.astype(np.float64), rng, noise=0.0)
    moved = ndimage.shift(plate, (-0.3, 0.4, 0), order=1, mode="nearest")
    frame = expose(moved, rng, gain=[1.06, 1.04, 0.98], noise=0.01)
    meter = ShiftMeter(background)
    flat = frame.reshape(-1)
    seen = sum(flat.take(meter.at + k).astype(np.float32) for k in range(3))
    seen = seen.reshape(len(meter.flat), -1).mean(axis=1) / np.float32(3.0)
    got = steadiness._box_means(flat, meter.at, len(meter.flat))
    assert got.dtype == np.float32 and np.array_equal(got, seen)
    clip2 = np.float32(3.0 * 2.5) ** 2
    shifts = [(du, dv) for dv in range(-SEARCH, SEARCH + 1) for du in range(-SEARCH, SEARCH + 1)]
    shifts.append((9, -7))
    for nth in (1, COARSE):
        want = _numpy_residuals(meter, seen, shifts, nth, clip2)
        got = steadiness._residuals(
            meter.bank, meter.planes, meter.rows, meter.cols, meter.h, meter.w, seen, 0, 0,
            np.array(shifts, dtype=np.intp), nth, clip2, True,
        )  # fmt: skip
        for a, b in zip(got, (want[0], want[2]), strict=True):
            assert a.dtype == b.dtype and np.array_equal(a, b)
    found = 0
    residuals = _numpy_residuals(meter, seen, shifts, 1, clip2)
    for shift, d, where in zip(shifts, *residuals[:2], strict=True):
        want = _numpy_step(meter, d, where, seen, clip2)
        ok, su, sv = steadiness._lucas_kanade(
            d, *shift, meter.bank, meter.planes, meter.rows, meter.cols, meter.h, meter.w, seen,
            clip2,
        )  # fmt: skip
        assert ok == (want is not None)
        if want is not None:
            found += 1
            assert abs(su - want[0]) <= 1e-9 and abs(sv - want[1]) <= 1e-9, ((su, sv), want)
    assert found > 10


def _toss(knock: tuple[float, float] | None, tmp_path, name: str):  # type: ignore[no-untyped-def]
    """A ball tossed before a brick wall, filmed at 30 fps; ``knock``: from frame 10 on, the
    picture moved by that (a tripod knocked). The clip, its plate and its scene."""
    scene = Scene(
        "toss",
        (Body("ball", Circle(0.04), (0.2, 0.3), velocity=(1.6, 4.2), mass=0.06),),
        bounds=(0.0, 0.0, 1.6, 1.2),
        fps=30.0,
        frames=28,
        substeps=20,
    )
    traj = PymunkSimulator().simulate(scene)
    pins = {"oblique": 0.0, "k1": 0.0, "k2": 0.0, "drift": 0.0, "roll": 0.0}
    cam = FieldCamera(320, seed=11, texture="bricks", **pins)
    frames = cam.exposure(scene, traj)
    if knock is not None:
        for k in range(10, len(frames)):
            frames[k] = ndimage.shift(frames[k], (knock[1], knock[0], 0), order=1, mode="nearest")
    path = tmp_path / f"{name}.mp4"
    write_video(path, frames, fps=30.0, times=np.asarray(traj.times), crf=20)
    return path, cam.plate(scene), scene, cam.calibration(scene)


def test_a_knocked_camera_is_named_and_a_steady_one_is_not(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """The same toss filmed steady and with the camera knocked 2 px right and 1 px down a third
    of the way through: the knock is named with its size and from when (where the ball is lost,
    in the error; else as a warning), against the plate and against the clip's median; the
    steady clip names no camera motion."""
    path, plate, scene, cal = _toss(None, tmp_path, "steady")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        steady = track_video(path, scene, cal, background=plate, allow_gaps=True)
    assert not steady.summary.camera_moved and steady.summary.camera_shift_px == 0.0
    assert not [w for w in caught if "camera moved" in str(w.message)]
    path, plate, scene, cal = _toss((2.0, 1.0), tmp_path, "knocked")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            said = track_video(path, scene, cal, background=plate).summary
            words = " ".join(str(w.message) for w in caught if w.category is PhysbenchWarning)
        except TrackLostError as exc:
            said, words = exc.result.summary, str(exc)
    assert said.camera_moved and said.camera_moved[0][0] == pytest.approx(10 / 30)
    assert abs(said.camera_shift_px - np.hypot(2.0, 1.0)) < 0.3, said.camera_shift_px
    assert f"camera moved by up to {said.camera_shift_px:.1f} px" in words
    assert "from 0.33" in words and "tripod" in words
    # Against the clip's median (the knocked view, two thirds of the clip), the first frame is
    # the one off: named as the cause where the ball is not found there (before, the message
    # blamed the ball's contrast).
    with pytest.raises(BodyNotFoundError, match=r"first frame's picture lies \d\.\d px off the "
                       r"clip's median: the camera moved"):  # fmt: skip
        track_video(path, scene, cal)

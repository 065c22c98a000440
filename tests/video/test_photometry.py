"""The light of a frame against the background: a gain and an offset per channel, measured
robustly away from the bodies, and the difference taken in that light."""

from __future__ import annotations

import numpy as np

from physbench.video.medians import median
from physbench.video.photometry import MIN_SPREAD, TUKEY, Light, LightMeter
from physbench.video.spheres import expose, wall


def test_gain_and_offset_are_measured_through_foreground_the_meter_did_not_expect() -> None:
    rng = np.random.default_rng(1)
    plate = wall((240, 320), 4)
    background = expose(plate.astype(np.float64), rng, noise=0.0)
    light = plate * np.array([1.08, 1.05, 0.97]) + 0.02
    light[60:180, 100:220] = (0.9, 0.7, 0.6)  # a hand a sixth of the view, not a body
    frame = expose(light, rng, noise=0.01)
    got = LightMeter(background).measure(frame, [(40.0, 40.0, 20.0)])
    gain, offset = np.array([1.08, 1.05, 0.97]), 0.02 * 255
    np.testing.assert_allclose(got.gain, gain, atol=0.02)
    # The wall's levels in this frame's light, within 2 grey levels (the foreground threshold is
    # 12 at least).
    for level in (80.0, 120.0, 160.0):
        np.testing.assert_allclose(got.gain * level + got.offset, gain * level + offset, atol=2.0)
    assert abs(got.change - 0.073) < 0.01  # the mean gain less 1, and the offset of mid-grey
    # Noise of 2.5 grey levels per channel: 6 robust standard deviations of the largest channel
    # difference, as before the light was measured.
    assert 20 < got.threshold() < 40
    # In the frame's light the wall differs from the background by noise only, the hand by a lot.
    diff = got.difference(frame, background)
    assert np.median(diff[:40]) <= 4 and np.median(diff[80:160, 120:200]) > 60


def test_a_plain_wall_gives_a_gain_alone() -> None:
    # On a uniform wall an offset cannot be told from a gain: it stays 0.
    background = np.full((120, 160, 3), 100, np.uint8)
    frame = np.full((120, 160, 3), 110, np.uint8)
    got = LightMeter(background).measure(frame)
    np.testing.assert_allclose(got.gain, 1.1, atol=1e-6)
    np.testing.assert_allclose(got.offset, 0.0)
    assert got.difference(frame, background).max() == 0


def _numpy_measure(
    meter: LightMeter, image: np.ndarray, avoid: list[tuple[float, float, float]]
) -> Light:
    """:meth:`LightMeter.measure` as NumPy calls, before its compiled loop."""
    y = image.reshape(-1, 3)[meter.flat].T
    keep = meter.usable & (np.maximum(np.maximum(y[0], y[1]), y[2]) < 254)
    if len(avoid):
        b = np.asarray(avoid, dtype=float)
        near = (meter.u[:, None] - b[:, 0]) ** 2 + (meter.v[:, None] - b[:, 1]) ** 2
        keep &= (near > b[:, 2] ** 2).all(axis=1)
    if keep.sum() < 30:
        return Light.unchanged()
    x, y = meter.bg[:, keep], y[:, keep].astype(np.float64)
    gain = median(y / np.maximum(x, 1.0), axis=1)[:, None]
    r = y - gain * x
    scale = TUKEY * np.maximum(1.4826 * median(np.abs(r), axis=1), 0.5)[:, None]
    spread = x.std(axis=1) >= MIN_SPREAD
    offset = np.zeros((3, 1))
    w = np.ones_like(x)
    for _ in range(2):
        z = r / scale
        w = np.maximum(1 - z * z, 0.0) ** 2
        wx = w * x
        sw, sx, sy = w.sum(axis=1), wx.sum(axis=1), (w * y).sum(axis=1)
        sxx, sxy = (wx * x).sum(axis=1), (wx * y).sum(axis=1)
        det = sw * sxx - sx * sx
        sloped = (sw * sxy - sx * sy) / np.maximum(det, 1e-9)
        g = np.where(spread, sloped, sxy / np.maximum(sxx, 1e-9))
        o = np.where(spread, (sy - g * sx) / np.maximum(sw, 1e-9), 0.0)
        gain, offset = g[:, None], o[:, None]
        r = y - gain * x - offset
    r = np.abs(r)
    sigma = 1.4826 * float(median(np.maximum(np.maximum(r[0], r[1]), r[2])))
    return Light(gain[:, 0], offset[:, 0], sigma, int((w > 0).all(axis=0).sum()))


def test_the_compiled_meter_measures_what_the_numpy_expressions_did_to_the_bit() -> None:
    # Textured and plain walls (no offset), foreground, bodies to avoid, grids of odd and even
    # counts, and too few pixels left.
    rng = np.random.default_rng(7)
    for case in range(120):
        h, w = rng.integers(30, 300, 2)
        background = rng.integers(0, 256, (h, w, 3)).astype(np.uint8)
        if case % 3 == 0:
            background[:] = rng.integers(0, 256, 3)
        light = background * rng.uniform(0.8, 1.2, 3) + rng.uniform(-10, 10, 3)
        light += rng.normal(0, rng.uniform(0, 5), light.shape)
        if case % 2:
            top, left = rng.integers(0, h), rng.integers(0, w)
            light[top : top + h // 3, left : left + w // 3] = rng.integers(0, 256, 3)
        frame = np.rint(np.clip(light, 0, 255)).astype(np.uint8)
        avoid = [(*rng.uniform(0, (w, h)), rng.uniform(1, 80)) for _ in range(rng.integers(0, 4))]
        meter = LightMeter(background, samples=int(rng.choice([40, 100, 500, 2000])))
        got, want = meter.measure(frame, avoid), _numpy_measure(meter, frame, avoid)
        assert got.gain.tobytes() == want.gain.tobytes()
        assert got.offset.tobytes() == want.offset.tobytes()
        assert (got.sigma, got.samples) == (want.sigma, want.samples)

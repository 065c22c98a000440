"""Transfer functions: decoding a camera's pixel values to linear light before tracking."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from physbench.components import create
from physbench.discover.synthetic import pendulum
from physbench.render.camera import CameraRenderer
from physbench.testing.field_camera import FieldCamera
from physbench.testing.field_footage import centre_errors
from physbench.video.footage import motion_view
from physbench.video.reader import VideoReader
from physbench.video.track import ENDS_SPAN, track_video
from physbench.video.transfer import (
    CODES,
    DEFAULT,
    TRANSFERS,
    Decoder,
    TransferError,
    check_transfer,
    from_tag,
    resolve,
    to_linear,
)
from physbench.video.writer import write_clip, write_video


def test_the_curves_decode_known_values() -> None:
    half = {"linear": 0.5, "srgb": 0.2140, "bt709": 0.2596, "gamma2.2": 0.2176, "gamma2.8": 0.1436}
    for name, value in half.items():
        assert to_linear(name, np.array(0.5)) == pytest.approx(value, abs=1e-3)
        ends = to_linear(name, np.array([0.0, 1.0]))
        assert ends == pytest.approx([0.0, 1.0])
    levels = np.arange(256.0)
    decoded = Decoder("srgb")(levels)
    assert decoded[0] == 0 and decoded[-1] == pytest.approx(255) and (np.diff(decoded) > 0).all()
    assert Decoder("linear")(levels) is levels  # the identity costs nothing
    assert Decoder("gamma2.2")(np.array([128.0])) == pytest.approx([56.0], abs=0.1)


def test_a_tagged_stream_is_read_as_tagged(tmp_path: Path) -> None:
    frames = [np.full((16, 16, 3), 100, np.uint8)] * 2
    for name in TRANSFERS:
        path = write_video(tmp_path / f"{name}.mp4", frames, fps=10.0, transfer=name)
        assert VideoReader(path).info().transfer == name
    untagged = write_video(tmp_path / "untagged.mp4", frames, fps=10.0)
    assert VideoReader(untagged).info().transfer is None
    # Every curve of BT.709's shape is BT.709; unspecified (2) and HLG (18) are not read.
    assert [from_tag(c) for c in (1, 6, 14, 15, 4, 8, 13, 2, 18, None)] == [
        "bt709",
        "bt709",
        "bt709",
        "bt709",
        "gamma2.2",
        "linear",
        "srgb",
        None,
        None,
        None,
    ]
    assert all(from_tag(code) == name for name, code in CODES.items())


def test_physbench_cameras_tag_what_they_write() -> None:
    assert CameraRenderer(64).transfer == "linear"
    assert FieldCamera(64, seed=1).transfer == "gamma2.2"


def test_an_option_beats_the_tag_which_beats_the_default() -> None:
    assert resolve("srgb", "linear") == ("srgb", "option")
    assert resolve("auto", "bt709") == ("bt709", "tag")
    assert resolve(None, "gamma2.2") == ("gamma2.2", "tag")
    assert resolve(None, None) == (DEFAULT, "default")


def test_a_bad_transfer_is_named_with_those_accepted(tmp_path: Path) -> None:
    with pytest.raises(TransferError, match=r"transfer = 'gamma2\.4': expected one of .*srgb"):
        check_transfer("gamma2.4")
    with pytest.raises(TransferError, match="auto"):
        resolve("rec709", None)
    scene = replace(pendulum(np.random.default_rng(2), (0.9, 1.3)), frames=2)
    path = write_video(tmp_path / "c.mp4", [np.zeros((32, 32, 3), np.uint8)] * 2, fps=20.0)
    with pytest.raises(TransferError, match="'sRGB2'"):
        track_video(path, scene, transfer="sRGB2")


def test_a_gamma_camera_is_tracked_in_linear_light(tmp_path: Path, monkeypatch) -> None:
    """A swinging arm filmed by the field camera (gamma 2.2, shutter open 70 % of the frame),
    measured by its weighted centroid (what the tracker falls back to where the arm's ends are
    not both seen): read as linear light, its blur is unmixed wrong and the centre is pulled
    along the arm (measured over runs, x264 is not bit-exact: 2.2-2.3 px median, 3.2 px p95 at
    320x240); decoded by the stream's tag, 0.5 and 0.8-1.0 px. Centred between its ends, the
    arm is 0.1-0.2 px off either way."""
    from physbench.video import track

    scene = replace(pendulum(np.random.default_rng(2), (0.9, 1.3)), frames=12)
    traj = create("simulator", "pymunk").simulate(scene)
    still = {"drift": 0.0, "oblique": 0.0, "k1": 0.0, "k2": 0.0}
    cam = FieldCamera(320, seed=2, view=motion_view(scene, traj), shutter=0.7, **still)
    path = write_clip(cam, tmp_path / "arm.mp4", scene, traj)
    plate, cal = cam.plate(scene), cam.calibration(scene)
    errors = {}
    for ends in (False, True):
        monkeypatch.setattr(track, "ENDS_SPAN", ENDS_SPAN if ends else (np.inf, np.inf))
        for transfer in ("linear", None):
            got = track_video(path, scene, cal, background=plate, transfer=transfer)
            errors[ends, transfer] = centre_errors(cam, scene, traj, got.recording)["arm"]
    assert errors[False, "linear"]["median"] > 1.6 and errors[False, "linear"]["p95"] > 2.6
    assert errors[False, None]["median"] < 1.0 and errors[False, None]["p95"] < 1.5
    for transfer in ("linear", None):
        assert errors[True, transfer]["median"] < 0.3 and errors[True, transfer]["p95"] < 0.6


def test_hdr_video_is_named_and_warned_of_where_no_curve_is_given(
    tmp_path: Path, still_disc
) -> None:  # type: ignore[no-untyped-def]
    """A phone's HDR clip (HLG, or PQ) is tagged with a curve physbench does not read: its info
    says which, and tracking it without --transfer warns, naming the curve; with a transfer
    given, or for an SDR clip, nothing is said."""
    import warnings

    from physbench.errors import PhysbenchWarning
    from physbench.video.track import track_video

    scene, cal, plate = still_disc.scene, still_disc.calibration, still_disc.plate
    for code, curve in ((18, "HLG"), (16, "PQ")):
        path = still_disc.clip(tmp_path / f"{curve}.mp4", trc=code)
        info = VideoReader(path).info()
        assert (info.hdr, info.transfer) == (curve, None)
        with pytest.warns(PhysbenchWarning, match=rf"is HDR video \({curve}\)"):
            got = track_video(path, scene, cal, background=plate)
        assert got.summary.detections["ball"] == 20
        with warnings.catch_warnings():
            warnings.simplefilter("error", PhysbenchWarning)
            track_video(path, scene, cal, background=plate, transfer="gamma2.2")
    sdr = still_disc.clip(tmp_path / "sdr.mp4", trc=1)
    assert VideoReader(sdr).info().hdr is None
    with warnings.catch_warnings():
        warnings.simplefilter("error", PhysbenchWarning)
        track_video(sdr, scene, cal, background=plate)

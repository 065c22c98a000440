"""``physbench train``: bad choices fail before any training starts."""

from __future__ import annotations

import sys

import pytest

from physbench.cli import main


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--params", "volume"], "unknown parameter 'volume'"),
        (["--params", "mass", "--renderer", "nope"], "unknown renderer 'nope'"),
        (["--params", "mass", "-R", "colour=red"], "renderer 'raster' does not take options"),
        (["--params", "mass", "--widths", "1,2"], "--widths '1,2': expected 4 positive integers"),
        (["--params", "mass", "--frames", "0"], "--frames 0: must be >= 1"),
    ],
)
def test_bad_arguments_are_named(
    argv: list[str], message: str, capsys: pytest.CaptureFixture[str], tmp_path
) -> None:  # type: ignore[no-untyped-def]
    code = main(["train", "--scene", "three_circles", "--out", str(tmp_path), *argv])
    assert code == 2 and message in capsys.readouterr().err
    assert not any(tmp_path.iterdir())  # nothing was written


def test_training_without_torch_names_the_extra(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch, tmp_path
) -> None:  # type: ignore[no-untyped-def]
    monkeypatch.setitem(sys.modules, "torch", None)
    assert (
        main(
            ["train", "--scene", "three_circles", "--params", "mass", "--out", str(tmp_path / "w")]
        )
        == 2
    )
    assert "pip install 'physbench[learn]'" in capsys.readouterr().err
    assert not (tmp_path / "w").exists()

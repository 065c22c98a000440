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
        (
            ["--params", "mass", "-R", "colour=red"],
            "renderer 'raster' (physbench's own) has no option 'colour'; the options -R can set: "
            "none",
        ),
        (["--params", "mass", "--widths", "1,2"], "--widths '1,2': expected 4 positive integers"),
        (["--params", "mass", "--resolution", "4096"], "--resolution 4096: expected 8..512"),
        (
            ["--params", "mass", "--samples", "1000000000"],
            "this training (1000000000 simulations of 30 frames x 10 substeps x 3 bodies at 64 px)"
            " would need about 38.9 days of compute, more than the 24 h limit; make --samples "
            "smaller, or set PHYSBENCH_NO_SIZE_CHECK=1",
        ),
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


def test_a_scene_file_trains_weights_that_run_on_it(
    capsys: pytest.CaptureFixture[str], tmp_path
) -> None:  # type: ignore[no-untyped-def]
    pytest.importorskip("torch")
    from physbench.scene_toml import dumps_scene
    from physbench.scenes.generator import resolve_scene

    scene = resolve_scene("three_circles", 3)
    toml = tmp_path / "my_table.toml"
    toml.write_text(dumps_scene(scene))
    tiny = ["--samples", "16", "--batch", "8", "--eval-every", "16", "--val-groups", "1"]
    tiny += ["--eval-seeds", "0", "--widths", "4,8,8,8", "--resolution", "16", "--frames", "6"]
    out = tmp_path / "w"
    argv = ["train", "--scene", str(toml), "--params", "mass", "--out", str(out), "-q", *tiny]
    assert main([*argv, "--workers", "0", "--threads", "1"]) == 0
    weights = out / f"{scene.name}__mass.safetensors"
    assert weights.is_file(), sorted(p.name for p in out.iterdir())
    capsys.readouterr()
    run = ["run", "--scene", str(toml), "--estimator", "resnet3d", "--iterations", "2"]
    assert main([*run, "-o", f"weights={weights}", "--json", "-q"]) == 0
    import json

    history = json.loads(capsys.readouterr().out)
    assert history["meta"]["scene"] == scene.name and len(history["iterations"]) == 2


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--params", "volume"], "unknown parameter 'volume'"),
        (["--params", "mass", "--samples", "5"], "--samples 5: must be >= 20"),
    ],
)
def test_posterior_bad_arguments_are_named(
    argv: list[str], message: str, capsys: pytest.CaptureFixture[str], tmp_path
) -> None:  # type: ignore[no-untyped-def]
    code = main(["train", "--posterior", "--scene", "three_circles", "--out", str(tmp_path), *argv])
    assert code == 2 and message in capsys.readouterr().err
    assert not any(tmp_path.iterdir())


def test_posterior_writes_npe_weights_the_estimator_loads(
    capsys: pytest.CaptureFixture[str], tmp_path
) -> None:  # type: ignore[no-untyped-def]
    pytest.importorskip("torch")
    from physbench.estimators.npe import weights

    argv = ["train", "--posterior", "--scene", "second_order", "--params", "mass"]
    code = main(
        [*argv, "--samples", "20", "--frames", "4", "--threads", "1", "--out", str(tmp_path)]
    )
    assert code == 0
    assert "npe weights:" in capsys.readouterr().out
    members, meta = weights.load(tmp_path / "second_order__mass.safetensors")
    assert meta["data"]["frames"] == 4 and meta["training"]["train_rows"] == 40
    assert len(members) == meta["net"]["members"] == 3

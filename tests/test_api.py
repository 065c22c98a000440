"""The Python API (``physbench.make_scene``, ``simulate``, ``render_frames``, ``run``, ``refine``,
``sweep``, ``load_table``, ``read_recording``, ``discover_effects``): reachable from the package,
loaded lazily, and giving what the machinery behind each command gives for the same settings."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

import physbench
from physbench import api
from physbench.effects import LinearDrag, SensorOffset
from physbench.errors import PhysbenchError, UnknownNameError
from physbench.experiment import RunConfig, run_config
from physbench.loop import History
from physbench.recording import Recording, Track, write_recordings
from physbench.scene import Scene
from physbench.scene_toml import save_scene
from physbench.simulators.pymunk_sim import PymunkSimulator

TINY_SPEC = {
    "name": "tiny",
    "scenes": [{"name": "three_circles", "unknowns": ["mass", "mass+elasticity"]}],
    "estimators": ["random"],
    "seeds": 2,
    "iterations": 2,
    "resolution": 16,
}


def noisy(rec: Recording, sigma: float = 0.002) -> Recording:
    rng = np.random.default_rng(0)
    tracks = {
        b: Track(t.t, t.x + rng.normal(0, sigma, len(t)), t.y + rng.normal(0, sigma, len(t)))
        for b, t in rec.tracks.items()
    }
    return Recording(tracks, fields=("x", "y"))


# ---------------------------------------------------------------- the package's names


def test_the_api_is_listed_by_dir_and_all() -> None:
    assert physbench.__all__ == api.__all__
    assert set(api.__all__) <= set(dir(physbench))
    for name in api.__all__:
        assert getattr(physbench, name) is getattr(api, name)
    assert physbench.refine is __import__("physbench.loop").loop.refine
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        _ = physbench.nope  # type: ignore[attr-defined]


def test_import_physbench_loads_neither_the_api_nor_numpy(
    heavy_imports: Callable[..., list[str]],
) -> None:
    heavy = ("physbench.api", "numpy", "pandas", "torch", "pymunk")
    assert heavy_imports("physbench", heavy=heavy) == []
    assert heavy_imports("physbench", then="dir(physbench)", heavy=heavy) == []
    # the first use loads it
    assert "physbench.api" in heavy_imports("physbench", then="physbench.run", heavy=heavy)


# ---------------------------------------------------------------- scenes, simulation, frames


def test_make_scene_takes_a_registered_name_with_a_seed_or_a_toml_file(tmp_path: Path) -> None:
    from physbench.scenes import resolve_scene

    a, b = physbench.make_scene("three_circles", seed=1), physbench.make_scene("three_circles", 2)
    assert a == resolve_scene("three_circles", 1)
    assert a != b
    save_scene(a, tmp_path / "s.toml")
    assert physbench.make_scene(tmp_path / "s.toml") == a
    assert physbench.make_scene(str(tmp_path / "s.toml"), seed=9) == a
    with pytest.raises(UnknownNameError, match=r"unknown scene 'nope'.*three_circles"):
        physbench.make_scene("nope")


def test_simulate_applies_params_and_effects_as_the_engine_does(slide: Scene) -> None:
    sc = slide
    plain = physbench.simulate(sc)
    np.testing.assert_array_equal(plain.states, PymunkSimulator().simulate(sc).states)
    dragged = physbench.simulate(sc, effects={"linear_drag": {"c": 0.3}})
    direct = PymunkSimulator().simulate(sc, effects=[LinearDrag(c=0.3)])
    np.testing.assert_array_equal(dragged.states, direct.states)
    assert dragged.states[-1, 0, 3] < plain.states[-1, 0, 3] - 0.1  # drag slowed the ball
    # a name alone takes the effect's defaults; an instance is used as it is
    np.testing.assert_array_equal(
        physbench.simulate(sc, effects=["linear_drag"]).states,
        PymunkSimulator().simulate(sc, effects=[LinearDrag()]).states,
    )
    # measurement effects change what is returned, as `physbench simulate` does
    shifted = physbench.simulate(sc, effects=[SensorOffset(dx=0.25)])
    np.testing.assert_allclose(shifted.states[:, 0, 0], plain.states[:, 0, 0] + 0.25)
    with pytest.raises(UnknownNameError, match="unknown effect 'nope'"):
        physbench.simulate(sc, effects=["nope"])


def test_simulate_overrides_body_parameters_and_takes_a_scene_name() -> None:
    sc = physbench.make_scene("three_circles")
    base = physbench.simulate("three_circles")
    np.testing.assert_array_equal(base.states, PymunkSimulator().simulate(sc).states)
    heavy = physbench.simulate(sc, params={"a.mass": 9.0})
    np.testing.assert_array_equal(
        heavy.states, PymunkSimulator().simulate(sc, {"a.mass": 9.0}).states
    )
    assert not np.array_equal(heavy.states, base.states)


def test_render_frames_builds_the_named_renderer_with_its_options() -> None:
    from physbench.components import make_renderer

    sc = physbench.make_scene("three_circles")
    traj = physbench.simulate(sc)
    frames = physbench.render_frames(sc, traj, resolution=32)
    expected = make_renderer("raster", {}, resolution=32, mode=None).render(sc, traj)
    np.testing.assert_array_equal(frames, expected)
    assert frames.shape[0] == traj.frames and frames.shape[1:2] == (2,)  # mark: two channels
    assert frames.shape[3] == 32 and frames.dtype == np.float32
    mask = physbench.render_frames(sc, traj, "raster", resolution=16, mode="mask")
    assert mask.shape[1] == 1 and mask.shape[3] == 16
    with pytest.raises(
        PhysbenchError,
        match=r"renderer 'raster' \(physbench's own\) does not take option 'blur_px'; its "
        r"options: none",
    ):
        physbench.render_frames(sc, traj, blur_px=2)


# ---------------------------------------------------------------- the loop


def test_run_returns_the_history_of_the_same_run_config() -> None:
    h = physbench.run(scene="three_circles", params="mass", iterations=2, resolution=16)
    assert isinstance(h, History)
    assert h.keys == ("a.mass", "b.mass") and len(h) == 2
    assert h.truth is not None and set(h.truth) == set(h.keys)
    assert h.best_nmse is not None and math.isfinite(h.best_nmse)
    same = run_config(RunConfig(params=("mass",), iterations=2, resolution=16))
    assert h.to_dict(timings=False) == same.to_dict(timings=False)
    # lists are taken for tuples, and the seed changes the problem
    other = physbench.run(params=["mass"], iterations=2, resolution=16, seed=1)
    assert other.truth != h.truth


def test_run_refuses_an_unknown_setting_naming_the_known(slide: Scene) -> None:
    with pytest.raises(PhysbenchError, match=r"unknown settings \['iteration'\].*iterations"):
        physbench.run(iteration=2)
    with pytest.raises(PhysbenchError, match=r"run\(scene=Scene\): expected a registered"):
        physbench.run(scene=slide)


def test_run_takes_a_scene_file_as_a_path(tmp_path: Path) -> None:
    save_scene(physbench.make_scene("three_circles", seed=4), tmp_path / "s.toml")
    h = physbench.run(scene=tmp_path / "s.toml", iterations=1, resolution=16)
    assert h.meta["scene"] == "three_circles" and h.keys == ("a.mass", "b.mass")


def test_run_warns_about_an_unknown_that_moves_no_pixel() -> None:
    with pytest.warns(UserWarning, match="mass"):
        h = physbench.run(scene="ball_drop", params="mass", iterations=1, resolution=16)
    assert h.unseen


def test_refine_is_the_loop_with_every_part_given() -> None:
    from physbench.components import create
    from physbench.observation import simulate_observation

    sc = physbench.make_scene("three_circles")
    sim, ren = PymunkSimulator(), create("renderer", "raster", resolution=16)
    obs = simulate_observation(sc, {"a.mass": 3.0, "b.mass": 6.0}, sim, ren)
    h = physbench.refine(
        obs, sc, ["mass"], sim, ren, create("estimator", "random"), iterations=3, seed=0
    )
    assert len(h) == 3 and h.keys == ("a.mass", "b.mass")


def test_run_and_refine_take_scene_level_unknowns_as_the_command_line_does() -> None:
    from physbench.components import create
    from physbench.effects import LinearDrag
    from physbench.observation import simulate_observation

    h = physbench.run(
        scene="three_circles",
        params="mass+gravity=-11:-9+linear_drag.c=0:0.5",  # the words of run --params
        effects="linear_drag",
        iterations=2,
        resolution=16,
    )
    assert h.keys == ("a.mass", "b.mass", "gravity", "linear_drag.c")
    assert -11 <= h.truth["gravity"] <= -9 and h.meta["effects"] == ["linear_drag"]
    sc = physbench.make_scene("three_circles")
    sim, ren, drag = PymunkSimulator(), create("renderer", "raster", resolution=16), LinearDrag()
    obs = simulate_observation(
        sc, {"gravity": -9.5, "linear_drag.c": 0.3}, sim, ren, effects=[drag]
    )
    h = physbench.refine(
        obs,
        sc,
        ["gravity", "linear_drag.c"],
        sim,
        ren,
        create("estimator", "random"),
        iterations=3,
        effects=[drag],
    )
    assert h.keys == ("gravity", "linear_drag.c") and h.truth == {
        "gravity": -9.5,
        "linear_drag.c": 0.3,
    }


# ---------------------------------------------------------------- sweeps and their table


@pytest.fixture(scope="module")
def tiny_sweep(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("tiny")
    res = physbench.sweep(TINY_SPEC, out, executor="serial")
    assert res.cells == 4 and res.failed == 0
    return out


def test_sweep_takes_a_spec_file_like_physbench_bench(tiny_sweep: Path, tmp_path: Path) -> None:
    from physbench.bench.tables import without_timings

    lines = [f"{k} = {json.dumps(v)}" for k, v in TINY_SPEC.items() if k != "scenes"]
    lines += ["[[scenes]]", 'name = "three_circles"', 'unknowns = ["mass", "mass+elasticity"]']
    (tmp_path / "tiny.toml").write_text("\n".join(lines) + "\n")
    res = physbench.sweep(tmp_path / "tiny.toml", tmp_path / "out", executor="serial")
    assert (tmp_path / "out" / "spec.toml").is_file()
    a = without_timings(physbench.load_table(tmp_path / "out", flat=False))
    b = without_timings(physbench.load_table(tiny_sweep, flat=False))
    assert a.drop(columns="versions").equals(b.drop(columns="versions"))
    assert res.ran == 4
    again = physbench.sweep(tmp_path / "tiny.toml", tmp_path / "out", executor="serial")
    assert again.ran == 0 and again.skipped == 4  # resumed


def test_load_table_flat_spreads_params_and_truth_into_columns(tiny_sweep: Path) -> None:
    long = physbench.load_table(tiny_sweep, flat=False)
    flat = physbench.load_table(tiny_sweep)
    assert {"params", "truth"} <= set(long.columns)
    assert not {"params", "truth"} & set(flat.columns)
    keys = ["a.mass", "b.mass", "a.elasticity", "b.elasticity"]
    for prefix in ("params", "truth"):
        assert all(f"{prefix}_{k}" in flat.columns for k in keys)
    assert len(flat) == len(long) == 8  # 4 cells x 2 iterations
    for (_, row), (_, flat_row) in zip(long.iterrows(), flat.iterrows(), strict=True):
        for prefix in ("params", "truth"):
            values = json.loads(row[prefix])
            for k in keys:
                got = flat_row[f"{prefix}_{k}"]
                assert got == values[k] if k in values else math.isnan(got)
    assert flat["params_a.mass"].dtype == np.float64
    # the truth of a mass-only cell is the truth `run` draws for that seed
    seed1 = flat[(flat["unknowns"] == "mass") & (flat["seed"] == 1)].iloc[0]
    h = physbench.run(params="mass", seed=1, iterations=1, resolution=16)
    assert h.truth is not None and seed1["truth_a.mass"] == h.truth["a.mass"]


def test_load_table_names_a_folder_without_a_table(tmp_path: Path) -> None:
    with pytest.raises(PhysbenchError, match=r"no results\.parquet there"):
        physbench.load_table(tmp_path)


# ---------------------------------------------------------------- recordings and discovery


def test_read_recording_reads_what_was_written(tmp_path: Path, slide: Scene) -> None:
    rec = Recording.from_trajectory(physbench.simulate(slide))
    write_recordings(tmp_path / "r.csv", rec)
    back = physbench.read_recording(tmp_path / "r.csv")
    assert back.bodies == ("ball",)
    np.testing.assert_array_equal(back.track("ball").x, rec.track("ball").x)


def test_discover_effects_names_the_hidden_drag(tmp_path: Path, slide: Scene) -> None:
    sc = slide
    hidden = physbench.simulate(sc, effects={"linear_drag": {"c": 0.3}})
    rec = noisy(Recording.from_trajectory(hidden))
    effects = ["linear_drag", "constant_force"]
    found = physbench.discover_effects(rec, sc, effects=effects)
    assert found.causes == ["linear_drag"]
    chosen = next(c for c in found.candidates if c.chosen)
    assert chosen.params["c"] == pytest.approx(0.3, rel=0.1)
    # from files, as `physbench discover REC.csv --scene S.toml` reads them
    write_recordings(tmp_path / "r.csv", rec)
    save_scene(sc, tmp_path / "s.toml")
    from_files = physbench.discover_effects(
        tmp_path / "r.csv", tmp_path / "s.toml", effects=effects
    )
    assert from_files.causes == ["linear_drag"]
    with pytest.raises(PhysbenchError, match=r"unknown settings \['efects'\].*effects"):
        physbench.discover_effects(rec, sc, efects=effects)


# ---------------------------------------------------------------- sweeps from a script


def _script(tmp_path: Path, body: str) -> subprocess.CompletedProcess[str]:
    script = tmp_path / "sweep_script.py"
    script.write_text(body)
    return subprocess.run(
        [sys.executable, str(script)], capture_output=True, text=True, cwd=tmp_path, timeout=300
    )


def test_a_sweep_outside_the_main_guard_is_refused_before_any_cell_runs(tmp_path: Path) -> None:
    """Issue 28: the worker processes (spawn) run the script again, so an unguarded sweep failed
    every cell with FolderBusyError tracebacks and the script exited 0."""
    out = tmp_path / "out"
    body = (
        "import physbench\n"
        f"res = physbench.sweep({TINY_SPEC!r}, {str(out)!r}, workers=1)\n"
        "print('failed', res.failed)\n"
    )
    proc = _script(tmp_path, body)
    assert proc.returncode != 0, proc.stdout + proc.stderr
    err = proc.stderr
    assert "sweep_script.py, line 2: a sweep on local worker processes" in err, err[-2000:]
    assert 'if __name__ == "__main__":' in err and "executor='serial'" in err
    assert "FolderBusyError" not in err and "WorkerDied" not in err
    assert not out.exists()  # refused before anything ran or was written


def test_a_sweep_whose_every_cell_fails_raises(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Issue 28: a sweep with no finished cell returned as if fine."""
    from physbench import experiment
    from physbench.bench.runner import SweepFailedError

    def broken(*args: object, **kwargs: object) -> None:
        raise RuntimeError("no simulation today")

    monkeypatch.setattr(experiment, "run_config", broken)
    with pytest.raises(SweepFailedError) as err:
        physbench.sweep(TINY_SPEC, tmp_path, executor="serial")
    message = str(err.value)
    assert "all 4 cells failed (4 cells: RuntimeError: no simulation today)" in message
    assert str(tmp_path / "cells") in message
    assert err.value.result.failed == 4 and (tmp_path / "results.parquet").is_file()


def test_non_finite_numbers_are_refused_by_every_api_entry(tmp_path: Path, slide: Scene) -> None:
    """Issue 28: ``floor=nan`` was accepted and then discovery found nothing."""
    nan = float("nan")
    with pytest.raises(PhysbenchError, match=r"run setting blur = nan: expected a finite number"):
        physbench.run(blur=nan)
    with pytest.raises(PhysbenchError, match=r"floor = inf: expected a finite number >= 0 \(m\)"):
        physbench.discover_effects(tmp_path / "rec.csv", slide, floor=float("inf"))
    with pytest.raises(PhysbenchError, match=r"min_delta_bic = nan"):
        physbench.discover_effects(tmp_path / "rec.csv", slide, min_delta_bic=nan)
    with pytest.raises(PhysbenchError, match=r"noise = nan"):
        physbench.sweep({**TINY_SPEC, "noise": nan}, tmp_path / "out", executor="serial")
    with pytest.raises(PhysbenchError, match=r"seed = nan: expected a whole number in \[0, "):
        physbench.make_scene("three_circles", seed=nan)  # type: ignore[arg-type]
    with pytest.raises(PhysbenchError, match=r"seed = 1180591620717411303424: expected a whole"):
        physbench.make_scene("three_circles", seed=2**70)
    # an engine would abort the process on a NaN mass (Chipmunk's assertion)
    with pytest.raises(PhysbenchError, match=r"mass = nan: must be a finite number"):
        physbench.simulate("three_circles", params={"a.mass": nan})

"""Discovery's parts: effect set-up and the contact hook in the simulators, initial-state nuisance,
splits, residual layout, diagnostics, the verdict's JSON, frames input, estimators, and the CLI."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from physbench.cli import main as cli
from physbench.discover import DiscoverError, Run, Settings, discover, make_split
from physbench.discover.data import sub_recording
from physbench.discover.diagnostics import _oscillation
from physbench.discover.model import apply_initial, chain_parents
from physbench.discover.residuals import Layout
from physbench.discover.verdict import to_dict
from physbench.effects import LinearDrag, TableTilt, VelocityDependentRestitution
from physbench.errors import PhysbenchError
from physbench.recording import Recording, Track, write_recordings
from physbench.scene import Body, Box, Circle, Joint, Scene, Segment
from physbench.scene_toml import save_scene
from physbench.simulators.box2d_sim import Box2DSimulator
from physbench.simulators.pymunk_sim import PymunkSimulator

ENGINES = [PymunkSimulator, Box2DSimulator]


def slide(v=(2.0, 0.5), mass=1.0, frames=41, fps=20.0) -> Scene:
    return Scene(
        "slide",
        (Body("ball", Circle(0.05), (1.0, 1.0), velocity=v, mass=mass),),
        bounds=(-3, -3, 9, 6),
        gravity=(0.0, 0.0),
        fps=fps,
        frames=frames,
        substeps=4,
    ).validate()


def noisy(traj, sigma=0.002, seed=0, fields=None) -> Recording:
    rng = np.random.default_rng(seed)
    rec = Recording.from_trajectory(traj)
    tracks = {
        b: Track(
            t.t,
            t.x + rng.normal(0, sigma, len(t)),
            t.y + rng.normal(0, sigma, len(t)),
            None if t.angle is None else t.angle + rng.normal(0, sigma, len(t)),
        )
        for b, t in rec.tracks.items()
    }
    return Recording(tracks, fields=fields or ("x", "y"))


# --------------------------------------------------------------------------- simulators


@pytest.mark.parametrize("sim", ENGINES)
def test_simulate_sets_effects_up_with_the_scene_as_simulated(sim):
    # TableTilt's force is m·a: set up once with mass 1 but simulated with mass 3, the acceleration
    # must still be a, which needs setup() with the parameters applied inside simulate().
    scene = slide(v=(0.0, 0.0))
    tilt = TableTilt(ax=0.5)
    tilt.setup(scene, {})
    tr = sim().simulate(scene, {"ball.mass": 3.0, "table_tilt.ay": -0.25}, effects=[tilt])
    t = tr.times[-1]
    assert tr.body("ball")[-1, 3] == pytest.approx(0.5 * t, rel=1e-4)
    assert tr.body("ball")[-1, 4] == pytest.approx(-0.25 * t, rel=1e-4)
    assert tilt.values == {"ax": 0.5, "ay": -0.25}


@pytest.mark.parametrize("sim", ENGINES)
def test_two_instances_of_an_effect_need_labels(sim):
    scene = Scene(
        "two",
        (
            Body("a", Circle(0.05), (1, 1), velocity=(1, 0)),
            Body("b", Circle(0.05), (1, 3), velocity=(1, 0)),
        ),
        bounds=(0, 0, 6, 5),
        gravity=(0, 0),
        frames=31,
    )
    a, b = LinearDrag(bodies=["a"], label="drag_a"), LinearDrag(bodies=["b"], label="drag_b")
    tr = sim().simulate(scene, {"drag_a.c": 1.0, "drag_b.c": 0.0}, effects=[a, b])
    assert tr.body("a")[-1, 3] == pytest.approx(math.exp(-tr.times[-1]), rel=5e-3)
    assert tr.body("b")[-1, 3] == pytest.approx(1.0, abs=1e-6)
    with pytest.raises(PhysbenchError, match="share the parameter key 'linear_drag'"):
        sim().simulate(scene, effects=[LinearDrag(), LinearDrag()])
    with pytest.raises(PhysbenchError, match="label"):
        LinearDrag(label="a.b")


@pytest.mark.parametrize("sim", ENGINES)
def test_contact_hook_applies_velocity_dependent_restitution(sim):
    # A ball dropped 1.25 m hits the floor at ~5 m/s: the rebound keeps e0 - k·v of the speed.
    scene = Scene(
        "drop",
        (Body("ball", Circle(0.1), (1.0, 1.35), elasticity=1.0),),
        statics=(Segment((-1, 0), (5, 0)),),
        bounds=(0, 0, 4, 4),
        fps=100.0,
        frames=71,
        substeps=10,
    )
    e0, k = 0.9, 0.08
    tr = sim().simulate(scene, effects=[VelocityDependentRestitution(e0=e0, k=k)])
    vy = tr.body("ball")[:, 4]
    i = int(np.argmax(np.diff(vy)))
    v_in, v_out = -vy[i], vy[i + 1]
    g_dt = 9.81 / scene.fps  # a frame of gravity on either side of the impact
    assert v_out / v_in == pytest.approx(e0 - k * v_in, abs=g_dt / v_in + 0.01)
    plain = sim().simulate(scene)
    assert plain.body("ball")[i + 1, 4] > v_out + 1.0  # without the effect: elastic


def test_restitution_hook_agrees_between_engines():
    # Normal speeds stay above Box2D's 1 m/s threshold, below which Box2D makes impacts inelastic.
    scene = Scene(
        "box",
        (
            Body(
                "puck", Circle(0.05), (0.5, 0.4), velocity=(4.0, 3.0), elasticity=1.0, friction=0.0
            ),
        ),
        statics=tuple(
            Segment(a, b)
            for a, b in (((0, 0), (2, 0)), ((2, 0), (2, 1)), ((2, 1), (0, 1)), ((0, 1), (0, 0)))
        ),
        bounds=(0, 0, 2, 1),
        gravity=(0.0, 0.0),
        fps=50.0,
        frames=41,
        substeps=10,
    )
    trs = [
        s().simulate(scene, effects=[VelocityDependentRestitution(e0=0.95, k=0.05)])
        for s in ENGINES
    ]
    vx, vy = ([abs(t.states[-1, 0, c]) for t in trs] for c in (3, 4))
    assert vx[0] == pytest.approx(vx[1], rel=1e-3) and vy[0] == pytest.approx(vy[1], rel=1e-3)
    assert vx[0] == pytest.approx(
        (0.95 - 0.05 * 4.0) * 4.0, rel=0.01
    )  # one side-wall impact at 4 m/s
    assert vy[0] < 0.85 * 3.0


# --------------------------------------------------------------------------- model pieces


def double_pendulum() -> Scene:
    a = Body("upper", Box(0.04, 0.4), (1.0, 1.3), mass=0.5)
    b = Body("lower", Box(0.04, 0.3), (1.0, 0.95), mass=0.3)
    return Scene(
        "dp",
        (a, b),
        bounds=(0, 0, 2, 2),
        gravity=(0.0, 0.0),
        fps=100.0,
        frames=3,
        substeps=10,
        joints=(Joint("upper", (1.0, 1.5)), Joint("lower", (1.0, 1.1), "upper")),
    ).validate()


def test_initial_angles_move_the_whole_chain_rigidly():
    scene = double_pendulum()
    assert chain_parents(scene) == {"upper": (None, 0), "lower": ("upper", 1)}
    moved = apply_initial(
        scene,
        {"upper": {"angle0": 0.3, "omega0": 1.0}, "lower": {"angle0": -0.2, "omega0": 2.0}},
        {},
    )
    up, lo = moved.bodies
    elbow = np.array([1.0, 1.5]) + 0.4 * np.array([math.sin(0.3), -math.cos(0.3)])
    assert np.allclose(moved.joints[1].anchor, elbow)
    assert np.allclose(
        up.position, np.array([1.0, 1.5]) + 0.2 * np.array([math.sin(0.3), -math.cos(0.3)])
    )
    assert np.allclose(lo.position, elbow + 0.15 * np.array([math.sin(-0.2), -math.cos(-0.2)]))
    v_elbow = 1.0 * 0.4 * np.array([math.cos(0.3), math.sin(0.3)])
    assert np.allclose(
        lo.velocity, v_elbow + 2.0 * 0.15 * np.array([math.cos(-0.2), math.sin(-0.2)])
    )
    for sim in ENGINES:  # a consistent state: without gravity the joints do not jerk the rates
        tr = sim().simulate(moved.validate())
        assert abs(tr.states[1, 0, 5] - 1.0) < 0.05 and abs(tr.states[1, 1, 5] - 2.0) < 0.05
        jerked = sim().simulate(
            apply_initial(scene, {"upper": {"angle0": 0.3, "omega0": 1.0}}, {}).validate()
        )
        assert jerked.states[1, 1, 5] == pytest.approx(
            0.0, abs=0.05
        )  # lower keeps its own rate (0)


def test_layout_follows_the_residual_order_and_weights_angles():
    rec = Recording(
        {
            "b": Track(
                np.array([0.0, 0.1]),
                np.array([1.0, 2.0]),
                np.array([3.0, 4.0]),
                np.array([0.1, 0.2]),
            ),
            "a": Track(np.array([0.0]), np.array([5.0]), np.array([6.0]), np.array([0.3])),
        }
    )
    scene = Scene("s", (Body("a", Circle(0.1), (1, 1)), Body("b", Box(0.2, 0.4), (2, 2))))
    lay = Layout.of_recording(rec, scene)
    assert lay.body.tolist() == [0, 0, 0, 0, 0, 0, 1, 1, 1]  # recording order: b then a
    assert lay.field.tolist() == [0, 0, 1, 1, 2, 2, 0, 1, 2]
    assert lay.weight[4] == pytest.approx(Box(0.2, 0.4).extent()) and lay.weight[0] == 1.0
    assert lay.unit.startswith("m (angles")


def test_splits_by_time_and_by_runs():
    rec = Recording({"ball": Track(np.arange(21) * 0.1, np.zeros(21), np.zeros(21))})
    scene = slide(frames=21, fps=10.0)
    s = make_split([Run("r", scene, recording=rec)], holdout=0.3)
    assert s.kind == "time" and s.fit[0].size == 15 and s.held[0].size == 6
    runs = [Run(f"r{i}", scene, recording=rec) for i in range(4)]
    s = make_split(runs, holdout=0.3)
    assert (
        s.kind == "runs"
        and s.train_runs == (0, 1, 2)
        and s.test_runs == (3,)
        and s.lead[0].size == 6
    )
    with pytest.raises(DiscoverError, match="leaves 2 samples to fit"):
        make_split([Run("short", scene, recording=sub_recording(rec, -1, 0.35))], holdout=0.5)
    with pytest.raises(DiscoverError, match=r"holdout = 0\.9"):
        make_split(runs, holdout=0.9)


def test_envelope_diagnostic_tells_viscous_from_coulomb():
    t = np.arange(0, 12, 0.01)
    w = 2 * math.pi
    visc = Track(t, 0 * t, 0 * t, 1.0 * np.exp(-0.15 * t) * np.cos(w * t))
    coul = Track(t, 0 * t, 0 * t, np.maximum(1.0 - 0.06 * t, 0.0) * np.cos(w * t))
    sim = Track(t, 0 * t, 0 * t, np.cos(w * t))
    for track, want in ((visc, "joint_viscous_damping"), (coul, "joint_coulomb_friction")):
        env = [f for f in _oscillation("r", "arm", track, sim) if f.kind == "envelope"]
        assert env and env[0].suggests == (want,)


# --------------------------------------------------------------------------- end to end


def test_discovery_finds_linear_drag_and_writes_json_with_the_documented_keys(tmp_path):
    scene = slide()
    rec = noisy(PymunkSimulator().simulate(scene, effects=[LinearDrag(c=0.4)]))
    disc = discover(
        [Run("r", scene, recording=rec)],
        "pymunk",
        settings=Settings(
            effects=["linear_drag", "quadratic_drag", "rolling_resistance", "sensor_offset"]
        ),
    )
    d = to_dict(disc)
    assert d["causes"] == ["linear_drag"] and d["gain"] > 0.9
    assert {"base", "candidates", "causes", "gain"} <= set(d)
    for c in d["candidates"]:
        assert {"effect", "params", "heldout_error", "gain", "criterion"} <= set(c)
    chosen = next(c for c in d["candidates"] if c["chosen"])
    assert chosen["params"]["c"] == pytest.approx(0.4, rel=0.05) and chosen["stderr"]["c"] > 0
    json.dumps(d)  # strictly serialisable
    from physbench.discover.report import write_report

    page = write_report(disc, tmp_path / "rep")
    assert page.is_file() and (tmp_path / "rep" / "trajectories.png").is_file()
    assert "linear_drag" in page.read_text()


def test_black_box_estimator_for_the_base_fit():
    scene = Scene(
        "m",
        (Body("ball", Circle(0.05), (1.0, 1.0), velocity=(1.5, 0.0), mass=2.0),),
        bounds=(-3, -3, 9, 6),
        gravity=(0.0, 0.0),
        fps=20.0,
        frames=31,
        substeps=4,
        forces=(),
        unknowns=(),
    )
    rec = noisy(PymunkSimulator().simulate(scene))
    disc = discover(
        [Run("r", scene, recording=rec)],
        "pymunk",
        settings=Settings(effects=["linear_drag"], estimator="random", estimator_iterations=8),
    )
    assert disc.causes == [] and disc.base.fit.rms < 0.004
    with pytest.raises(PhysbenchError, match="unknown estimator 'nope'"):
        discover([Run("r", scene, recording=rec)], "pymunk", settings=Settings(estimator="nope"))


def test_frames_input_uses_the_image_loss(tmp_path):
    from physbench.observation import Observation, save_observation
    from physbench.render.raster import RasterRenderer

    scene = Scene(
        "frames",
        (Body("ball", Circle(0.3), (1.0, 2.0), velocity=(2.5, 0.3), mass=1.0),),
        bounds=(0, 0, 6, 4),
        gravity=(0.0, 0.0),
        fps=10.0,
        frames=21,
        substeps=4,
    ).validate()
    r = RasterRenderer(resolution=32, mode="mask")
    frames = r.render(scene, PymunkSimulator().simulate(scene, effects=[LinearDrag(c=0.5)]))
    save_observation(tmp_path / "obs.npz", Observation(frames))
    save_scene(scene, tmp_path / "scene.toml")
    out = tmp_path / "v.json"
    rc = cli(
        [
            "discover",
            str(tmp_path / "obs.npz"),
            "--scene",
            str(tmp_path / "scene.toml"),
            "--effects",
            "linear_drag",
            "rolling_resistance",
            "--json",
            str(out),
            "-q",
        ]
    )
    assert rc == 0
    d = json.loads(out.read_text())
    assert d["causes"] == ["linear_drag"] and d["unit"] == "pixel intensity"
    c = next(c for c in d["candidates"] if c["chosen"])
    assert c["params"]["c"] == pytest.approx(0.5, rel=0.15)


def test_cli_prints_the_verdict_and_the_table(tmp_path, capsys):
    scene = slide()
    rec = noisy(PymunkSimulator().simulate(scene))
    write_recordings(tmp_path / "r.csv", rec)
    save_scene(scene, tmp_path / "s.toml")
    rc = cli(
        [
            "discover",
            str(tmp_path / "r.csv"),
            "--scene",
            str(tmp_path / "s.toml"),
            "--effects",
            "linear_drag",
            "constant_force",
            "--report",
            str(tmp_path / "rep"),
        ]
    )
    out = capsys.readouterr().out
    assert rc == 0
    assert "no cause found" in out and "linear_drag" in out and "held-out" in out
    assert (tmp_path / "rep" / "index.html").is_file()

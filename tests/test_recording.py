"""Recording CSV: malformed files name line, row and column; good files round-trip; recordings
compare with simulated trajectories."""

from __future__ import annotations

import math
import re
from dataclasses import replace

import numpy as np
import pytest

from physbench.recording import (
    Recording,
    RecordingError,
    Track,
    format_recordings,
    parse_recordings,
    read_recording,
    read_recordings,
    write_recordings,
)
from physbench.scene import Body, Circle, Scene
from physbench.simulators.pymunk_sim import PymunkSimulator
from physbench.trajectory import Trajectory

BODIES = ("ball", "box")

# (case id, CSV text, expected line, expected row (None: header), expected column, message fragment)
MALFORMED = [
    ("empty file", "", 1, None, "t", "empty file"),
    ("only blank lines", "\n\n  \n", 1, None, "t", "empty file"),
    ("header only", "t,body,x,y\n", 2, 1, "t", "no data rows"),
    ("missing column", "t,body,x\n0,ball,1\n", 1, None, "y", "missing required column"),
    ("unknown column", "t,body,x,y,angel\n0,ball,1,2,0\n", 1, None, "angel", "unknown column name"),
    ("duplicate column", "t,body,x,y,x\n0,ball,1,2,3\n", 1, None, "x", "duplicate column"),
    ("short row", "t,body,x,y\n0,ball,1,2\n0.1,ball,1\n", 3, 2, "y", "expected 4 values"),
    ("long row", "t,body,x,y\n0,ball,1,2,5\n", 2, 1, "#5", "expected 4 values"),
    (
        "non-numeric x",
        "t,body,x,y\n0,ball,1,2\n0.1,ball,one,2\n",
        3,
        2,
        "x",
        "'one' is not a number",
    ),
    ("empty y", "t,body,x,y\n0,ball,1,\n", 2, 1, "y", "'' is not a number"),
    ("NaN", "t,body,x,y\n0,ball,1,2\n0.1,ball,1,nan\n", 3, 2, "y", "finite"),
    ("infinite angle", "t,body,x,y,angle\n0,ball,1,2,inf\n", 2, 1, "angle", "finite"),
    (
        "non-numeric time",
        "t,body,x,y\n0,ball,1,2\n1s,ball,1,2\n",
        3,
        2,
        "t",
        "'1s' is not a number",
    ),
    ("negative time", "t,body,x,y\n-0.1,ball,1,2\n", 2, 1, "t", ">= 0"),
    ("unknown body", "t,body,x,y\n0,ball,1,2\n0,bal,1,2\n", 3, 2, "body", "unknown body 'bal'"),
    ("empty body", "t,body,x,y\n0,,1,2\n", 2, 1, "body", "empty body name"),
    (
        "repeated time",
        "t,body,x,y\n0,ball,1,2\n0.5,ball,1,2\n0.5,ball,1.1,2\n",
        4,
        3,
        "t",
        "repeats",
    ),
    (
        "repeated time, rows apart",
        "t,body,x,y,run\n0.2,ball,1,2,a\n0.1,box,1,2,a\n0.2,ball,3,2,a\n",
        4,
        3,
        "t",
        "also at line 2",
    ),
    (
        "angle given then missing",
        "t,body,x,y,angle\n0,ball,1,2,0.5\n0.1,ball,1,2,\n",
        3,
        2,
        "angle",
        "given",
    ),
    (
        "empty run label",
        "t,body,x,y,run\n0,ball,1,2,a\n0,ball,1,2,\n",
        3,
        2,
        "run",
        "empty run label",
    ),
    (
        "comment lines count",
        "# made by hand\nt,body,x,y\n0,ball,1,2\n0,ball,x,2\n",
        4,
        2,
        "x",
        "not a number",
    ),
]


@pytest.mark.parametrize(
    ("text", "line", "row", "column", "fragment"),
    [c[1:] for c in MALFORMED],
    ids=[c[0] for c in MALFORMED],
)
def test_malformed_csv_names_line_row_and_column(text, line, row, column, fragment):
    with pytest.raises(RecordingError) as info:
        parse_recordings(text, bodies=BODIES, source="rec.csv")
    err = info.value
    assert (err.line, err.row, err.column) == (line, row, column)
    msg = str(err)
    assert msg.startswith(f"rec.csv: line {line} (")
    assert ("(header)" if row is None else f"(data row {row})") in msg
    assert f"column {column!r}" in msg
    assert fragment in msg


def test_repeated_time_is_allowed_across_bodies_and_runs():
    text = "t,body,x,y,run\n0.5,ball,1,2,a\n0.5,box,1,2,a\n0.5,ball,1,2,b\n"
    recs = parse_recordings(text, bodies=BODIES)
    assert [r.run for r in recs] == ["a", "b"] and recs[0].bodies == ("ball", "box")


def test_rows_in_any_order_are_sorted_per_body():
    text = "body,t,y,x\nball,0.3,3,30\nbox,0.0,0,0\nball,0.1,1,10\n\nball,0.2,2,20\n"
    (rec,) = parse_recordings(text)
    tr = rec.track("ball")
    assert (
        tr.t.tolist() == [0.1, 0.2, 0.3]
        and tr.x.tolist() == [10, 20, 30]
        and tr.y.tolist() == [1, 2, 3]
    )
    assert tr.angle is None and rec.run == "" and rec.track("box").t.tolist() == [0.0]


def random_recordings(rng: np.random.Generator) -> list[Recording]:
    recs = []
    for run in ("drop 1", "drop-2", "3"):
        tracks = {}
        for body, with_angle in (("ball", True), ("box", False)):
            n = int(rng.integers(1, 30))
            t = np.sort(
                rng.choice(np.linspace(0, 5, 2000), size=n, replace=False) + rng.uniform(0, 1e-3, n)
            )
            tracks[body] = Track(
                t,
                rng.normal(size=n),
                rng.normal(size=n) * 1e-7,
                rng.normal(size=n) if with_angle else None,
            )
        recs.append(Recording(tracks, run=run))
    return recs


def test_round_trip_of_several_irregular_runs_is_exact(tmp_path):
    recs = random_recordings(np.random.default_rng(3))
    path = tmp_path / "runs.csv"
    write_recordings(path, recs)
    back = read_recordings(path, bodies=BODIES)
    assert [r.run for r in back] == [r.run for r in recs]
    for a, b in zip(recs, back, strict=True):
        assert a.bodies == b.bodies
        for body in a.bodies:
            ta, tb = a.track(body), b.track(body)
            for f in ("t", "x", "y"):
                np.testing.assert_array_equal(getattr(ta, f), getattr(tb, f))
            assert (ta.angle is None) == (tb.angle is None)
            if ta.angle is not None:
                np.testing.assert_array_equal(ta.angle, tb.angle)
    # rows shuffled still read back the same
    lines = path.read_text().splitlines()
    body = lines[1:]
    np.random.default_rng(0).shuffle(body)
    path.write_text("\n".join([lines[0], *body]) + "\n")
    assert format_recordings(read_recordings(path)) != "\n".join(lines)  # order differs ...
    again = read_recordings(path)
    assert sorted(r.run for r in again) == sorted(r.run for r in recs)
    for r in again:  # ... but the content is the same
        orig = next(o for o in recs if o.run == r.run)
        for name in orig.bodies:
            np.testing.assert_array_equal(r.track(name).x, orig.track(name).x)
    assert read_recording(path, run="drop-2").run == "drop-2"
    with pytest.raises(RecordingError, match="holds 3 runs"):
        read_recording(path)


def test_single_run_without_run_column(tmp_path):
    rec = Recording(
        {"ball": Track(np.array([0.0, 0.25]), np.array([1.0, 2.0]), np.array([0.5, 0.25]))}
    )
    write_recordings(tmp_path / "one.csv", rec)
    assert (tmp_path / "one.csv").read_text().splitlines()[0] == "t,body,x,y"
    assert read_recording(tmp_path / "one.csv").track("ball").x.tolist() == [1.0, 2.0]


#: Characters of random run and body names: CSV and JSON specials, a comment mark, non-ASCII.
NAME_CHARS = [*"ab01 ,\"'#:;\\\n\té€", '": y', "of run"]


def random_name(rng: np.random.Generator) -> str:
    name = "".join(rng.choice(NAME_CHARS) for _ in range(int(rng.integers(1, 8))))
    return name.strip() or "r"  # a reader strips cells: the writer refuses edge white space


def random_track(rng: np.random.Generator, with_angle: bool) -> Track:
    n = int(rng.integers(1, 12))
    scale = 10.0 ** rng.integers(-300, 5)  # repr must carry any double within the limits (1e6)
    t = np.cumsum(rng.uniform(1e-9, 1.0, n)) - rng.uniform(0, 1e-9)
    values = [rng.normal(size=n) * scale for _ in range(3)]
    return Track(t, values[0], values[1], values[2] if with_angle else None)


def random_fields(rng: np.random.Generator) -> tuple[str, ...] | None:
    if rng.random() < 0.3:
        return None
    k = int(rng.integers(0, 4))
    return tuple(str(f) for f in rng.permutation(["x", "y", "angle"])[:k])


def test_write_then_parse_gives_back_the_same_recordings() -> None:
    """Seeded cases: tracks bit for bit, run labels and measured fields (any subset, any order,
    or none named), one run without a label or several with labels full of CSV specials."""
    rng = np.random.default_rng(13)
    for case in range(300):
        n_runs = int(rng.integers(1, 4))
        labels: list[str] = [""] if n_runs == 1 and rng.random() < 0.5 else []
        while len(labels) < n_runs:
            label = random_name(rng)
            labels += [] if label in labels else [label]
        recs = []
        for run in labels:
            bodies = {random_name(rng) for _ in range(int(rng.integers(1, 4)))}
            tracks = {b: random_track(rng, bool(rng.random() < 0.5)) for b in sorted(bodies)}
            recs.append(Recording(tracks, run=run, fields=random_fields(rng)))
        text = format_recordings(recs)
        back = parse_recordings(text, source="rec.csv")
        assert [(r.run, r.fields, r.bodies) for r in back] == [
            (r.run, r.fields, r.bodies) for r in recs
        ], (case, text)
        for a, b in zip(recs, back, strict=True):
            assert b.source == "rec.csv" and dict(b.meta) == {}
            for name in a.bodies:
                ta, tb = a.track(name), b.track(name)
                assert (ta.angle is None) == (tb.angle is None), (case, text)
                for f in ("t", "x", "y", "angle")[: 4 if ta.angle is not None else 3]:
                    got, want = getattr(tb, f), getattr(ta, f)
                    assert got.tobytes() == want.tobytes(), (case, f, text)


def test_fields_lines_are_read_and_files_without_them_are_unchanged() -> None:
    plain = "t,body,x,y,run\n0,ball,0,1,a\n0,ball,0,2,b\n"
    assert [r.fields for r in parse_recordings(plain)] == [None, None]
    # a comment that is no fields line changes nothing
    assert [r.fields for r in parse_recordings("# fields were tracked by hand\n" + plain)] == [
        None,
        None,
    ]
    every = "# made by hand\n# fields: y\n" + plain
    assert [r.fields for r in parse_recordings(every)] == [("y",), ("y",)]
    one = '#fields of run "b" : x ,angle\n# fields: y\n' + plain
    assert [r.fields for r in parse_recordings(one)] == [("y",), ("x", "angle")]
    assert parse_recordings("# fields:\nt,body,x,y\n0,ball,0,1\n")[0].fields == ()


@pytest.mark.parametrize(
    ("text", "line", "fragment"),
    [
        ("# fields: y, z\n", 1, "unknown field 'z'; fields are x, y, angle"),
        ("# fields: y\n#fields:x\n", 2, "fields of every run given twice (also at line 1)"),
        ("# fields of run a: y\n", 1, "run label a is not a JSON string"),
        (
            '\n# fields of run "c": y\n',
            2,
            "fields of run 'c', but no row is of that run; runs: 'a'",
        ),
    ],
)
def test_bad_fields_lines_name_their_line(text: str, line: int, fragment: str) -> None:
    with pytest.raises(RecordingError) as info:
        parse_recordings(text + "t,body,x,y,run\n0,ball,0,1,a\n", source="rec.csv")
    assert info.value.line == line
    assert str(info.value).startswith(f"rec.csv: line {line} (comment): ") and fragment in str(
        info.value
    )


def test_names_a_reader_would_strip_are_refused() -> None:
    track = Track(np.array([0.0]), np.zeros(1), np.zeros(1))
    for rec in (Recording({"ball": track}, run=" a"), Recording({"ball ": track})):
        with pytest.raises(RecordingError, match="starts or ends with white space"):
            format_recordings([rec])


# --------------------------------------------------------------------------- comparison


def falling_ball(frames: int = 31, fps: float = 30.0) -> tuple[Scene, Trajectory]:
    scene = Scene(
        "drop",
        (Body("ball", Circle(0.1), (1.0, 9.0), velocity=(0.5, 0.0), angular_velocity=2.0),),
        bounds=(0, 0, 10, 10),
        fps=fps,
        frames=frames,
    )
    return scene, PymunkSimulator().simulate(scene)


def test_residuals_interpolate_the_simulation_at_recorded_times():
    scene, traj = falling_ball()
    # The same substeps recorded at every substep are the truth between the 30 fps frames.
    dense = PymunkSimulator().simulate(replace(scene, fps=300.0, frames=301, substeps=1))
    k = np.array([0, 4, 150, 231, 299])
    truth = Recording.from_trajectory(dense, times=dense.times[k])
    np.testing.assert_array_equal(truth.track("ball").y, dense.body("ball")[k, 1])
    res, lin = truth.residuals(traj), truth.residuals(traj, method="linear")
    assert res.shape == (15,)
    assert np.abs(res).max() < 5e-4  # Hermite, with the velocities: ~g·dt·h/4
    assert np.abs(lin).max() > 1e-3  # linear: ~g·dt²/8
    assert truth.rms(traj, fields=["x"])["x"] < 1e-9  # uniform motion is exact either way
    # a recording of the simulation itself has zero residual
    own = Recording.from_trajectory(traj, times=traj.times[[0, 7, 30]])
    np.testing.assert_allclose(own.residuals(traj), 0.0, atol=1e-12)
    assert Recording.from_trajectory(traj).n_samples == 31


def test_residuals_respect_fields_and_wrap_angles():
    _, traj = falling_ball()
    t = np.array([0.1, 0.2])
    sim = Recording.from_trajectory(traj, times=t)
    tr = sim.track("ball")
    shifted = Recording(
        {"ball": Track(t, tr.x + 0.1, tr.y, tr.angle + 2 * math.pi + 0.05)}, fields=("x", "angle")
    )
    res = shifted.residuals(traj)  # default: the measured fields only
    np.testing.assert_allclose(res, [-0.1, -0.1, -0.05, -0.05], atol=1e-9)
    np.testing.assert_allclose(shifted.residuals(traj, fields=["y"]), 0.0, atol=1e-12)
    no_angle = Recording({"ball": Track(t, tr.x, tr.y)})
    assert no_angle.residuals(traj).shape == (4,)
    with pytest.raises(RecordingError, match=r"no track .* has field 'angle'"):
        no_angle.residuals(traj, fields=["angle"])


def test_residuals_refuse_recordings_outside_the_simulation():
    _, traj = falling_ball(frames=16)  # 0 .. 0.5 s
    late = Recording({"ball": Track(np.array([0.2, 0.9]), np.zeros(2), np.zeros(2))}, run="r")
    with pytest.raises(
        RecordingError, match=r"0.2..0.9 s but the simulation covers 0..0.5 s.*at least 28"
    ):
        late.residuals(traj)
    assert late.frames_for(30.0) == 28
    ghost = Recording({"cube": Track(np.array([0.1]), np.zeros(1), np.zeros(1))})
    with pytest.raises(RecordingError, match="'cube' is not simulated"):
        ghost.residuals(traj)


def test_track_checks_its_arrays():
    with pytest.raises(RecordingError, match="increase strictly"):
        Track(np.array([0.0, 0.2, 0.1]), np.zeros(3), np.zeros(3))
    with pytest.raises(RecordingError, match="as long as t"):
        Track(np.array([0.0, 0.1]), np.zeros(3), np.zeros(2))
    with pytest.raises(RecordingError, match="NaN"):
        Track(np.array([0.0, 0.1]), np.array([0.0, np.nan]), np.zeros(2))


def test_the_accuracy_a_recording_states_survives_its_csv():
    track = Track(np.arange(3.0), np.zeros(3), np.ones(3))
    runs = [Recording({"b": track}, run="a", accuracy=2e-3), Recording({"b": track}, run="b")]
    back = parse_recordings(format_recordings(runs))
    assert [r.accuracy for r in back] == [2e-3, 2e-3]  # one line per file: the coarsest
    assert parse_recordings("t,body,x,y\n0,b,0,0\n")[0].accuracy == 0.0
    assert parse_recordings("# accuracy: 0.004 m\nt,body,x,y\n0,b,0,0\n")[0].accuracy == 0.004
    with pytest.raises(RecordingError, match=r"line 1 \(comment\): accuracy 'x'"):
        parse_recordings("# accuracy: x\nt,body,x,y\n0,b,0,0\n")


def test_the_angle_accuracy_a_recording_states_survives_its_csv() -> None:
    track = Track(np.arange(3.0), np.zeros(3), np.ones(3), np.zeros(3))
    runs = [
        Recording({"b": track}, run="a", accuracy=2e-3, angle_accuracy=3e-3),
        Recording({"b": track}, run="b", angle_accuracy=1e-3),
    ]
    text = format_recordings(runs)
    assert "# accuracy: 0.002\n# angle accuracy: 0.003\n" in text
    back = parse_recordings(text)
    assert [(r.accuracy, r.angle_accuracy) for r in back] == [(2e-3, 3e-3)] * 2
    assert parse_recordings("t,body,x,y\n0,b,0,0\n")[0].angle_accuracy == 0.0
    text = "# angle accuracy: 0.004 rad\nt,body,x,y\n0,b,0,0\n"
    assert [(r.accuracy, r.angle_accuracy) for r in parse_recordings(text)] == [(0.0, 0.004)]
    with pytest.raises(RecordingError, match=r"line 2 \(comment\): angle accuracy '-1' is not rad"):
        parse_recordings("# accuracy: 0.002\n# angle accuracy: -1\nt,body,x,y\n0,b,0,0\n")
    with pytest.raises(RecordingError, match=r"angle_accuracy = inf: expected radians >= 0"):
        Recording({"b": track}, angle_accuracy=math.inf)


def test_a_cell_over_the_csv_field_limit_is_a_recording_error() -> None:
    text = "t,body,x,y\n0,a,0,0\n0.1,a," + "9" * 140_000 + ",0\n"
    with pytest.raises(RecordingError, match=r"rec.csv: line 3: not readable as CSV .*131072"):
        parse_recordings(text, source="rec.csv")


@pytest.mark.parametrize(
    ("column", "cell", "limit"),
    [
        ("x", "1e300", r"\|x\| <= 1e\+06 m \(the largest coordinate"),
        ("y", "-2e6", r"\|y\| <= 1e\+06 m"),
        ("t", "1e300", r"t <= 1e\+06 s \(the longest a scene simulates: 100000 frames at 0.1"),
        ("angle", "-1e12", r"\|angle\| <= 1e\+11 rad"),
    ],
)
def test_values_beyond_the_scene_limits_are_refused_naming_the_limit(
    column: str, cell: str, limit: str
) -> None:
    cells = {"t": "0.1", "body": "b", "x": "0.5", "y": "0.5", "angle": "0"}
    cells[column] = cell
    text = "t,body,x,y,angle\n0,b,0,0,0\n" + ",".join(cells.values()) + "\n"
    with pytest.raises(RecordingError) as exc:
        parse_recordings(text, source="rec.csv")
    said = str(exc.value)
    assert said.startswith(f"rec.csv: line 3 (data row 2), column {column!r}: {column} = ")
    assert re.search(f"is beyond the scene limit {limit}", said), said


def test_values_at_the_scene_limits_are_read() -> None:
    from physbench.limits import MAX_ANGLE, MAX_COORDINATE, MAX_TIME

    last = f"{MAX_TIME!r},b,{MAX_COORDINATE!r},{-MAX_COORDINATE!r},{MAX_ANGLE!r}"
    text = f"t,body,x,y,angle\n0,b,0,0,0\n{last}\n"
    (rec,) = parse_recordings(text)
    assert rec.t_end == MAX_TIME and rec.track("b").angle[-1] == MAX_ANGLE


def test_the_limits_are_the_scenes(tmp_path) -> None:
    from physbench import limits, scene

    assert scene.MAX_COORDINATE is limits.MAX_COORDINATE and scene.FPS is limits.FPS
    longest = (limits.MAX_FRAMES - 1) / limits.FPS[0]  # the longest simulation
    assert longest <= limits.MAX_TIME
    assert limits.MAX_ANGLE >= limits.MAX_SPIN * limits.MAX_TIME


def test_the_cli_refuses_an_out_of_range_recording_in_one_line_without_warnings(tmp_path) -> None:
    # -W error: any warning (numpy's overflow among them) would end the run with a traceback.
    import subprocess
    import sys

    (tmp_path / "rec.csv").write_text("t,body,x,y\n0,ball,0,47\n0.1,ball,1e300,46.9\n")
    done = subprocess.run(
        [
            sys.executable,
            "-W",
            "error",
            "-m",
            "physbench",
            "discover",
            "rec.csv",
            "--scene",
            "ball_drop",
        ],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 2 and done.stdout == "", done
    assert done.stderr == (
        "physbench discover: error: rec.csv: line 3 (data row 2), column 'x': x = 1e+300 m is "
        "beyond the scene limit |x| <= 1e+06 m (the largest coordinate a scene has)\n"
    )

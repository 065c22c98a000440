"""Scene files: exact round trip, and bad inputs named by key, value and line."""

from __future__ import annotations

from pathlib import Path

import pytest

from physbench.errors import SceneError
from physbench.plugins import build_registry
from physbench.scene_toml import dumps_scene, load_scene, loads_scene, save_scene

GOOD = """\
name = "demo"
bounds = [0.0, 0.0, 4.0, 4.0]
gravity = [0.0, -9.81]
fps = 30.0
frames = 20
substeps = 8
test_body = "test"

[[bodies]]
name = "test"
shape = { kind = "circle", radius = 0.3 }
position = [1.0, 2.0]
mass = 5.0

[[bodies]]
name = "a"
shape = { kind = "box", width = 0.4, height = 0.4 }
position = [2.5, 0.5]
mass = 3.0
elasticity = 0.4
friction = 0.6

[[bodies]]
name = "tri"
shape = { kind = "polygon", points = [[-0.2, -0.2], [0.2, -0.2], [0.0, 0.3]] }
position = [3.2, 1.0]

[[statics]]
kind = "segment"
a = [0.0, 0.0]
b = [4.0, 0.0]

[[forces]]
body = "test"
vector = [100.0, 0.0]
start = 0.0
end = 0.2

[[joints]]
a = "tri"
anchor = [3.2, 1.5]

[[unknowns]]
body = "a"
param = "mass"
range = [1.0, 10.0]
"""


def test_good_file_loads() -> None:
    s = loads_scene(GOOD)
    assert s.body_names == ("test", "a", "tri")
    assert s.bodies[1].shape.kind == "box" and s.joints[0].b is None
    assert s.unknowns[0].key == "a.mass"


def builtin_scenes() -> list[tuple[str, int]]:
    names = build_registry(env=False).names("scene")
    return [(n, seed) for n in names for seed in (0, 3)]


@pytest.mark.parametrize(("name", "seed"), builtin_scenes())
def test_builtin_scene_round_trip_is_exact(name: str, seed: int, tmp_path: Path) -> None:
    scene = build_registry(env=False).get("scene", name)(seed)
    text = dumps_scene(scene)
    assert loads_scene(text) == scene
    path = tmp_path / f"{name}.toml"
    save_scene(scene, path)
    assert load_scene(path) == scene
    assert dumps_scene(load_scene(path)) == text


# (replace this, with that, expected key, expected line, message fragment)
BAD = [
    (
        "radius = 0.3 }",
        "radius = -0.3 }",
        "bodies[0].shape.radius",
        11,
        "must lie in [1e-06, 1e+06] m",
    ),
    (
        'kind = "circle"',
        'kind = "ellipse"',
        "bodies[0].shape.kind",
        11,
        "unknown shape; known: circle, box, polygon",
    ),
    ("mass = 5.0", "mass = -2.0", "bodies[0].mass", 13, "mass must lie in [1e-06, 1e+06] kg"),
    ("elasticity = 0.4", "elasticity = 1.5", "bodies[1].elasticity", 20, "must lie in [0.0, 1.0]"),
    ("friction = 0.6", "friction = -0.1", "bodies[1].friction", 21, "must lie in"),
    (
        "position = [1.0, 2.0]",
        "position = [9.0, 2.0]",
        "bodies[0].position",
        12,
        "inside the world bounds",
    ),
    ("position = [1.0, 2.0]", "position = [1.0]", "bodies[0].position", 12, "pair of numbers"),
    ('name = "a"', 'name = "test"', "bodies[1].name", 16, "duplicate body name"),
    ("frames = 20", "frames = 0", "frames", 5, "whole number in"),
    ("fps = 30.0", "fps = -30.0", "fps", 4, "must lie in [0.1, 100000] Hz"),
    ("bounds = [0.0, 0.0, 4.0, 4.0]", "bounds = [4.0, 0.0, 0.0, 4.0]", "bounds", 2, "min < max"),
    ('test_body = "test"', 'test_body = "nobody"', "test_body", 7, "no such body"),
    ("mass = 3.0", 'mass = 3.0\ncolour = "red"', "bodies[1].colour", 20, "unknown key"),
    (
        'param = "mass"',
        'param = "colour"',
        "unknowns[0].param",
        45,
        "unknown parameter; known: mass",
    ),
    ("range = [1.0, 10.0]", "range = [10.0, 1.0]", "unknowns[0].range", 46, "low < high"),
    (
        "range = [1.0, 10.0]",
        "range = [-1.0, 10.0]",
        "unknowns[0].range[0]",
        46,
        "mass must lie in [1e-06, 1e+06] kg",
    ),
    ('body = "a"\nparam', 'body = "ghost"\nparam', "unknowns[0].body", 44, "no such body"),
    ("end = 0.2", "end = 0.0", "forces[0].end", 37, "end > start"),
    ('body = "test"\nvector', 'body = "ghost"\nvector', "forces[0].body", 34, "no such body"),
    ('a = "tri"', 'a = "ghost"', "joints[0].a", 40, "no such body"),
    (
        "[-0.2, -0.2], [0.2, -0.2], [0.0, 0.3]",
        "[0.0, 0.3], [0.2, -0.2], [-0.2, -0.2]",
        "bodies[2].shape.points",
        25,
        "convex",
    ),
    ("b = [4.0, 0.0]", "b = [0.0, 0.0]", "statics[0].b", 31, "end points must differ"),
    ('kind = "segment"', 'kind = "circle"', "statics[0].kind", 29, "unknown static kind"),
    ("gravity = [0.0, -9.81]", 'gravity = "down"', "gravity", 3, "pair of numbers"),
    ("substeps = 8", "substeps = 2.5", "substeps", 6, "whole number"),
    ('name = "demo"', 'title = "demo"', "title", 1, "unknown key"),
    # Found by fuzzing (issue 14): each raised TypeError, OverflowError, ZeroDivisionError or
    # MemoryError, in loading or later in a simulator or the rasteriser.
    ('kind = "circle"', 'kind = ["circle"]', "bodies[0].shape.kind", 11, "unknown shape"),
    ('body = "a"\nparam', 'body = ["a"]\nparam', "unknowns[0].body", 44, "no such body"),
    ('test_body = "test"', 'test_body = { name = "test" }', "test_body", 7, "no such body"),
    ('a = "tri"', 'a = { name = "tri" }', "joints[0].a", 40, "no such body"),
    ("bounds = [0.0, 0.0, 4.0, 4.0]", "bounds = 0", "bounds", 2, "[xmin, ymin, xmax, ymax]"),
    (
        "bounds = [0.0, 0.0, 4.0, 4.0]",
        "bounds = [0.0, 0.0, 4.0, 1e30]",
        "bounds[3]",
        2,
        "must lie in [-1e+06, 1e+06] m",
    ),
    (
        "height = 0.4",
        "height = 5e-324",
        "bodies[1].shape.height",
        17,
        "must lie in [1e-06, 1e+06] m",
    ),
    ("substeps = 8", f"substeps = {2**62}", "substeps", 6, "whole number in [1, 10000]"),
]


@pytest.mark.parametrize(
    ("old", "new", "key", "line", "fragment"), BAD, ids=[b[2] + ":" + b[4][:18] for b in BAD]
)
def test_bad_scene_file_names_key_value_and_line(
    old: str, new: str, key: str, line: int, fragment: str
) -> None:
    assert old in GOOD
    text = GOOD.replace(old, new, 1)
    with pytest.raises(SceneError) as info:
        loads_scene(text, source="bad.toml")
    err = info.value
    assert err.key == key, str(err)
    assert err.line == line, str(err)
    assert fragment in str(err)
    assert str(err).startswith(f"bad.toml:{line}: {key} = ")


def test_syntax_error_reports_line() -> None:
    with pytest.raises(SceneError, match=r"bad.toml:3: not valid TOML"):
        loads_scene('name = "x"\nfps = 30\nframes = = 3\n', source="bad.toml")


def test_file_that_is_not_utf8_is_a_scene_error_naming_the_byte(tmp_path: Path) -> None:
    path = tmp_path / "latin1.toml"
    path.write_bytes(GOOD.encode() + b'description = "caf\xe9"\n')
    with pytest.raises(SceneError, match=r"latin1.toml:47: byte \d+ \(b'\\xe9'\) is not UTF-8"):
        load_scene(path)


def test_deeply_nested_arrays_are_a_scene_error() -> None:
    deep = "[" * 2000 + "]" * 2000
    with pytest.raises(SceneError, match="nested too deeply"):
        loads_scene(f"name = {deep}\n" + GOOD, source="deep.toml")


def test_missing_file_is_a_scene_error(tmp_path: Path) -> None:
    with pytest.raises(SceneError, match="cannot read scene file"):
        load_scene(tmp_path / "nope.toml")

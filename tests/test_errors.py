"""Typed errors: each is a PhysbenchError and the builtin error it stands for, and its message
names the bad value, where it was found and what would be accepted."""

from __future__ import annotations

import pytest

from physbench.errors import (
    PhysbenchError,
    PluginError,
    SceneError,
    SimulationError,
    UnknownNameError,
)


def test_every_error_is_a_physbench_error_and_its_builtin_kind() -> None:
    assert issubclass(UnknownNameError, PhysbenchError) and issubclass(UnknownNameError, KeyError)
    assert issubclass(SceneError, PhysbenchError) and issubclass(SceneError, ValueError)
    assert issubclass(SimulationError, PhysbenchError)
    assert issubclass(SimulationError, RuntimeError)
    assert issubclass(PluginError, PhysbenchError)


def test_an_unknown_name_lists_the_known_names_sorted_and_is_not_quoted() -> None:
    err = UnknownNameError("scene", "nope", ["b_scene", "a_scene"], where="in the registry")
    assert str(err) == (
        "unknown scene 'nope' in the registry; known scenes in the registry: a_scene, b_scene"
    )
    assert (err.kind, err.name, err.known) == ("scene", "nope", ["a_scene", "b_scene"])
    assert str(UnknownNameError("engine", "x", [])) == (
        "unknown engine 'x'; known engines: (none registered)"
    )


def test_the_plural_of_body_is_bodies() -> None:
    assert str(UnknownNameError("body", "c", ["a", "b"])) == "unknown body 'c'; known bodies: a, b"


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"key": "fps", "value": 0, "source": "s.toml", "line": 3}, "s.toml:3: fps = 0: bad"),
        ({"key": "fps", "value": "x", "source": "s.toml"}, "s.toml: fps = 'x': bad"),
        ({"key": "fps", "value": None, "line": 3}, "line 3: fps = None: bad"),
        ({}, "bad"),
    ],
)
def test_a_scene_error_says_where_which_key_and_value(
    kwargs: dict[str, object], message: str
) -> None:
    err = SceneError("bad", **kwargs)  # type: ignore[arg-type]
    assert str(err) == message and err.reason == "bad"
    assert (err.key, err.value, err.source, err.line) == tuple(
        kwargs.get(k) for k in ("key", "value", "source", "line")
    )


def test_a_simulation_error_names_the_engine_frame_and_body() -> None:
    err = SimulationError("NaN state", engine="pymunk", frame=12, body="a")
    assert str(err) == "[pymunk] frame 12, body 'a': NaN state"
    assert (err.engine, err.frame, err.body) == ("pymunk", 12, "a")
    assert str(SimulationError("far away", engine="box2d", frame=0)) == "[box2d] frame 0: far away"


def test_plurals_of_the_kinds_physbench_names() -> None:
    from physbench.errors import plural

    words = {"body": "bodies", "scene": "scenes", "box": "boxes", "key": "keys", "alias": "aliases"}
    assert {w: plural(w) for w in words} == words
    err = UnknownNameError("body of recording 'r'", "z", ["a"])
    assert str(err) == "unknown body of recording 'r' 'z'; known bodies of recording 'r': a"
    assert "known drag laws: " in str(UnknownNameError("drag law", "x", ["linear"]))


def test_counts_agree_with_their_nouns() -> None:
    from physbench.errors import counted

    assert [counted(n, "worker") for n in (0, 1, 2)] == ["0 workers", "1 worker", "2 workers"]
    assert (counted(1, "body"), counted(3, "body")) == ("1 body", "3 bodies")

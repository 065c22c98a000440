"""Scenes to and from TOML. Loading validates and names the bad key, value and line.

Layout (every table but ``[[bodies]]`` optional)::

    name = "three_circles"
    bounds = [0.0, 0.0, 4.0, 4.0]
    gravity = [0.0, -9.81]
    fps = 30.0
    frames = 30
    substeps = 10
    test_body = "test"

    [[bodies]]
    name = "test"
    shape = { kind = "circle", radius = 0.3 }     # or box (width, height), polygon (points)
    position = [1.0, 2.0]
    mass = 5.0

    [[statics]]
    kind = "segment"                                # or polygon (points)
    a = [0.0, 0.0]
    b = [4.0, 0.0]

    [[forces]]
    body = "test"
    vector = [40.0, 0.0]
    start = 0.0
    end = 0.2

    [[joints]]
    a = "bob"
    anchor = [2.0, 3.0]                             # b = "world" by default

    [[unknowns]]
    body = "a"
    param = "mass"
    range = [1.0, 10.0]
"""

from __future__ import annotations

import math
import re
import tomllib
from dataclasses import fields
from pathlib import Path
from typing import Any

import tomli_w

from physbench.errors import SceneError
from physbench.scene import (
    SHAPE_KINDS,
    Body,
    Box,
    Circle,
    Force,
    Joint,
    Polygon,
    Scene,
    Segment,
    Shape,
    Static,
    StaticPolygon,
    body_unknown,
)

_TOP_KEYS = {
    "name", "description", "bounds", "gravity", "fps", "frames", "substeps", "test_body",
    "bodies", "statics", "forces", "joints", "unknowns", "meta",
}  # fmt: skip
_BODY_KEYS = {f.name for f in fields(Body)}
_FORCE_KEYS = {"body", "vector", "start", "end", "kind"}
_JOINT_KEYS = {"kind", "a", "b", "anchor"}
_UNKNOWN_KEYS = {"body", "param", "range"}
_SEGMENT_KEYS = {"kind", "a", "b", "radius", "elasticity", "friction"}
_SPOLY_KEYS = {"kind", "points", "elasticity", "friction"}
_SHAPE_KEYS = {
    "circle": {"kind", "radius"},
    "box": {"kind", "width", "height"},
    "polygon": {"kind", "points"},
}


# --------------------------------------------------------------------------- loading


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene file."""
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise SceneError(f"cannot read scene file: {exc.strerror}", source=str(path)) from exc
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise SceneError(
            f"byte {exc.start} ({data[exc.start : exc.start + 1]!r}) is not UTF-8; scene files "
            "are UTF-8 TOML text",
            source=str(path),
            line=data.count(b"\n", 0, exc.start) + 1,
        ) from None
    return loads_scene(text, source=str(path))


def loads_scene(text: str, *, source: str = "<scene>") -> Scene:
    """Parse and validate a scene from TOML text; errors carry ``source:line``."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        m = re.search(r"line (\d+)", str(exc))
        raise SceneError(
            f"not valid TOML: {exc}", source=source, line=int(m.group(1)) if m else None
        ) from exc
    except RecursionError:  # tomllib recurses once per nesting level of arrays and tables
        raise SceneError(
            "arrays or tables nested too deeply to parse; a scene nests at most 3 levels",
            source=source,
        ) from None
    try:
        return scene_from_dict(data).validate()
    except SceneError as exc:
        if exc.key is None:
            raise
        raise SceneError(
            exc.reason, key=exc.key, value=exc.value, source=source, line=locate(text, exc.key)
        ) from None


def _vec_or_raw(v: Any) -> Any:
    return tuple(v) if isinstance(v, list) else v


def _check_keys(key: str, table: object, allowed: set[str]) -> dict[str, Any]:
    if not isinstance(table, dict):
        raise SceneError("must be a table", key=key, value=table)
    for k in table:
        if k not in allowed:
            raise SceneError(
                f"unknown key; allowed: {', '.join(sorted(allowed))}",
                key=f"{key}.{k}" if key else k,
                value=table[k],
            )
    return table


def _points(v: Any) -> Any:
    return tuple(_vec_or_raw(p) for p in v) if isinstance(v, list) else v


def _shape(key: str, raw: object) -> Shape:
    if not isinstance(raw, dict):
        raise SceneError(
            'must be a table like { kind = "circle", radius = 0.3 }', key=key, value=raw
        )
    kind = raw.get("kind")
    if not isinstance(kind, str) or kind not in _SHAPE_KEYS:
        raise SceneError(
            f"unknown shape; known: {', '.join(SHAPE_KINDS)}", key=f"{key}.kind", value=kind
        )
    _check_keys(key, raw, _SHAPE_KEYS[kind])
    try:
        if kind == "circle":
            return Circle(radius=raw["radius"])
        if kind == "box":
            return Box(width=raw["width"], height=raw["height"])
        return Polygon(points=_points(raw["points"]))
    except KeyError as exc:
        raise SceneError(f"missing key {exc.args[0]!r} for a {kind}", key=key, value=raw) from None


def _list_of_tables(data: dict[str, Any], name: str) -> list[dict[str, Any]]:
    v = data.get(name, [])
    if not isinstance(v, list) or not all(isinstance(t, dict) for t in v):
        raise SceneError(f"must be an array of tables ([[{name}]])", key=name, value=v)
    return v


def _require(key: str, table: dict[str, Any], name: str) -> Any:
    if name not in table:
        raise SceneError(f"missing required key {name!r}", key=key, value=table)
    return table[name]


def scene_from_dict(data: dict[str, Any]) -> Scene:
    """Build a :class:`Scene` from plain data (as parsed TOML). Does not validate values."""
    _check_keys("", data, _TOP_KEYS)
    bodies = []
    for i, raw in enumerate(_list_of_tables(data, "bodies")):
        k = f"bodies[{i}]"
        _check_keys(k, raw, _BODY_KEYS)
        kw = {n: _vec_or_raw(v) for n, v in raw.items() if n != "shape"}
        _require(k, raw, "name")
        _require(k, raw, "position")
        bodies.append(Body(shape=_shape(f"{k}.shape", _require(k, raw, "shape")), **kw))
    statics: list[Static] = []
    for i, raw in enumerate(_list_of_tables(data, "statics")):
        k = f"statics[{i}]"
        kind = raw.get("kind", "segment")
        if kind == "segment":
            _check_keys(k, raw, _SEGMENT_KEYS)
            statics.append(
                Segment(
                    **{n: _vec_or_raw(v) for n, v in raw.items()}
                    | {
                        "a": _vec_or_raw(_require(k, raw, "a")),
                        "b": _vec_or_raw(_require(k, raw, "b")),
                    }
                )
            )
        elif kind == "polygon":
            _check_keys(k, raw, _SPOLY_KEYS)
            statics.append(
                StaticPolygon(
                    **{n: v for n, v in raw.items()}
                    | {"points": _points(_require(k, raw, "points"))}
                )
            )
        else:
            raise SceneError(
                "unknown static kind; known: segment, polygon", key=f"{k}.kind", value=kind
            )
    forces = []
    for i, raw in enumerate(_list_of_tables(data, "forces")):
        k = f"forces[{i}]"
        _check_keys(k, raw, _FORCE_KEYS)
        _require(k, raw, "body")
        _require(k, raw, "vector")
        forces.append(Force(**{n: _vec_or_raw(v) for n, v in raw.items()}))
    joints = []
    for i, raw in enumerate(_list_of_tables(data, "joints")):
        k = f"joints[{i}]"
        _check_keys(k, raw, _JOINT_KEYS)
        _require(k, raw, "a")
        _require(k, raw, "anchor")
        kw = {n: _vec_or_raw(v) for n, v in raw.items()}
        if kw.get("b") == "world":
            kw["b"] = None
        joints.append(Joint(**kw))
    unknowns = []
    for i, raw in enumerate(_list_of_tables(data, "unknowns")):
        k = f"unknowns[{i}]"
        _check_keys(k, raw, _UNKNOWN_KEYS)
        rng = _require(k, raw, "range")
        if not isinstance(rng, list) or len(rng) != 2:
            raise SceneError("must be [low, high]", key=f"{k}.range", value=rng)
        unknowns.append(
            body_unknown(_require(k, raw, "body"), _require(k, raw, "param"), rng[0], rng[1])
        )
    top = {
        n: _vec_or_raw(data[n])
        for n in (
            "name",
            "description",
            "bounds",
            "gravity",
            "fps",
            "frames",
            "substeps",
            "test_body",
        )
        if n in data
    }
    if "name" not in top:
        raise SceneError("missing required key 'name'", key="name", value=None)
    meta = data.get("meta", {})
    if not isinstance(meta, dict):
        raise SceneError("must be a table", key="meta", value=meta)
    if isinstance(top.get("fps"), int) and not isinstance(top.get("fps"), bool):
        top["fps"] = float(top["fps"])
    return Scene(
        bodies=tuple(bodies),
        statics=tuple(statics),
        forces=tuple(forces),
        joints=tuple(joints),
        unknowns=tuple(unknowns),
        meta=meta,
        **top,
    )


def locate(text: str, key: str) -> int | None:
    """Best-effort line number (1-based) of a dotted key path like ``bodies[2].shape.radius``.

    Finds the n-th ``[[table]]`` header, then the first line of that table defining the leaf
    key (or the nested key's parent, for inline tables).
    """
    parts = re.findall(r"([A-Za-z_][A-Za-z0-9_]*)(?:\[(\d+)\])?", key)
    if not parts:
        return None
    lines = text.splitlines()
    start, end = 0, len(lines)
    first, index = parts[0]
    rest = [p[0] for p in parts[1:]]
    if index:
        header = re.compile(rf"^\s*\[\[\s*{re.escape(first)}\s*\]\]")
        hits = [i for i, ln in enumerate(lines) if header.match(ln)]
        n = int(index)
        if not hits:  # an element of an array value, such as bounds[3]: the array's line
            return locate(text, ".".join([first, *rest]))
        if n >= len(hits):
            return None
        start = hits[n] + 1
        nxt = [i for i, ln in enumerate(lines) if i >= start and re.match(r"^\s*\[", ln)]
        end = nxt[0] if nxt else len(lines)
        if not rest:
            return hits[n] + 1
        leaf = rest[0]
    else:
        leaf = first
        nxt = [i for i, ln in enumerate(lines) if re.match(r"^\s*\[", ln)]
        end = nxt[0] if nxt else len(lines)
    pattern = re.compile(rf"^\s*{re.escape(leaf)}\s*=")
    for i in range(start, end):
        if pattern.match(lines[i]):
            return i + 1
    return start if index else None


# --------------------------------------------------------------------------- saving


def _clean(v: Any) -> Any:
    if isinstance(v, tuple | list):
        return [_clean(x) for x in v]
    if isinstance(v, float) and math.isinf(v):
        raise SceneError("cannot save an infinite value", value=v)
    return v


def _shape_dict(s: Shape) -> dict[str, Any]:
    if isinstance(s, Circle):
        return {"kind": "circle", "radius": s.radius}
    if isinstance(s, Box):
        return {"kind": "box", "width": s.width, "height": s.height}
    return {"kind": "polygon", "points": _clean(s.points)}


def scene_to_dict(scene: Scene) -> dict[str, Any]:
    """Plain data for a scene; ``scene_from_dict(scene_to_dict(s)) == s``."""
    d: dict[str, Any] = {"name": scene.name}
    if scene.description:
        d["description"] = scene.description
    d |= {
        "bounds": _clean(scene.bounds),
        "gravity": _clean(scene.gravity),
        "fps": float(scene.fps),
        "frames": scene.frames,
        "substeps": scene.substeps,
    }
    if scene.test_body is not None:
        d["test_body"] = scene.test_body
    if scene.meta:
        d["meta"] = dict(scene.meta)
    bodies = []
    for b in scene.bodies:
        bd: dict[str, Any] = {"name": b.name, "shape": _shape_dict(b.shape)}
        for f in fields(Body):
            if f.name in ("name", "shape"):
                continue
            v = getattr(b, f.name)
            if v is None:
                continue
            bd[f.name] = _clean(v)
        bodies.append(bd)
    d["bodies"] = bodies
    if scene.statics:
        d["statics"] = [
            {
                "kind": "segment",
                "a": _clean(s.a),
                "b": _clean(s.b),
                "radius": s.radius,
                "elasticity": s.elasticity,
                "friction": s.friction,
            }
            if isinstance(s, Segment)
            else {
                "kind": "polygon",
                "points": _clean(s.points),
                "elasticity": s.elasticity,
                "friction": s.friction,
            }
            for s in scene.statics
        ]
    if scene.forces:
        d["forces"] = [
            {
                "body": f.body,
                "kind": f.kind,
                "vector": _clean(f.vector),
                "start": f.start,
                "end": f.end,
            }
            for f in scene.forces
        ]
    if scene.joints:
        d["joints"] = [
            {"kind": j.kind, "a": j.a, "b": j.b or "world", "anchor": _clean(j.anchor)}
            for j in scene.joints
        ]
    if scene.unknowns:
        d["unknowns"] = [
            {"body": u.owner, "param": u.name, "range": [u.low, u.high]} for u in scene.unknowns
        ]
    return d


def dumps_scene(scene: Scene) -> str:
    return tomli_w.dumps(scene_to_dict(scene))


def save_scene(scene: Scene, path: str | Path) -> None:
    Path(path).write_text(dumps_scene(scene), encoding="utf-8")

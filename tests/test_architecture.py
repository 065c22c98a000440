"""The architecture rules of docs/architecture.md, read from the code: imports point down the
layers, render and video import in one direction, no import cycles, no function over 100 lines,
no two modules share a base name for different concepts, and one driver calls estimators."""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "physbench"

#: The layers, lowest first (docs/architecture.md). A module takes the layer of the longest
#: prefix listed; every module must have one.
LAYERS: dict[str, int] = {
    # 0 contracts and data: what every component may import
    "physbench": 0,  # the package itself: __version__ (its lazy API forwarding is excepted)
    "physbench.errors": 0,
    "physbench.limits": 0,
    "physbench.numeric": 0,
    "physbench.kinds": 0,
    "physbench.hookspecs": 0,
    "physbench.requirements": 0,
    "physbench.parameter": 0,
    "physbench.unknowns": 0,
    "physbench.scene": 0,
    "physbench.scene_toml": 0,
    "physbench.trajectory": 0,
    "physbench.recording": 0,
    "physbench.observation": 0,
    "physbench.calibration": 0,
    "physbench.codec": 0,
    "physbench.metrics": 0,
    "physbench.cost": 0,
    "physbench.teardown": 0,
    "physbench.posterior": 0,
    "physbench.simulators.base": 0,
    "physbench.render.base": 0,
    "physbench.estimators.base": 0,
    "physbench.effects.base": 0,
    # 1 the registry and the component factory
    "physbench.plugins": 1,
    "physbench.components": 1,
    # 2 built-in components (and the shipped data sets)
    "physbench.simulators": 2,
    "physbench.render": 2,
    "physbench.estimators": 2,
    "physbench.effects": 2,
    "physbench.video": 2,
    "physbench.scenes": 2,
    "physbench.datasets": 2,
    "physbench.examples": 2,
    # 3 orchestration: what runs components
    "physbench.loop": 3,
    "physbench.experiment": 3,
    "physbench.bench": 3,
    "physbench.discover": 3,
    "physbench.plotting": 3,
    "physbench.testing": 3,
    # 4 the CLI and the Python API
    "physbench.api": 4,
    "physbench.cli": 4,
    "physbench.commands": 4,
    "physbench.__main__": 4,
}
NAMES = {0: "contracts", 1: "registry and factory", 2: "built-in components", 3: "orchestration"}
NAMES[4] = "CLI and API"

#: Packages of built-in components and the orchestration modules they must never import (the
#: issue's rule, stricter than the layers alone for modules within a built-in's own folder).
BUILTINS = ("estimators", "render", "simulators", "effects", "video")
ORCHESTRATION = ("experiment", "bench", "discover", "api", "commands", "cli", "loop")

#: Base names that several modules share for the same concept, and why.
SAME_CONCEPT = {
    "base": "the contract of a component kind, in that kind's package",
    "estimator": "the estimator class of a learned estimator's package",
    "train": "training a learned estimator; commands/train.py is the command for it",
    "training_data": "the simulated training pairs of a learned estimator",
    "network": "the torch network of a learned estimator",
    "weights": "shipped and trained weights of a learned estimator",
    "compare": "comparing sweeps; commands/compare.py is the command for it",
    "plugins": "the plugin registry; commands/plugins.py is the command that lists it",
    "track": "tracking video; commands/track.py is the command for it",
    "posterior": "the posterior; plotting/posterior.py draws it",
    "report": "the HTML report page of a job (a sweep's, a discovery's)",
    "bench": "sweeps; commands/bench.py is the command that runs one",
    "discover": "discovery; commands/discover.py is the command that runs it",
    "scenes": "the built-in scenes; commands/scenes.py is the command that lists them",
    "datasets": "the shipped data sets; commands/datasets.py is the command that lists them",
    "simulators": "simulators; testing/simulators.py is their conformance kit",
    "estimators": "estimators; testing/estimators.py is their conformance kit",
    "effects": "effects; testing/effects.py is their conformance kit",
}


def modules() -> dict[str, Path]:
    out = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


MODULES = modules()


def _type_checking_nodes(tree: ast.AST) -> set[int]:
    skip: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            skip.update(id(n) for n in ast.walk(node))
    return skip


def imports_of(name: str) -> set[str]:
    """The physbench modules ``name`` imports, at module level or inside functions (imports under
    ``TYPE_CHECKING`` only name types and are left out)."""
    tree = ast.parse(MODULES[name].read_text())
    skip = _type_checking_nodes(tree)
    out: set[str] = set()
    for node in ast.walk(tree):
        if id(node) in skip:
            continue
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names if a.name.startswith("physbench"))
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            if not node.module.startswith("physbench"):
                continue
            subs = [f"{node.module}.{a.name}" for a in node.names]
            found = [s for s in subs if s in MODULES]
            out.update(found)
            if len(found) < len(subs):  # names defined in the module itself
                out.add(node.module)
    if name == "physbench":
        out.discard("physbench.api")  # __getattr__ forwards the public API, on attribute access
    out.discard(name)
    return out


GRAPH = {name: imports_of(name) for name in MODULES}


def layer(name: str) -> int:
    best = max((p for p in LAYERS if name == p or name.startswith(p + ".")), key=len, default="")
    if not best:
        raise AssertionError(f"{name} has no layer: add it to LAYERS and docs/architecture.md")
    return LAYERS[best]


def test_every_module_has_a_layer() -> None:
    for name in MODULES:
        layer(name)


def test_imports_point_down_the_layers() -> None:
    wrong = [
        f"{m} ({NAMES[layer(m)]}) imports {i} ({NAMES[layer(i)]})"
        for m, targets in GRAPH.items()
        for i in sorted(targets)
        if layer(i) > layer(m)
    ]
    assert not wrong, "imports against the layers:\n" + "\n".join(wrong)


def test_builtin_components_never_import_what_runs_them() -> None:
    wrong = [
        f"{m} imports {i}"
        for m, targets in GRAPH.items()
        if m.split(".")[1:2] and m.split(".")[1] in BUILTINS
        for i in sorted(targets)
        if i.split(".")[1:2] and i.split(".")[1] in ORCHESTRATION
    ]
    assert not wrong, "\n".join(wrong)


def test_render_and_video_import_in_one_direction() -> None:
    back = [
        f"{m} imports {i}"
        for m, targets in GRAPH.items()
        if m.startswith("physbench.render")
        for i in targets
        if i.startswith("physbench.video")
    ]
    assert not back, "render must not import video (video builds on render):\n" + "\n".join(back)


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    found: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in graph:
                continue
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                found.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def test_no_import_cycles() -> None:
    assert _cycles(GRAPH) == []


def test_the_checks_can_fail() -> None:
    """The rules above are not vacuous: a planted wrong-way import and cycle are found."""
    planted = {**GRAPH, "physbench.render.raster": {*GRAPH["physbench.render.raster"]}}
    planted["physbench.render.raster"].add("physbench.video.track")
    planted["physbench.video.track"] = {*GRAPH["physbench.video.track"], "physbench.render.raster"}
    assert _cycles(planted)
    assert layer("physbench.experiment") > layer("physbench.render.raster")
    assert "physbench.components" in GRAPH["physbench.experiment"]


def _functions() -> Iterator[tuple[str, str, int]]:
    for name, path in MODULES.items():
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                yield name, node.name, node.end_lineno - node.lineno + 1  # type: ignore[operator]


def test_no_function_is_longer_than_100_lines() -> None:
    long = [f"{m}.{f}: {n} lines" for m, f, n in _functions() if n > 100]
    assert not long, "split into named steps:\n" + "\n".join(long)


def test_modules_share_a_base_name_only_for_the_same_concept() -> None:
    by_base: dict[str, list[str]] = {}
    for name in MODULES:  # packages count by their folder's name
        by_base.setdefault(name.rpartition(".")[2], []).append(name)
    shared = {b: ms for b, ms in by_base.items() if len(ms) > 1}
    unexplained = sorted(set(shared) - set(SAME_CONCEPT))
    assert not unexplained, {b: shared[b] for b in unexplained}
    stale = sorted(set(SAME_CONCEPT) - set(shared))
    assert not stale, f"SAME_CONCEPT lists names no longer shared: {stale}"


def _calls(attr: str) -> list[str]:
    out = []
    for name, path in MODULES.items():
        for node in ast.walk(ast.parse(path.read_text())):
            if (
                isinstance(node, ast.Call)
                and isinstance(node.func, ast.Attribute)
                and node.func.attr == attr
                and (attr != "start" or any(k.arg == "seed" for k in node.keywords))
            ):
                out.append(name)
    return out


@pytest.mark.parametrize("method", ["start", "propose", "posterior"])
def test_one_driver_calls_estimators(method: str) -> None:
    """Only loop.drive calls an estimator's start, propose and posterior. The conformance kits
    call components directly on purpose (they test the contract, e.g. propose before start),
    and npe hands its correction to the resnet3d estimator it wraps."""
    callers = set(_calls(method)) - {"physbench.loop"}
    callers = {c for c in callers if not c.startswith("physbench.testing")}
    callers.discard("physbench.estimators.npe.estimator")
    assert not callers, f"{method}() is called outside physbench.loop.drive by {sorted(callers)}"
    assert "physbench.loop" in _calls(method)

"""Sweep specs: expansion into cells (the renderer axis among them), seeds, clear errors for bad
specs, and the shipped specs (the output-folder errors of ``physbench bench``:
tests/commands/test_bench.py)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from physbench.bench.spec import RendererSpec, SpecError, load_spec, parse_spec, with_renderer
from physbench.render.base import DEFAULT_RENDERER

GOOD = {
    "name": "t",
    "estimators": [
        "random",
        {"name": "optuna", "label": "optuna-rs", "options": {"sampler": "random"}},
    ],
    "seeds": 3,
    "iterations": [2, 3],
    "resolution": 32,
    "scenes": [{"name": "three_circles", "unknowns": ["mass", "mass+elasticity"]}, "second_order"],
}


def test_product_order_and_seeds() -> None:
    spec = parse_spec(GOOD)
    cells = spec.cells()
    # (2 + 1 unknown sets) x 2 iteration budgets x 2 estimators x 3 seeds
    assert len(cells) == 3 * 2 * 2 * 3
    assert [c.index for c in cells] == list(range(len(cells)))
    first = cells[0].config
    assert (first.scene, first.params, first.iterations, first.estimator, first.seed) == (
        "three_circles",
        ("mass",),
        2,
        "random",
        0,
    )
    assert [c.config.seed for c in cells[:3]] == [0, 1, 2]  # the run seed is the seed value
    assert cells[3].label == "optuna-rs" and cells[3].config.options == {"sampler": "random"}
    assert (
        cells[-1].config.params == ("mass",) and cells[-1].scene == "second_order"
    )  # the default unknowns
    assert len({c.key for c in cells}) == len(cells)
    assert parse_spec(GOOD).cells()[5].key == cells[5].key  # keys are stable


@pytest.mark.parametrize(
    ("seeds", "expected"),
    [(2, (0, 1)), ([7, 3], (7, 3)), ({"start": 10, "count": 2}, (10, 11))],
)
def test_seed_forms(seeds: object, expected: tuple[int, ...]) -> None:
    assert parse_spec({**GOOD, "seeds": seeds}).seeds == expected


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"temperature": 3}, "unknown axis or key 'temperature'; known: name, description, scenes"),
        ({"estimators": ["random", "nope"]}, "unknown estimator 'nope'; known estimators: "),
        (
            {"estimators": [{"name": "optuna", "options": {"temperature": 1}}]},
            "estimator 'optuna' (physbench's own) does not take option 'temperature'; "
            "its options: sampler,",
        ),
        ({"scenes": ["no_such_scene"]}, "unknown scene 'no_such_scene'"),
        (
            {"scenes": [{"name": "three_circles", "unknowns": ["friction"]}]},
            "unknown parameter 'friction' of scene 'three_circles'",
        ),
        (
            {"scenes": [{"name": "three_circles", "colour": "red"}]},
            "scenes[0]: unknown key 'colour'; known keys: name, unknowns, bodies",
        ),
        ({"engine": ["pymunk", "bullet"]}, "unknown simulator 'bullet'"),
        ({"seeds": []}, "empty product: the axis 'seeds' has no values"),
        ({"estimators": []}, "empty product: the axis 'estimators' has no values"),
        ({"blur": []}, "empty product: the axis 'blur' has no values"),
        (
            {"scenes": [{"name": "three_circles", "unknowns": []}]},
            "empty product: the scene lists no unknown-parameter set",
        ),
        ({"seeds": -1}, "seeds = -1: expected a count"),
        ({"iterations": 0}, "iterations = 0: expected a whole number >= 1"),
        ({"blur": -1.0}, "blur = -1.0: expected a finite number in [0, 4096]"),
        # Found by fuzzing (issue 14): a MemoryError building the seeds, a huge frame, a blur
        # that overflows the kernel.
        ({"seeds": 2**62}, f"seeds = {2**62}: expected a count"),
        ({"seeds": {"start": 2**40, "count": 2}}, "whole numbers in [0, 4294967295]"),
        ({"resolution": 100_000}, "resolution = 100000: expected a whole number in [1, 4096]"),
        ({"blur": 1e30}, "blur = 1e+30: expected a finite number in [0, 4096]"),
        ({"estimators": ["random", "random"]}, "two estimators are labelled 'random'"),
    ],
)
def test_bad_specs(change: dict[str, object], message: str) -> None:
    with pytest.raises(SpecError) as err:
        parse_spec({**GOOD, **change})
    assert message in str(err.value), str(err.value)


def test_spec_file_not_utf8_or_nested_too_deeply_is_a_spec_error(tmp_path: Path) -> None:
    latin1 = tmp_path / "latin1.toml"
    latin1.write_bytes(b'name = "t"\ndescription = "caf\xe9"\n')
    with pytest.raises(
        SpecError, match=r"latin1.toml: byte 29 \(b'\\xe9'\) on line 2 is not UTF-8"
    ):
        load_spec(latin1)
    deep = tmp_path / "deep.toml"
    deep.write_text("seeds = " + "[" * 2000 + "]" * 2000 + "\n")
    with pytest.raises(SpecError, match=r"deep\.toml: arrays or tables nested too deeply"):
        load_spec(deep)


def test_missing_axis_and_duplicate_cells() -> None:
    with pytest.raises(
        SpecError, match="seeds: missing; a spec needs scenes, estimators and seeds"
    ):
        parse_spec({k: v for k, v in GOOD.items() if k != "seeds"})
    with pytest.raises(
        SpecError, match=r"cells 0 and 12 are the same run \(scene 'three_circles', unknowns mass"
    ):
        parse_spec({**GOOD, "scenes": ["three_circles", "three_circles"]})


def test_shipped_specs_load() -> None:
    root = Path(__file__).resolve().parents[2] / "benchmarks"
    t1 = load_spec(root / "table1.toml")
    assert t1.seeds == tuple(range(50)) and t1.axes["iterations"] == (11,)
    assert {e.name for e in t1.estimators} >= {"tpe", "cmaes", "optuna", "random", "resnet3d"}
    assert {(s.name, u) for s in t1.scenes for u in s.unknowns} == {
        ("three_circles", ("mass",)),
        ("three_circles", ("elasticity",)),
        ("three_circles", ("mass", "elasticity")),
        ("second_order", ("mass",)),
        ("second_order", ("elasticity",)),
        ("stacked_boxes", ("mass",)),
        ("stacked_boxes", ("friction",)),
        ("bouncing_balls", ("mass",)),
    }
    assert len(load_spec(root / "smoke.toml").seeds) >= 5  # the compare test needs >= 5 seeds
    gap = load_spec(root / "reality_gap.toml")
    assert any(c.config.engine != c.config.observe_engine for c in gap.cells())


@pytest.mark.usefixtures("blocks")
def test_renderer_axis_forms_and_product() -> None:
    assert parse_spec(GOOD).renderers == (RendererSpec(DEFAULT_RENDERER, DEFAULT_RENDERER),)
    one = parse_spec({**GOOD, "renderer": "blocks"})
    assert {(c.config.renderer, c.renderer_label) for c in one.cells()} == {("blocks", "blocks")}
    spec = parse_spec(
        {
            **GOOD,
            "renderer": [
                DEFAULT_RENDERER,
                "blocks",
                {"name": "blocks", "label": "dim", "options": {"gain": 0.5}},
                {"name": "blocks", "options": {"gain": 0.25}},
            ],
        }
    )
    assert [r.label for r in spec.renderers] == [
        DEFAULT_RENDERER,
        "blocks",
        "dim",
        "blocks(gain=0.25)",
    ]
    cells = spec.cells()
    assert len(cells) == 4 * len(parse_spec(GOOD).cells()) == len({c.key for c in cells})
    # the renderer is outside the other axes: each renderer's block is one whole default product
    block = len(cells) // 3 // 4  # 3 scene x unknown sets
    assert [c.renderer_label for c in cells[block - 1 : block + 1]] == [DEFAULT_RENDERER, "blocks"]
    dim = next(c for c in cells if c.renderer_label == "dim").config
    assert (dim.renderer, dict(dim.renderer_options)) == ("blocks", {"gain": 0.5})
    # the default renderer's cells keep their keys when a renderer axis is added
    assert cells[0].key == parse_spec(GOOD).cells()[0].key


@pytest.mark.parametrize(
    ("renderer", "message"),
    [
        ("nope", "s.toml: renderer = 'nope': unknown renderer 'nope'; known renderers: "),
        (
            ["blocks", {"name": "blocks", "options": {"gain": 7}}],
            "s.toml: renderer[1] = 'blocks': gain = 7: expected a number in (0, 1]",
        ),
        (
            {"name": "blocks", "options": {"colour": "red"}},
            "s.toml: renderer = 'blocks': renderer 'blocks' (plugin 'toy_blocks', registered by "
            "PHYSBENCH_PLUGINS) does not take option 'colour'",
        ),
        (
            {"name": "blocks", "options": {"resolution": 8}},
            "renderer option 'resolution': set it with --resolution",
        ),
        (["blocks", "blocks"], "renderer: two renderers are labelled 'blocks'"),
        ({"name": "blocks", "gain": 1}, "renderer[0]: unknown key 'gain'; known keys: name,"),
        ([], "empty product: the axis 'renderer' has no values"),
    ],
)
@pytest.mark.usefixtures("blocks")
def test_bad_renderers_fail_before_anything_runs(
    tmp_path: Path, renderer: object, message: str
) -> None:
    with pytest.raises(SpecError) as err:
        parse_spec({**GOOD, "renderer": renderer}, path=str(tmp_path / "s.toml"))
    assert message in str(err.value), str(err.value)


@pytest.mark.usefixtures("blocks")
def test_renderer_modes_are_checked_with_every_render_mode() -> None:
    with pytest.raises(
        SpecError, match="renderer = 'blocks': mode = 'instance': renderer 'blocks'"
    ):
        parse_spec({**GOOD, "renderer": "blocks", "render_mode": ["mark", "instance"]})


@pytest.mark.usefixtures("blocks")
def test_renderer_override() -> None:
    spec = parse_spec({**GOOD, "renderer": {"name": "blocks", "options": {"gain": 0.5}}})
    swapped = with_renderer(spec, DEFAULT_RENDERER, {})
    assert swapped.renderers == (RendererSpec(DEFAULT_RENDERER, DEFAULT_RENDERER),)
    assert [c.key for c in swapped.cells()] == [c.key for c in parse_spec(GOOD).cells()]
    updated = with_renderer(spec, None, {"gain": 0.25})  # -R alone: the spec's renderer
    assert updated.renderers == (RendererSpec("blocks", "blocks(gain=0.25)", {"gain": 0.25}),)
    with pytest.raises(SpecError, match="--renderer = 'blocks': gain = 2: expected a number"):
        with_renderer(spec, None, {"gain": 2})
    two = parse_spec({**GOOD, "renderer": [DEFAULT_RENDERER, "blocks"]})
    with pytest.raises(SpecError, match=r"the spec has 2 renderers .*; name the one to run"):
        with_renderer(two, None, {"gain": 0.5})


TOSS = """
name = "toss"
bounds = [0.0, 0.0, 4.0, 3.0]
frames = 20

[[bodies]]
name = "ball"
shape = { kind = "circle", radius = 0.1 }
position = [0.5, 0.5]
velocity = [2.5, 5.0]
mass = 0.2
"""


def _toss_spec(tmp_path: Path, **change: object) -> dict[str, object]:
    (tmp_path / "toss.toml").write_text(TOSS, encoding="utf-8")
    scene = {
        "name": "toss.toml",
        "effects": ["linear_drag:c=0.1"],
        "unknowns": ["gravity", "linear_drag.c=0:0.5+camera.scale"],
    }
    return {"estimators": ["random"], "seeds": 2, "iterations": 2, "scenes": [scene], **change}


def test_scene_level_unknowns_and_effects_in_a_spec(tmp_path: Path) -> None:
    from physbench.api import sweep

    spec = parse_spec(_toss_spec(tmp_path), base=tmp_path)
    cells = spec.cells()
    assert [c.config.params for c in cells[::2]] == [
        ("gravity",),
        ("linear_drag.c=0:0.5", "camera.scale"),
    ]
    assert {c.config.effects for c in cells} == {("linear_drag:c=0.1",)}
    table = sweep(spec, tmp_path / "out", executor="serial").table
    assert len(table) == 4 * 2 and (table["status"] == "ok").all()  # 4 cells, 2 iterations each
    keys = {k for p in table["params"] for k in json.loads(p)}
    assert keys == {"gravity", "linear_drag.c", "camera.scale"}
    assert table["best_nmse"].notna().all()  # the truth of every scene-level unknown is known


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (
            {"estimators": ["resnet3d"]},
            "estimator 'resnet3d' corrects one marked body at a time, so it cannot fit gravity",
        ),
        (
            {"observer": "camera"},
            "an observer camera films the scene's own physics with its true calibration; it "
            "cannot show linear_drag:c=0.1",
        ),
        ({"effects": "linear_drag"}, None),
    ],
)
def test_a_spec_refuses_what_its_estimators_or_observers_cannot_take(
    tmp_path: Path, change: dict[str, object], message: str | None
) -> None:
    data = _toss_spec(tmp_path, **change)
    if message is None:  # a top-level default for scenes that list none
        data["scenes"] = [{"name": "toss.toml", "unknowns": ["linear_drag.c"]}]
        assert parse_spec(data, base=tmp_path).cells()[0].config.effects == ("linear_drag",)
        return
    with pytest.raises(SpecError, match=message):
        parse_spec(data, base=tmp_path)

"""``benchmarks/oneshot_gpu.py``, the GPU machine's one-shot fine-tune and evaluation: its pieces
that need no GPU (the run itself is a benchmark: ``bash benchmarks/gpu_oneshot.sh``)."""

from __future__ import annotations

import importlib.metadata as md
import importlib.util
import json
import subprocess
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location(
    "oneshot_gpu", ROOT / "benchmarks" / "oneshot_gpu.py"
)
assert _spec and _spec.loader
oneshot = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(oneshot)


def test_the_rows_are_the_one_shot_misses_with_the_papers_values() -> None:
    assert [oneshot.paper(s, p) for s, p in oneshot.ROWS] == [8.7e-5, 6.3e-3]
    assert all(oneshot.shipped(s, p).is_file() for s, p in oneshot.ROWS)


def test_the_summary_compares_on_the_seeds_every_model_finished() -> None:
    row = "three_circles__elasticity"
    cells = [
        {"row": row, "weights": w, "blur": 0.0, "seed": s, "after_2": v, "error": None}
        for w, s, v in (
            ("shipped", 0, 4e-4),
            ("shipped", 1, 2e-4),
            ("shipped", 2, 9e-4),  # ft32 never got to seed 2: left out
            ("ft32", 0, 1e-4),
            ("ft32", 1, 5e-5),
        )
    ]
    cells.append({**cells[-1], "seed": 2, "after_2": None, "error": "boom", "weights": "ft32"})
    models = {row: {"shipped": "a", "ft32": "b"}}
    summary = oneshot.summarize(cells, models)
    sharp = {e["weights"]: e for e in summary if e["blur"] == 0.0}
    assert sharp["shipped"]["seeds"] == sharp["ft32"]["seeds"] == 2
    assert sharp["shipped"]["mean"] == pytest.approx(3e-4)
    assert sharp["ft32"]["mean"] == pytest.approx(7.5e-5) and sharp["ft32"]["met"]
    assert not sharp["shipped"]["met"]
    assert sharp["ft32"]["over_shipped"][0] == pytest.approx(0.25)
    assert sharp["ft32"]["over_paper"] == pytest.approx(7.5e-5 / 8.7e-5)
    blurred = [e for e in summary if e["blur"] == 3.0]
    assert [e["seeds"] for e in blurred] == [0, 0]  # no cells: rows without a mean
    text = oneshot.markdown(
        summary, {}, {"device": "cpu", "cores": 2, "workers": 1, "train_seconds": 1}
    )
    assert "7.50e-05" in text and "| 0 | – |" in text


def test_a_killed_run_keeps_its_best_weights_with_its_own_input_size(tmp_path: Path) -> None:
    torch = pytest.importorskip("torch")
    from physbench.estimators.resnet3d import weights
    from physbench.estimators.resnet3d.network import NetConfig, build_net

    torch.manual_seed(0)
    run = tmp_path / "in64"
    run.mkdir()
    net = build_net(NetConfig(n_outputs=1, resolution=64, frames=30))
    weights.save(run / "best.safetensors", dict(net.state_dict()), {"samples": 64})
    (run / "log.txt").write_text("-m physbench train --resolution 64 --frames 30 --lr 1e-3\n")
    history = [{"samples": 0, "val_mse": 0.2}, {"samples": 64, "val_mse": 0.1}]
    (run / "checkpoint.json").write_text(
        json.dumps({"history": history, "samples": 64, "wall_s": 3.0})
    )
    path, how = oneshot.final_weights(run, "three_circles", "elasticity")
    assert how == "best so far" and path is not None
    _, meta = weights.load(path)
    assert meta["net"]["resolution"] == 64 and meta["data"]["frames"] == 30
    assert meta["val_mse"] == 0.1
    assert meta["training"] == {"unfinished": True, "samples_seen": 64, "wall_s": 3.0}
    assert oneshot.final_weights(tmp_path / "nothing", "three_circles", "elasticity") == (
        None,
        "no weights",
    )


def test_a_run_past_the_deadline_is_killed_with_its_process_group() -> None:
    p = subprocess.Popen(["sleep", "30"], start_new_session=True)
    t = time.time()
    assert oneshot.wait({"x": p}, t + 0.5, t) == {"x": "killed"}
    assert p.poll() is not None and time.time() - t < 10


def test_the_entry_points_written_for_a_bare_checkout_are_pyprojects(tmp_path: Path) -> None:
    oneshot.write_entry_points(tmp_path)
    (dist,) = md.distributions(path=[str(tmp_path)])
    written = {ep.name: ep.value for ep in dist.entry_points if ep.group == "physbench"}
    own = {
        ep.name: ep.value
        for ep in md.entry_points(group="physbench")
        if ep.dist is not None and ep.dist.name == "physbench"
    }
    assert written == own  # what an installed physbench registers
    assert written["resnet3d"] == "physbench.estimators.resnet3d"


def test_the_committed_gpu_run_measured_the_distance() -> None:
    """results/resnet3d/oneshot_gpu: one H100 call, 320 s of training per arm, 200 seeds. No arm
    reached the paper's 11-iteration value after 2 iterations; the committed numbers say how far."""
    run = json.loads((ROOT / "results/resnet3d/oneshot_gpu/results.json").read_text())
    assert run["info"]["device"].startswith("NVIDIA H100") and run["info"]["seeds_asked"] == 200
    rows = {(r["row"], r["blur"], r["weights"]): r for r in run["summary"]}
    assert len(rows) == 12 and all(r["seeds"] == 200 for r in rows.values())
    assert not any(r["met"] for r in rows.values())
    sharp = {k[0]: r for k, r in rows.items() if k[1] == 0.0 and k[2] == "shipped"}
    assert sharp["three_circles__elasticity"]["over_paper"] == pytest.approx(3.42, abs=0.01)
    assert sharp["bouncing_balls__mass"]["over_paper"] == pytest.approx(1.43, abs=0.01)
    for row in ("three_circles__elasticity", "bouncing_balls__mass"):
        for blur in (0.0, 3.0):  # fine-tuning at 32 px for 320 s moved no row below the paper
            assert rows[(row, blur, "ft32")]["over_paper"] > 1.3
            assert rows[(row, blur, "in64")]["mean"] > rows[(row, blur, "shipped")]["mean"]
    assert (ROOT / "results/resnet3d/oneshot_gpu/summary.md").read_text().startswith("# One shot")


def test_the_committed_near_pair_run_kept_the_shipped_weights() -> None:
    """results/resnet3d/oneshot_gpu_near: the second H100 call, fine-tuning on pairs half of which
    are drawn near each other (``train --near 0.5``) for 220 s. Validation MSE only rose from the
    shipped weights' (so the best, kept, weights are the shipped ones: ratios of exactly 1)."""
    run = json.loads((ROOT / "results/resnet3d/oneshot_gpu_near/results.json").read_text())
    assert run["info"]["arms"]["near32"][-2:] == ["--near", "0.5"]
    for arm, train in run["training"].items():
        curve = [h["val_mse"] for h in train["history"]]
        assert len(curve) > 5 and min(curve[1:]) > curve[0], arm
    rows = [r for r in run["summary"] if r["weights"] == "near32"]
    assert len(rows) == 4 and all(r["seeds"] == 200 and not r["met"] for r in rows)
    assert all(r["over_shipped"][0] == pytest.approx(1.0) for r in rows)

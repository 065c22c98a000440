"""The resnet3d sweep's tables on a tiny synthetic sweep with known errors."""

from __future__ import annotations

import pandas as pd

from physbench.bench.resnet3d_table import after, table


def sweep_rows() -> pd.DataFrame:
    """Two seeds, 11 iterations: best-so-far error (seed + 1) / (iteration + 1), doubled under
    blur; plus one failed cell."""
    rows = []
    for est, blurs in (("resnet3d", (0.0, 3.0)), ("tpe", (0.0,))):
        for blur in blurs:
            for seed in (0, 1):
                for it in range(11):
                    err = (seed + 1) / (it + 1) * (2.0 if blur else 1.0)
                    rows.append(
                        {
                            "cell": f"{est}-{blur}-{seed}",
                            "status": "ok",
                            "error": None,
                            "estimator_name": est,
                            "scene": "three_circles",
                            "unknowns": "mass",
                            "bodies": "a",
                            "blur": blur,
                            "seed": seed,
                            "iteration": it,
                            "best_nmse": err,
                            "nmse": err,
                        }
                    )
    failed = {**rows[0], "cell": "bad", "status": "error", "error": "boom", "iteration": None}
    return pd.DataFrame([*rows, {**failed, "estimator_name": "random"}])


def test_after_n_iterations_is_indexed_by_seed():
    df = sweep_rows()
    tpe = df[df.estimator_name == "tpe"]
    assert after(tpe, 2).to_dict() == {0: 0.5, 1: 1.0}
    assert after(tpe, 11).to_dict() == {0: 1 / 11, 1: 2 / 11}


def test_table_rows_from_a_sweep_folder(tmp_path):
    sweep_rows().to_parquet(tmp_path / "results.parquet")
    lines = table(tmp_path).splitlines()
    (nn,) = [x for x in lines if x.startswith("| three_circles | mass | a | –")]
    cells = [c.strip() for c in nn.split("|")[1:-1]]
    assert cells[4:7] == ["7.50e-01", "1.36e-01", "–"]  # after 2, after 11, no paper value
    assert cells[7].startswith("5.50 [") and cells[8] == "no"  # 2 / 11 against the limit 2
    assert cells[10].startswith("2.00 [") and cells[11] == "yes"  # blur / sharp
    assert cells[12:] == ["2.00", "2.00", "2"]  # seeds 0-9, final iterates, seeds
    tpe = "| three_circles | mass | a | 0 | tpe "
    assert tpe + "| 7.50e-01 ± 3.5e-01 | 1.36e-01 ± 6.4e-02 | 5.50 | 2 |" in lines
    assert lines[-1] == "failed: three_circles mass a 0.0 random: 1 cell (boom)"

"""The tracker's compiled loops: compiled on first call, never on import, and a clear error
where numba is missing."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from physbench.video.compiled import (
    CompiledCacheWarning,
    CompiledError,
    jit,
    pairwise_sum,
    solve,
)


def test_a_compiled_function_gives_what_the_python_gives() -> None:
    def total(x):  # type: ignore[no-untyped-def]
        s = 0.0
        for v in x:
            s += v * v
        return s

    x = np.arange(10.0)
    assert jit(total)(x) == total(x) == 285.0


def test_importing_the_tracker_does_not_load_numba() -> None:
    code = "import sys, physbench.video.track; print('numba' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_without_numba_the_error_names_the_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "numba", None)  # import numba raises ImportError
    with pytest.raises(CompiledError, match=r"pip install 'physbench\[video\]'"):
        jit(lambda x: x)(1.0)


def test_without_a_writable_cache_folder_the_loops_compile_with_a_warning(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # Neither the folder beside the module nor the user's cache folder writable: numba finds no
    # place to keep machine code (its locators all decline) and refuses cache=True.
    from numba.core import caching

    import physbench.video.compiled as compiled

    monkeypatch.setattr(caching.CacheImpl, "_locator_classes", [])
    monkeypatch.setattr(compiled, "_warned", [])

    def cube(x):  # type: ignore[no-untyped-def]
        return x * x * x

    with pytest.warns(CompiledCacheWarning, match="NUMBA_CACHE_DIR"):
        assert jit(cube)(3.0) == 27.0


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_the_pairwise_sum_is_numpys_to_the_bit(dtype: type) -> None:
    rng = np.random.default_rng(3)
    for n in [*range(0, 140), 255, 256, 1000, 1401, 9000]:
        a = (rng.standard_normal(n) * 10 ** rng.uniform(-3, 3, n)).astype(dtype)
        assert pairwise_sum(a, 0, n) == a.sum(), n
        assert pairwise_sum(a, 3, max(n - 5, 0)) == a[3 : max(n - 2, 3)].sum(), n


@pytest.mark.parametrize("n", [3, 4])
def test_the_small_solve_is_numpys(n: int) -> None:
    # To the bit where OpenBLAS's sums come out as the loop's (the machine measured); the
    # residual check holds on any BLAS.
    rng = np.random.default_rng(n)
    for _ in range(200):
        a = rng.standard_normal((n, n)) * 10 ** rng.uniform(-2, 2, (n, n))
        b = rng.standard_normal(n)
        m, x = a.copy(), b.copy()
        assert solve(m, x)
        np.testing.assert_allclose(x, np.linalg.solve(a, b), rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(a @ x, b, rtol=1e-8, atol=1e-8)
    singular = np.ones((n, n))
    assert not solve(singular, np.ones(n))  # np.linalg.solve raises LinAlgError


@jit
def _twice_the_sum(a):  # type: ignore[no-untyped-def]
    return 2.0 * pairwise_sum(a, 0, len(a))


def test_a_compiled_function_may_call_another() -> None:
    values = np.arange(200.0)
    assert _twice_the_sum(values) == 2 * values.sum() == 39800.0


def test_an_empty_cache_is_told_apart(tmp_path) -> None:  # type: ignore[no-untyped-def]
    # With numba's cache in an empty folder the tracker's loops are not cached: tracking says
    # it compiles them before its first frame, where it shows progress.
    code = "from physbench.video import compiled, track; print(compiled.cached())"
    env = {**__import__("os").environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert out.stdout.strip() == "False", out.stderr

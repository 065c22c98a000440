"""The estimator kit: checks of a :class:`~physbench.estimators.base.CorrectionEstimator` on the
closed-form toy task (:mod:`physbench.testing.toy`), so each takes well under a second, apart from
the other-process check, which starts one Python interpreter.

Kit settings: ``bad_options`` (option sets that must be refused, naming the option),
``subprocess`` (``False`` leaves out the other-process check) and ``unknowns`` (the toy parameters
the estimator can be asked for, default ``("mass", "elasticity")``; e.g. ``("mass",)`` for a
learned estimator whose weights predict mass only).
"""

from __future__ import annotations

import json
from collections.abc import Iterator, Mapping, Sequence
from typing import Any, ClassVar

from physbench.errors import PhysbenchError
from physbench.estimators.base import CorrectionEstimator, Step, Task
from physbench.loop import EstimatorError, History, draw_problem
from physbench.testing.kit import (
    Check,
    ConformanceError,
    Subject,
    import_path,
    label,
    require_contract,
    run_checks,
    run_in_child,
)
from physbench.testing.toy import run_toy, toy_task

#: The toy parameters an estimator is asked for unless its kit settings say otherwise.
UNKNOWNS = ("mass", "elasticity")


def _unknowns(unknowns: Sequence[str]) -> tuple[str, ...]:
    out = tuple(unknowns)
    if not out or not set(out) <= set(UNKNOWNS):
        raise ConformanceError(
            f"kit setting unknowns = {unknowns!r}: expected a non-empty subset of {UNKNOWNS}"
        )
    return out


def check_protocol(cls: type, **options: Any) -> None:
    """``cls`` subclasses :class:`~physbench.estimators.base.CorrectionEstimator`, ``name`` is a
    non-empty string and ``per_object`` a bool on the class; ``cls(**options)`` builds an
    instance with ``start`` and ``propose``."""
    require_contract(cls, CorrectionEstimator)
    per_object = cls.per_object  # type: ignore[attr-defined]  # declared by the base class
    if not isinstance(per_object, bool):
        raise ConformanceError(
            f"{label(cls)}: class attribute 'per_object' must be True or False, got {per_object!r}"
        )
    try:
        est = cls(**options)
    except Exception as exc:
        raise ConformanceError(
            f"{label(cls)}: {cls.__name__}(**{options!r}) raised {type(exc).__name__}: {exc}"
        ) from exc
    for meth in ("start", "propose"):
        if not callable(getattr(est, meth)):  # inherited; a subclass could shadow it
            raise ConformanceError(f"{label(cls)}: instances need a method {meth}()")


def check_respects_ranges(cls: type, *, unknowns: Sequence[str] = UNKNOWNS, **options: Any) -> None:
    """Every proposal has exactly the unknowns' keys, finite values inside their ranges, for one
    body's first parameter, every body's first parameter and every body's parameters (1, 2 and 4
    unknowns by default; the loop itself raises on a bad proposal; this turns that into a
    finding)."""
    params = _unknowns(unknowns)
    cases = [(params[:1], ("a",)), (params[:1], None)]
    if len(params) > 1:
        cases.append((params, None))
    for ps, bodies in cases:
        try:
            run_toy(cls, options, seed=1, iterations=8, params=ps, bodies=bodies)
        except EstimatorError as exc:
            raise ConformanceError(f"{label(cls)}: {exc}") from exc
        except Exception as exc:
            raise ConformanceError(
                f"{label(cls)}: a run on the toy task with unknowns {list(ps)} of bodies "
                f"{list(bodies) if bodies else 'a, b'} raised {type(exc).__name__}: {exc} "
                "(if the estimator cannot be asked for these, narrow the kit setting unknowns)"
            ) from exc


def _trace(h: History) -> dict[str, Any]:
    d: dict[str, Any] = json.loads(json.dumps(h.to_dict(timings=False)))
    d["meta"].pop("observation", None)
    return d


def _first_difference(a: dict[str, Any], b: dict[str, Any]) -> str:
    for ra, rb in zip(a["iterations"], b["iterations"], strict=False):
        if ra != rb:
            return (
                f"iteration {ra['iteration']}: {ra['params']} (loss {ra['loss']}) "
                f"vs {rb['params']} (loss {rb['loss']})"
            )
    diff = [k for k in a if a[k] != b.get(k)]
    return f"fields {diff}"


def check_deterministic(cls: type, *, unknowns: Sequence[str] = UNKNOWNS, **options: Any) -> None:
    """The same seed twice in this process gives identical histories."""
    params = _unknowns(unknowns)
    a = _trace(run_toy(cls, options, seed=3, params=params))
    b = _trace(run_toy(cls, options, seed=3, params=params))
    if a != b:
        raise ConformanceError(
            f"{label(cls)}: two runs with seed 3 differ at {_first_difference(a, b)}"
        )


def check_deterministic_in_subprocess(
    cls: type, *, unknowns: Sequence[str] = UNKNOWNS, **options: Any
) -> None:
    """The same seed in a fresh Python process (another hash seed) gives the identical history.
    Options must be JSON values; the class must be importable at module level."""
    params = _unknowns(unknowns)
    spec = {"cls": import_path(cls), "options": options, "seed": 5, "params": list(params)}
    theirs = run_in_child(cls, "physbench.testing.estimators:_child_trace", spec)
    ours = _trace(run_toy(cls, options, seed=5, params=params))
    if ours != theirs:
        raise ConformanceError(
            f"{label(cls)}: seed 5 gives a different history in another process, at "
            f"{_first_difference(ours, theirs)}; derive all randomness from the seed passed to "
            "start()"
        )


def _child_trace(spec: Mapping[str, Any]) -> dict[str, Any]:
    from physbench.testing.kit import load

    h = run_toy(load(spec["cls"]), spec["options"], seed=spec["seed"], params=tuple(spec["params"]))
    return _trace(h)


def _names(exc: BaseException, key: str) -> bool:
    return key in str(exc)


def check_bad_input(
    cls: type, bad_options: Sequence[Mapping[str, Any]] = (), **options: Any
) -> None:
    """Clear errors: an unknown option, ``propose`` before ``start``, and each of ``bad_options``
    raise an exception (not a crash deep inside) whose message names the problem."""
    try:
        cls(**options, no_such_option_xyz=1)
    except Exception as exc:
        if not _names(exc, "no_such_option_xyz"):
            raise ConformanceError(
                f"{label(cls)}: an unknown option raised {type(exc).__name__}: {exc!s} "
                "without naming it"
            ) from exc
    else:
        raise ConformanceError(
            f"{label(cls)}: an unknown option 'no_such_option_xyz' was accepted silently"
        )

    t = toy_task()
    est = cls(**options)
    # What the loop would pass: marked frames too, for an estimator that is per_object.
    marked = dict(t.observation.marked) if cls.per_object else {}  # type: ignore[attr-defined]
    step = Step(0, dict(t.observation.truth or {}), t.observation.frames, 0.0, marked=marked)
    try:
        est.propose(step)
    except (PhysbenchError, RuntimeError) as exc:
        if "start" not in str(exc):
            raise ConformanceError(
                f"{label(cls)}: propose() before start() raised {exc!s}; say that start() must "
                "come first"
            ) from exc
    except Exception as exc:
        raise ConformanceError(
            f"{label(cls)}: propose() before start() raised {type(exc).__name__}: {exc}; raise "
            "PhysbenchError (or RuntimeError) saying start() must come first"
        ) from exc
    else:
        raise ConformanceError(f"{label(cls)}: propose() before start() did not raise")

    for bad in bad_options:
        try:
            est = cls(**{**options, **bad})
            est.start(
                Task(
                    t.scene,
                    t.space,
                    t.observation.frames,
                    draw_problem(t.space, 0)[1],
                    t.renderer,
                    iterations=8,
                    marked_observation=t.observation.marked,
                ),
                seed=0,
            )
        except (PhysbenchError, ValueError, TypeError) as exc:
            if not any(_names(exc, k) for k in bad):
                raise ConformanceError(
                    f"{label(cls)}: bad options {dict(bad)} raised {exc!s} without naming "
                    "the option"
                ) from exc
        else:
            raise ConformanceError(f"{label(cls)}: bad options {dict(bad)} were accepted")


def check_marked_views(cls: type, **options: Any) -> None:
    """A :attr:`~physbench.estimators.base.CorrectionEstimator.per_object` estimator refuses, in
    ``start()``, a task whose marked observation lacks an unknown body, naming that body (an
    observation file without ``marked_<body>`` frames then gets a clear error, not a failure deep
    inside ``propose()``)."""
    t = toy_task(("mass",))
    marked = {b: f for b, f in t.observation.marked.items() if b != "b"}
    task = Task(
        t.scene,
        t.space,
        t.observation.frames,
        draw_problem(t.space, 0)[1],
        t.renderer,
        iterations=8,
        marked_observation=marked,
    )
    try:
        cls(**options).start(task, seed=0)
    except (PhysbenchError, ValueError, KeyError) as exc:
        if "'b'" not in str(exc) and '"b"' not in str(exc):
            raise ConformanceError(
                f"{label(cls)}: start() without the marked view of body 'b' raised {exc!s} "
                "without naming the body"
            ) from exc
    else:
        raise ConformanceError(
            f"{label(cls)}: is per_object, but start() accepted a task without the marked view "
            "of unknown body 'b' (task.marked_observation); raise PhysbenchError naming it"
        )


#: Kit settings the estimator checks take.
SETTINGS = frozenset({"bad_options", "subprocess", "unknowns"})
#: Every estimator check, in the order they run.
CHECKS = (
    check_protocol,
    check_respects_ranges,
    check_deterministic,
    check_bad_input,
    check_marked_views,
    check_deterministic_in_subprocess,
)


def yield_checks(subject: Subject) -> Iterator[Any]:
    """The estimator checks for ``subject``: ``check_marked_views`` only when it is
    ``per_object``, the other-process check unless its kit setting ``subprocess`` is false."""
    for check in CHECKS:
        if check is check_deterministic_in_subprocess and not subject.kit.get("subprocess", True):
            continue
        if check is check_marked_views and subject.cls.per_object is not True:  # type: ignore[attr-defined]
            continue
        yield check


def check_estimator(
    cls: type,
    /,
    *,
    bad_options: Sequence[Mapping[str, Any]] = (),
    subprocess: bool = True,
    unknowns: Sequence[str] = UNKNOWNS,
    **options: Any,
) -> None:
    """Every estimator check; raises one :class:`ConformanceError` listing every failure."""
    kit = {"bad_options": bad_options, "subprocess": subprocess, "unknowns": unknowns}
    subject = Subject(cls, options, kit)
    checks = [Check(f) for f in yield_checks(subject)]
    run_checks(subject, checks, stop_after=check_protocol.__name__)


class EstimatorConformance:
    """pytest base class: subclass it as ``Test...`` and set :attr:`estimator` (and options)."""

    estimator: ClassVar[type | None] = None
    options: ClassVar[Mapping[str, Any]] = {}
    bad_options: ClassVar[Sequence[Mapping[str, Any]]] = ()
    unknowns: ClassVar[Sequence[str]] = UNKNOWNS

    def _cls(self) -> type:
        if self.estimator is None:
            raise ConformanceError(f"{type(self).__name__}: set the class attribute 'estimator'")
        return self.estimator

    def test_protocol(self) -> None:
        check_protocol(self._cls(), **self.options)

    def test_respects_ranges(self) -> None:
        check_respects_ranges(self._cls(), unknowns=self.unknowns, **self.options)

    def test_deterministic(self) -> None:
        check_deterministic(self._cls(), unknowns=self.unknowns, **self.options)

    def test_deterministic_in_subprocess(self) -> None:
        check_deterministic_in_subprocess(self._cls(), unknowns=self.unknowns, **self.options)

    def test_bad_input(self) -> None:
        check_bad_input(self._cls(), self.bad_options, **self.options)

"""What every conformance kit shares: the error, the component under test, check selection by
kind, the runner behind ``check_<kind>`` and the pytest parametrization.

A check is a plain function ``check_x(cls, *, <kit settings>, **options)`` that raises
:class:`ConformanceError` saying what is wrong; ``options`` build the component
(``cls(**options)``), kit settings (keyword parameters of the check, e.g. an estimator's
``bad_options``) tune the check. Each kind's module ``physbench.testing.<kind>s`` lists its
checks in ``CHECKS``, its kit settings in ``SETTINGS`` and the checks that apply to one component
in ``yield_checks(subject)``, choosing by the component's declared traits.
"""

from __future__ import annotations

import importlib
import importlib.util
import inspect
import json
import os
import subprocess
import sys
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any


class ConformanceError(AssertionError):
    """A component failed a conformance check; the message says which and why."""


def label(cls: type) -> str:
    """``module.Class (name 'x')``: how every finding names the component."""
    return f"{cls.__module__}.{cls.__qualname__} (name {getattr(cls, 'name', '?')!r})"


def require_contract(cls: object, base: type) -> None:
    """``cls`` subclasses ``base`` and has a non-empty string ``name``: what every kit's
    protocol check asks first."""
    if not (isinstance(cls, type) and issubclass(cls, base)):
        raise ConformanceError(
            f"{cls!r} does not subclass {base.__module__}.{base.__qualname__}, the contract of "
            "its kind"
        )
    name = cls.name  # type: ignore[attr-defined]  # every base class declares it
    if not isinstance(name, str) or not name.strip():
        raise ConformanceError(
            f"{label(cls)}: class attribute 'name' must be a non-empty string, got {name!r}"
        )


def construct(cls: type, kwargs: Mapping[str, Any], base: type) -> Any:
    """``cls(**kwargs)``, as a kit check builds its component: a constructor that raises, or an
    instance that is not a ``base``, is a :class:`ConformanceError` naming the component."""
    try:
        obj = cls(**kwargs)
    except Exception as exc:
        raise ConformanceError(
            f"{label(cls)}: {cls.__name__}(**{dict(kwargs)!r}) raised {type(exc).__name__}: {exc}"
        ) from exc
    if not isinstance(obj, base):
        raise ConformanceError(f"{label(cls)}: instances are not physbench {base.__name__}s")
    return obj


@dataclass(frozen=True)
class Subject:
    """A component class under test: ``cls(**options)`` builds it; ``kit`` holds settings of its
    kind's checks (e.g. ``{"bad_options": [...]}`` for an estimator); ``requires`` names modules
    it imports lazily (the parametrized tests are skipped when one is missing);
    ``expected_failures`` maps check names to the reason the component fails them today (their
    parametrized tests are strict xfails: they fail once the component is fixed, so the entry
    gets removed); ``id`` is the first part of its pytest ids (default: the class name)."""

    cls: type
    options: Mapping[str, Any] = field(default_factory=dict)
    kit: Mapping[str, Any] = field(default_factory=dict)
    requires: tuple[str, ...] = ()
    expected_failures: Mapping[str, str] = field(default_factory=dict)
    id: str = ""

    @property
    def name(self) -> str:
        return self.id or self.cls.__name__

    def missing(self) -> list[str]:
        """The modules of :attr:`requires` that cannot be imported here."""
        return [m for m in self.requires if importlib.util.find_spec(m) is None]


def as_subject(component: type | Subject) -> Subject:
    return component if isinstance(component, Subject) else Subject(component)


def settings_of(func: Callable[..., None]) -> frozenset[str]:
    """The kit settings ``func`` takes: its named parameters after the component class."""
    params = list(inspect.signature(func).parameters.values())[1:]
    return frozenset(p.name for p in params if p.kind not in (p.VAR_KEYWORD, p.VAR_POSITIONAL))


@dataclass(frozen=True)
class Check:
    """One check bound to nothing: ``check(subject)`` runs ``func`` on the subject's class with
    the kit settings ``func`` takes and the subject's options."""

    func: Callable[..., None]

    @property
    def name(self) -> str:
        return self.func.__name__

    def __call__(self, subject: type | Subject) -> None:
        s = as_subject(subject)
        accepted = settings_of(self.func)
        settings = {k: v for k, v in s.kit.items() if k in accepted}
        self.func(s.cls, **settings, **s.options)


def kind_of(cls: type) -> str:
    """``simulator``, ``renderer``, ``effect`` or ``estimator``: the kind (of
    :data:`physbench.kinds.KINDS`) whose base class ``cls`` subclasses."""
    from physbench.kinds import KINDS, kind_of_class

    found = kind_of_class(cls)
    if found is None:
        names = ", ".join(k.base.replace(":", ".") for k in KINDS if k.base)
        raise ConformanceError(f"{cls!r} subclasses none of the component base classes ({names})")
    return found.name


def _module(kind: str) -> Any:
    return importlib.import_module(f"physbench.testing.{kind}s")


def checks_for(component: type | Subject) -> list[Check]:
    """The checks that apply to ``component``, chosen by its kind and declared traits. Raises
    :class:`ConformanceError` for a kit setting that no check of its kind takes."""
    s = as_subject(component)
    kind = kind_of(s.cls)
    module = _module(kind)
    known: frozenset[str] = module.SETTINGS
    unknown = sorted(set(s.kit) - known)
    if unknown:
        raise ConformanceError(
            f"{label(s.cls)}: unknown {kind} kit settings {unknown}; known: {sorted(known)}"
        )
    return [Check(f) for f in module.yield_checks(s)]


def run_checks(subject: Subject, checks: Iterable[Check], *, stop_after: str = "") -> None:
    """Run ``checks`` and raise one :class:`ConformanceError` listing every failure; a failure of
    the check named ``stop_after`` (the protocol check) stops the run."""
    failures = []
    for check in checks:
        try:
            check(subject)
        except ConformanceError as exc:
            failures.append(f"- {check.name}: {exc}")
            if check.name == stop_after:
                break  # nothing else can run meaningfully
        except Exception as exc:
            failures.append(f"- {check.name}: unexpected {type(exc).__name__}: {exc}")
    if failures:
        raise ConformanceError(
            f"{label(subject.cls)} fails {len(failures)} conformance check(s):\n"
            + "\n".join(failures)
        )


def parametrize_with_checks(components: Iterable[type | Subject]) -> Any:
    """A pytest decorator: one test per component x applicable check, with ids like
    ``RasterRenderer-check_marking``. The test takes ``component`` and ``check`` and calls
    ``check(component)``::

        @parametrize_with_checks([MyRenderer, Subject(MyEffect, {"label": "wind"})])
        def test_conformance(component, check):
            check(component)

    A subject whose :attr:`Subject.requires` are not installed gets skipped tests, with the
    reason naming the missing modules; its :attr:`Subject.expected_failures` become strict
    xfails. A name in ``expected_failures`` that is not one of its checks raises
    :class:`ConformanceError`.
    """
    import pytest

    params = []
    for component in components:
        s = as_subject(component)
        checks = checks_for(s)
        stale = sorted(set(s.expected_failures) - {c.name for c in checks})
        if stale:
            raise ConformanceError(
                f"{s.name}: expected_failures names {stale}, which are not among its checks "
                f"{[c.name for c in checks]}"
            )
        missing = s.missing()
        skip = pytest.mark.skip(reason=f"{s.name} needs {', '.join(missing)}, not installed")
        for check in checks:
            marks = [skip] if missing else []
            if check.name in s.expected_failures:
                reason = s.expected_failures[check.name]
                marks.append(pytest.mark.xfail(raises=ConformanceError, strict=True, reason=reason))
            params.append(pytest.param(s, check, marks=marks, id=f"{s.name}-{check.name}"))
    return pytest.mark.parametrize(("component", "check"), params)


# --------------------------------------------------------------------------- other process


def import_path(cls: type) -> str:
    """``module:Qualname`` of ``cls``, for a check that re-imports it in another process."""
    if "<locals>" in cls.__qualname__ or cls.__module__ == "__main__":
        raise ConformanceError(
            f"{label(cls)}: the other-process check re-imports the class as "
            f"{cls.__module__}:{cls.__qualname__}; define it at module level in an importable "
            "module"
        )
    return f"{cls.__module__}:{cls.__qualname__}"


def load(path: str) -> Any:
    """The object named by ``module:Qualname``."""
    mod, _, qual = path.partition(":")
    obj: Any = importlib.import_module(mod)
    for part in qual.split("."):
        obj = getattr(obj, part)
    return obj


def run_in_child(cls: type, function: str, spec: Mapping[str, Any]) -> Any:
    """``function(spec)`` (a ``module:name`` path) run in a fresh Python process with another hash
    seed; returns what it returned, through JSON. ``spec`` must be JSON values."""
    try:
        arg = json.dumps(dict(spec))
    except TypeError as exc:
        raise ConformanceError(
            f"{label(cls)}: options {dict(spec.get('options', {}))!r} must be JSON values for the "
            f"other-process check ({exc})"
        ) from exc
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join(p for p in sys.path if p),
        "PYTHONHASHSEED": "12345",
    }
    code = "from physbench.testing.kit import _child; _child()"
    proc = subprocess.run(
        [sys.executable, "-c", code, function, arg],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )
    if proc.returncode != 0:
        raise ConformanceError(
            f"{label(cls)}: the run in another process failed:\n{proc.stderr.strip()[-2000:]}"
        )
    return json.loads(proc.stdout)


def _child() -> None:
    print(json.dumps(load(sys.argv[1])(json.loads(sys.argv[2]))))

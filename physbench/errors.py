"""Typed errors. Every message names the bad value and what would be accepted."""

from __future__ import annotations

from collections.abc import Iterable


class PhysbenchError(Exception):
    """Base class of every error physbench raises on purpose."""


class PhysbenchWarning(UserWarning):
    """Base class of the warnings physbench issues on purpose; the command line shows each as one
    ``physbench COMMAND: warning: ...`` line."""


def plural(noun: str) -> str:
    """``body`` -> ``bodies``, ``scene`` -> ``scenes`` (the nouns error messages use)."""
    if noun.endswith("y") and noun[-2:-1] not in ("a", "e", "o", "u"):
        return noun[:-1] + "ies"
    return noun + ("es" if noun.endswith(("s", "x", "ch", "sh")) else "s")


def counted(n: int, noun: str) -> str:
    """``1 worker``, ``3 workers``: ``n`` and its ``noun`` in agreement, for messages."""
    return f"{n} {noun if n == 1 else plural(noun)}"


class UnknownNameError(PhysbenchError, KeyError):
    """A name (scene, engine, estimator, parameter, ...) that is not registered."""

    def __init__(
        self, kind: str, name: str, known: Iterable[str], *, where: str = "", hint: str = ""
    ) -> None:
        """``hint``: a sentence added at the end (e.g. the plugins that failed to load)."""
        self.kind, self.name, self.known = kind, name, sorted(known)
        listed = ", ".join(self.known) or "(none registered)"
        at = f" {where}" if where else ""
        head, of, rest = kind.partition(" of ")  # "body of scene 'x'": the head noun is plural
        words = head.split(" ")
        many = " ".join([*words[:-1], plural(words[-1])]) + of + rest
        tail = f"; {hint}" if hint else ""
        super().__init__(f"unknown {kind} {name!r}{at}; known {many}{at}: {listed}{tail}")

    def __str__(self) -> str:  # KeyError would quote the whole message
        return str(self.args[0])


class SceneError(PhysbenchError, ValueError):
    """A scene description that is invalid: names the key, the value and (for files) the line."""

    def __init__(
        self,
        message: str,
        *,
        key: str | None = None,
        value: object = None,
        source: str | None = None,
        line: int | None = None,
    ) -> None:
        self.key, self.value, self.source, self.line, self.reason = (
            key,
            value,
            source,
            line,
            message,
        )
        where = ""
        if source is not None:
            where = f"{source}:{line}: " if line is not None else f"{source}: "
        elif line is not None:
            where = f"line {line}: "
        what = f"{key} = {value!r}: " if key is not None else ""
        super().__init__(f"{where}{what}{message}")


class SimulationError(PhysbenchError, RuntimeError):
    """A simulation that exploded: NaN state or a body far outside the world."""

    def __init__(self, message: str, *, engine: str, frame: int, body: str | None = None) -> None:
        self.engine, self.frame, self.body = engine, frame, body
        super().__init__(
            f"[{engine}] frame {frame}" + (f", body {body!r}" if body else "") + f": {message}"
        )


class PluginError(PhysbenchError):
    """Plugin registration problems (duplicate names, hooks that match no spec)."""


class OptionError(PhysbenchError, ValueError):
    """A component that does not take an option, or refuses its value: names the component, where
    it comes from, the option and the options it takes (raised by
    :func:`physbench.components.create`)."""

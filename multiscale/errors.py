"""Exceptions shared by every part of the package.

User-caused problems are ``InputError`` (a ``ValueError``) naming the argument or scene field;
solvers that do not converge raise ``ConvergenceError`` carrying the residual history and,
where one exists, the partial result.
"""
from __future__ import annotations


class MultiscaleError(Exception):
    """Base class of every error raised on purpose by multiscale."""


class InputError(MultiscaleError, ValueError):
    """Bad input: names the argument (or field), the value and what is allowed."""

    def __init__(self, name: str, value, allowed: str):
        self.name, self.value, self.allowed = name, value, allowed
        super().__init__(f"{name} = {_short(value)}: {allowed}")

    def __reduce__(self):      # pickled as given (MPI broadcasts of an error met by one rank)
        return type(self), (self.name, self.value, self.allowed)


class SceneError(InputError):
    """Bad scene or study file; ``problems`` lists every problem found (one line each)."""

    def __init__(self, problems: list[str] | str):
        self.problems = [problems] if isinstance(problems, str) else list(problems)
        MultiscaleError.__init__(self, "\n".join(self.problems))
        self.name, self.value, self.allowed = "scene", None, self.problems[0] if self.problems else ""

    def __reduce__(self):
        return type(self), (self.problems,)


class OutputError(MultiscaleError, OSError):
    """A result could not be written (disk full, read-only folder, ...); raised on every rank."""


class ConvergenceError(MultiscaleError, RuntimeError):
    """An iterative solver stopped before reaching its tolerance.

    ``history`` holds the residual per iteration; ``result`` the partial result (or None).
    """

    def __init__(self, message: str, history=None, result=None):
        self.history = list(history) if history is not None else []
        self.result = result
        super().__init__(message)


def _short(value, limit: int = 60) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def check_positive(name: str, value, *, allow_zero: bool = False) -> float:
    """Return ``value`` as float, or raise InputError if it is not finite and > 0 (>= 0)."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(name, value, "must be a real number") from None
    ok = v >= 0 if allow_zero else v > 0
    if not (ok and v == v and v != float("inf")):
        raise InputError(name, value, "must be finite and " + (">= 0" if allow_zero else "> 0"))
    return v

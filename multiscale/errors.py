"""Exceptions shared by every part of the package.

User-caused problems are ``InputError`` (a ``ValueError``) naming the argument or scene field;
solvers that do not converge raise ``ConvergenceError`` carrying the residual history and,
where one exists, the partial result.
"""
from __future__ import annotations

import numbers
import re

import numpy as np


class MultiscaleError(Exception):
    """Base class of every error raised on purpose by multiscale."""


class InputError(MultiscaleError, ValueError):
    """Bad input: names the argument (or field), the value and what is allowed. ``value`` None: no
    value to show (a missing option or key): the message is "name: allowed", not "name = None: ..."."""

    def __init__(self, name: str, value, allowed: str):
        self.name, self.value, self.allowed = name, value, allowed
        super().__init__(f"{name}: {allowed}" if value is None else f"{name} = {_short(value)}: {allowed}")

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


class InputErrors(SceneError):
    """Several InputErrors found together (every body of a geometry file that names no volume);
    ``errors`` keeps each with its name and value."""

    def __init__(self, errors: list[InputError]):
        self.errors = list(errors)
        super().__init__([str(e) for e in self.errors])

    def __reduce__(self):
        return type(self), (self.errors,)

    @staticmethod
    def each(exc: InputError) -> list[InputError]:
        """The InputErrors that ``exc`` stands for: its ``errors``, or itself."""
        return exc.errors if isinstance(exc, InputErrors) else [exc]


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


class ClosedError(MultiscaleError, RuntimeError):
    """A model used to solve after its ``close()`` destroyed its PETSc solvers (its fields stay
    readable): raised instead of PETSc's crash on the destroyed objects."""


class Interrupted(KeyboardInterrupt):
    """Ctrl-C honoured at the end of a step (``multiscale.io.StepStop``): the results up to that
    step were written. The message says which ("after step 12 of 50"); ``warnings``: what the run
    noted up to there (``workflows.model.run_notes``), for its provenance."""

    def __init__(self, message: str = "", warnings=()):
        super().__init__(message)
        self.warnings = tuple(warnings)


def behind(exc: BaseException | None, kind: type) -> BaseException | None:
    """The exception of type ``kind`` behind ``exc``: ``exc`` itself, or the one that caused it on its
    way out of a library (petsc4py turns one raised in a callback of SNES into ``PETSc.Error`` 101,
    whose text is PETSc's stack); None if there is none."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, kind):
            return exc
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return None


def interrupted(exc: BaseException) -> KeyboardInterrupt | None:
    """The Ctrl-C behind ``exc`` (``behind``), None if there is none."""
    return behind(exc, KeyboardInterrupt)


MAX_TOML_BYTES = 16 * 2**20      # a scene or study file larger than this is not one


def read_toml_text(path, what: str) -> str:
    """The text of the ``what`` file (e.g. "scene") at ``path``: UTF-8, with or without a byte-order
    mark (Windows editors write one). A SceneError names the file when it cannot be read, is not
    UTF-8 (UTF-16 is named) or holds over MAX_TOML_BYTES (/dev/zero given as a scene filled memory)."""
    try:
        with open(path, "rb") as stream:
            data = stream.read(MAX_TOML_BYTES + 1)
    except OSError as exc:
        raise SceneError(f"{path}: cannot read the {what} file ({exc.strerror or exc})") from None
    if len(data) > MAX_TOML_BYTES:
        raise SceneError(f"{path}: is no {what} file, it holds over {MAX_TOML_BYTES // 2**20} MiB")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        why = "it is UTF-16: save it as UTF-8" if data[:2] in (b"\xff\xfe", b"\xfe\xff") \
            else f"{exc.reason} at byte {exc.start}"
        raise SceneError(f"{path}: cannot read the {what} file, it is not UTF-8 text ({why})") from None


def toml_problem(source, exc: Exception, text: str) -> SceneError:
    """A TOML syntax error of ``text`` (from ``source``) with the line it is on: tomllib gives the
    position only, and "Cannot overwrite a value (at line 35, column 23)" is a key given twice."""
    at = re.search(r"\(at line (\d+), column \d+\)", str(exc))
    lines = text.splitlines()
    shown = f": {lines[int(at.group(1)) - 1].strip()!r}" if at and 0 < int(at.group(1)) <= len(lines) else ""
    twice = " (a key or table given twice)" if "Cannot overwrite" in str(exc) or "Cannot declare" in str(exc) else ""
    return SceneError(f"{source}: not valid TOML: {exc}{shown}{twice}")


def _short(value, limit: int = 60) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def check_real(name: str, value) -> float:
    """``value`` as a float if it is a real number (not a string, a bool or an array), else
    ``InputError`` naming ``name``; NaN and inf pass (callers check ranges)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real) and not _scalar_array(value):
        raise InputError(name, value, "must be a real number")
    return float(value)


def check_positive(name: str, value, *, allow_zero: bool = False) -> float:
    """Return ``value`` as float, or raise InputError if it is not a real number, finite and > 0
    (>= 0). Strings, bools and arrays are refused (``"1e9"`` used to pass as a number)."""
    v = check_real(name, value)
    ok = v >= 0 if allow_zero else v > 0
    if not (ok and v == v and v != float("inf")):
        raise InputError(name, value, "must be finite and " + (">= 0" if allow_zero else "> 0"))
    return v


def check_count(name: str, value, minimum: int = 1) -> int:
    """A whole number >= ``minimum`` (an integral float such as 3.0 too; no NaN, no silent
    truncation of 2.5, no bool), else ``InputError``."""
    v = check_real(name, value)
    if not (v == v and abs(v) != float("inf") and v == int(v) and v >= minimum):
        raise InputError(name, value, f"must be a whole number >= {minimum}")
    return int(v)


def check_pair(name: str, value, check) -> tuple:
    """One value or two (x, y), each passed through ``check(name, v)`` (e.g. ``check_positive``,
    ``check_count``), as a pair; else ``InputError``."""
    values = tuple(value) if isinstance(value, (tuple, list, np.ndarray)) else (value,)
    if len(values) not in (1, 2):
        raise InputError(name, value, "one value or a pair (x, y)")
    return tuple(check(name, v) for v in values * (3 - len(values)))


def check_flag(name: str, value) -> bool:
    """True or False (numpy bools too), else ``InputError`` (``"no"`` is not False)."""
    if type(value).__name__ not in ("bool", "bool_"):
        raise InputError(name, value, "must be True or False")
    return bool(value)


def check_field(name: str, value, *, min_ndim: int = 0, nonnegative: bool = False):
    """``value`` as a finite float numpy array with at least ``min_ndim`` axes (>= 0 if
    ``nonnegative``), else ``InputError`` naming ``name``."""
    a = np.asarray(value) if not isinstance(value, (str, bytes)) else np.asarray(None)
    if a.dtype.kind not in "biuf" or a.dtype.kind == "b" and a.ndim == 0:
        raise InputError(name, _summary(value), "must be a number or an array of numbers")
    a = a.astype(float)
    if a.ndim < min_ndim:
        raise InputError(name + ".shape", a.shape, f"needs at least {min_ndim} axes")
    if not np.all(np.isfinite(a)):
        raise InputError(name, _summary(value), f"{non_finite(a)}: must be finite")
    if nonnegative and np.any(a < 0):
        raise InputError(name, _summary(value), "must be >= 0")
    return a


def check_mask(name: str, value, *, min_ndim: int = 2) -> np.ndarray:
    """``value`` as a bool array with at least ``min_ndim`` axes: bools, or numbers all 0 or 1, else
    ``InputError`` (a gap or pressure field given as a contact mask was read as "non-zero: in
    contact", its out-of-contact cells: a user trial)."""
    a = check_field(name, value, min_ndim=min_ndim)
    if not np.all((a == 0) | (a == 1)):
        raise InputError(name, _summary(value), "must be a mask: True (or 1) where in contact, e.g. "
                         "ContactResult.contact, not a gap or pressure field")
    return a == 1


def check_table(name: str, value, what: str) -> tuple[np.ndarray, np.ndarray]:
    """(temperatures [K], values) of a table given as two 1-D sequences of equal length >= 2 with
    finite, strictly increasing temperatures; InputError naming ``name`` (``what``: the allowed forms)."""
    try:
        temps, values = (np.asarray(v, dtype=float) for v in value)
    except (TypeError, ValueError):
        raise InputError(name, value, what) from None
    if temps.ndim != 1 or temps.shape != values.shape or temps.size < 2:
        raise InputError(name, value, "a table needs two 1-D arrays of equal length >= 2")
    if not (np.all(np.isfinite(temps)) and np.all(np.diff(temps) > 0)):
        raise InputError(f"{name}.temperatures", temps, "must be finite and strictly increasing")
    return temps, values


def check_instance(name: str, value, kind: type | tuple, what: str):
    """``value`` if it is a ``kind``, else ``InputError`` saying ``what`` is expected."""
    if not isinstance(value, kind):
        raise InputError(name, value, f"must be {what}")
    return value


def _scalar_array(value) -> bool:
    """A 0-d numpy array or numpy scalar of a real (non-bool) number."""
    dtype, shape = getattr(value, "dtype", None), getattr(value, "shape", None)
    return dtype is not None and shape == () and dtype.kind in "iuf"


def non_finite(a: np.ndarray) -> str:
    """What an error message says of an array holding NaN or inf: how many and where the first is."""
    bad = ~np.isfinite(a)
    first = tuple(int(i) for i in np.argwhere(bad)[0]) if a.ndim else ()
    return f"{int(bad.sum())} of its {a.size} values are NaN or inf" + (f" (the first at index {first})" if a.ndim else "")


def _summary(value):
    """What an error message shows of an array: its shape, else the value."""
    shape = getattr(value, "shape", None)
    return f"array of shape {shape}" if shape else value

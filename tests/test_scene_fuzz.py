"""Property-based test of the scene loader (issue 21): the demo scenes mutated at random (a key
dropped, a value retyped, a wrong unit, a value far out of range, a non-finite value, an unknown
key) give either one clean ``SceneError`` whose problems name the mutated field, or a scene that
validates and is plausible (a value outside its plausible range is a warning naming the field).
Never another exception. A few hundred examples in CI (deterministic); more with
MULTISCALE_FUZZ_EXAMPLES=N (then random)."""
import math
import os
import re
import tomllib
from pathlib import Path

import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from multiscale.errors import SceneError  # noqa: E402
from multiscale.scene import loads  # noqa: E402

DEMOS = Path(__file__).parent.parent / "demos"
# the scenes that load in milliseconds (the others inspect CAD files or measurements)
SCENES = {name: (DEMOS / f"{name}.toml").read_text() for name in
          ("block_on_flat", "brake_squeal", "pin_on_disc", "pin_on_disc_perfect", "pin_on_disc_thesis")}
EXAMPLES = int(os.environ.get("MULTISCALE_FUZZ_EXAMPLES", "300"))


def leaves(table: dict, prefix: str = "") -> list[tuple[str, object]]:
    """(dotted path, value) of every scalar or list value outside arrays of tables."""
    out = []
    for key, value in table.items():
        path = f"{prefix}{key}"
        if isinstance(value, dict):
            out += leaves(value, path + ".")
        elif not (isinstance(value, list) and value and isinstance(value[0], dict)):
            out.append((path, value))
    return out


LEAVES = {name: leaves(tomllib.loads(text)) for name, text in SCENES.items()}
NUMBER = re.compile(r"^\s*([-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?)\s*(.*)$")


def scaled(value, factor: float):
    """``value`` (a number or "number unit") times ``factor``; None if it is neither."""
    if isinstance(value, bool):
        return None
    if isinstance(value, (int, float)):
        return value * factor
    if isinstance(value, str) and (m := NUMBER.match(value)):
        return f"{float(m.group(1)) * factor:g} {m.group(4)}".strip()
    return None


def drop(text: str, path: str) -> str | None:
    """The scene text without the line of ``path`` (a one-line ``key = value`` in its table)."""
    *tables, key = path.split(".")
    current, out, dropped = "", [], False
    for line in text.splitlines():
        head = re.match(r"^\s*\[([^\[\]]+)\]\s*(#.*)?$", line)
        if head:
            current = head.group(1).strip()
        elif current == ".".join(tables) and re.match(rf"^\s*{re.escape(key)}\s*=", line) and \
                line.count("[") == line.count("]"):
            dropped = True
            continue
        out.append(line)
    return "\n".join(out) if dropped else None


@st.composite
def mutations(draw):
    name = draw(st.sampled_from(sorted(SCENES)))
    path, value = draw(st.sampled_from(LEAVES[name]))
    kind = draw(st.sampled_from(["drop", "retype", "unit", "range", "nonfinite", "unknown"]))
    if kind == "drop":
        return name, kind, path, None
    if kind in ("unit", "range", "nonfinite"):        # magnitudes only (not names, paths, switches)
        hypothesis.assume(scaled(value, 1.0) is not None)
    if kind == "retype":
        new = draw(st.sampled_from([True, "seven", [1, 2], {"a": 1}, -7, 0]))
    elif kind == "unit":
        number = draw(st.sampled_from(["3", "0.5", "2e3"]))
        new = f"{number} {draw(st.sampled_from(['kg', 'furlong', 'W/K', 'Pa s', 'degC/m']))}"
    elif kind == "range":
        new = scaled(value, draw(st.sampled_from([1e12, -1e9])))
        hypothesis.assume(scaled(new, 1.0) != scaled(value, 1.0))       # not 0 -> 0
    elif kind == "nonfinite":
        new = draw(st.sampled_from([math.nan, math.inf, -math.inf, "nan Pa", "inf m"]))
    else:
        path = path.rsplit(".", 1)[0] + ".zz_unknown" if "." in path else "zz_unknown"
        new = 1.0
    return name, kind, path, new


def named(problem: str, path: str) -> bool:
    """Does a problem (or warning) line name the field ``path`` (or a table it is in)?"""
    parts = path.split(".")
    return any(".".join(parts[:n]) in problem for n in range(len(parts), 0, -1))


@settings(max_examples=EXAMPLES, deadline=None, derandomize="MULTISCALE_FUZZ_EXAMPLES" not in os.environ,
          suppress_health_check=[HealthCheck.too_slow])
@given(mutations())
def test_a_mutated_demo_scene_is_a_clean_error_or_a_plausible_scene(mutation):
    name, kind, path, value = mutation
    text = SCENES[name]
    if kind == "drop":
        text = drop(text, path)
        hypothesis.assume(text is not None)
        overrides = None
    else:
        overrides = {path: value}
    try:
        scene = loads(text, DEMOS, overrides=overrides)
    except SceneError as exc:
        assert exc.problems and all(line.strip() for line in exc.problems)
        assert any(named(p, path) for p in exc.problems), (kind, path, value, exc.problems)
        return
    # accepted: only a value that is not wrong may pass
    assert kind in ("drop", "retype", "unit", "range"), (kind, path, value)
    if kind == "range" and isinstance(value, (int, float, str)) and path not in ("name", "description"):
        implausible = [w for w in scene.warnings if named(w, path)]
        assert implausible or _plausible(scene, path), (path, value, scene.warnings)


def _plausible(scene, path: str) -> bool:
    """A range-mutated value accepted without a warning: only fields that are not physical
    magnitudes (names, switches, counts the scene checks against each other) are allowed."""
    return path.split(".")[-1] in {"name", "description", "folder", "every", "seed", "law_points"}

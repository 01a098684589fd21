"""CLI `multiscale check|run`: clear one-line errors and a non-zero exit for bad input, never a
traceback; a summary for a good scene; earlier results are not overwritten without --overwrite."""
import contextlib
import io
import json
import os
import re
import subprocess
import sys
import types
from pathlib import Path

import pytest

from multiscale import cli
from multiscale.cli import main

BLOCK = (Path(__file__).resolve().parents[1] / "demos" / "block_on_flat.toml").read_text()
THERMAL = BLOCK.replace('effects = ["contact"]', 'effects = ["contact", "thermal"]').replace(
    'E = "4 GPa"', 'E = "4 GPa"\nkappa = "5 W/(m K)"\nchi = "1e-6 m^2/s"').replace(
    'E = "210 GPa"', 'E = "210 GPa"\nkappa = "45 W/(m K)"\nchi = "1e-5 m^2/s"') + '\n[time]\nend = "1 s"\n'
COOLED = THERMAL + '[[boundary]]\nsurfaces = ["free:block"]\nconvection = "10 W/(m^2 K)"\nambient = "20 degC"\n'


def _write(tmp_path, text, name="scene.toml"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return str(path)


def test_thermal_variant_is_good(tmp_path, capsys):
    assert main(["check", _write(tmp_path, THERMAL)]) == 0
    out = capsys.readouterr().out
    assert "thermal        transient conduction in block, flat" in out
    assert main(["check", _write(tmp_path, COOLED)]) == 0


BAD = [  # (name, the demo block scene changed, the one expected message)
    ("missing field", BLOCK.replace('E = "4 GPa"\n', ""),
     "materials.block.E: missing; required: a pressure or modulus > 0 Pa"),
    ("wrong unit", BLOCK.replace('"1 MPa"', '"1 MN"'),
     'loading.pressure = "1 MN": expected a pressure or modulus (Pa, kPa, MPa, GPa, bar); '
     'the unit "MN" is a force'),
    ("negative modulus", BLOCK.replace('"210 GPa"', '"-210 GPa"'),
     'materials.flat.E = "-210 GPa": must be > 0 Pa (got -2.1e+11 Pa)'),
    ("unknown effect", BLOCK.replace('["contact"]', '["contact", "thermol"]'),
     'effects = ["contact", "thermol"]: item 2 ("thermol"): unknown (did you mean "thermal"?); '
     "allowed: contact, friction, thermal, heat_partition, conductance, expansion, roughness, layers, "
     "wear, plasticity, stability"),
    ("unknown key", BLOCK.replace("penalty =", "penalty_stiffness ="),
     'interface.penalty_stiffness: unknown key (did you mean "penalty"?); allowed: penalty, partition, '
     "conductance"),
    ("effect without inputs", THERMAL.replace('kappa = "5 W/(m K)"\n', ""),
     'materials.block.kappa: missing; effect "thermal" needs it: a thermal conductivity > 0 W/(m K)'),
    ("effect without its effect", THERMAL.replace('["contact", "thermal"]', '["thermal", "conductance"]')
     .replace("[interface]", '[interface]\nconductance = "1e5 W/(m^2 K)"'),
     'effects: "conductance" needs effect "contact" too (add it to effects)'),
    ("unknown body material", BLOCK.replace("[materials.flat]", "[materials.flat_]"),
     'materials.flat_: unknown material of builder "block_on_flat" (did you mean "flat"?)'),
    ("malformed TOML", BLOCK.replace('E = "4 GPa"', 'E = "4 GPa'), "not valid TOML: "),
    ("a key twice", BLOCK.replace('E = "4 GPa"', 'E = "4 GPa"\nE = "5 GPa"'),      # (it gave the position only)
     "not valid TOML: Cannot overwrite a value (at line 18, column 12): 'E = \"5 GPa\"' (a key or table given twice)"),
    ("not a table", "loading = 3\n" + BLOCK.replace('[loading]\npressure = "1 MPa"\n', ""),
     "loading = 3: must be a table [loading]"),
    ("unknown thermal surface", COOLED.replace('"free:block"', '"block_topp"'),
     'boundary[1].surfaces: "block_topp" is not a surface of builder "block_on_flat"; known: block_top, '
     "flat_bottom, symmetry_x, symmetry_y, free:block, free:flat"),
    ("unknown free: body", COOLED.replace('"free:block"', '"free:blok"'),
     'boundary[1].surfaces: "free:blok" is not a surface of builder "block_on_flat"'),
    ("ambient without convection or emissivity", COOLED.replace('convection = "10 W/(m^2 K)"', 'temperature = "300 K"'),
     "boundary[1].ambient: only used with boundary[1].convection or boundary[1].emissivity"),
    ("convection table of one row", COOLED.replace('"10 W/(m^2 K)"', '[["0 rad/s", 10]]'),
     'boundary[1].convection = [["0 rad/s", 10]]: needs at least 2 rows [speed, h] with increasing speed'),
    ("material table of one row", THERMAL.replace('kappa = "5 W/(m K)"', 'kappa = [["300 K", 5]]'),
     'materials.block.kappa = [["300 K", 5]]: needs at least 2 rows [temperature, kappa] with increasing '
     "temperature"),
    ("material table out of order", THERMAL.replace('kappa = "5 W/(m K)"', 'kappa = [["400 K", 5], ["300 K", 6]]'),
     'materials.block.kappa = [["400 K", 5], ["300 K", 6]]: temperature must increase strictly from row to row '
     '(row 2: 300 K after 400 K)'),
]


@pytest.mark.parametrize("name, text, message", BAD, ids=[b[0] for b in BAD])
def test_bad_scene_gives_one_clear_line_and_exit_2(tmp_path, capsys, name, text, message):
    assert text not in (BLOCK, THERMAL, COOLED)
    path = _write(tmp_path, text)
    assert main(["check", path]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    errors = [line for line in err.splitlines() if line.startswith("error: ")]
    assert len(errors) == 1, err
    assert message in errors[0], err
    assert err.splitlines()[-1] == f"{path}: 1 problem"


def test_missing_file_is_a_clear_error(tmp_path, capsys):
    assert main(["check", str(tmp_path / "nope.toml")]) == 2
    err = capsys.readouterr().err
    assert "cannot read the scene file" in err and "Traceback" not in err


def test_scene_encodings_and_endless_files(tmp_path, capsys, monkeypatch):
    """A UTF-8 scene with a byte-order mark (Windows editors) is read; a UTF-16 one is named with
    what to do (before: a codec message); a file larger than any scene is refused after a bounded
    read (before: /dev/zero given as the scene filled memory)."""
    bom = tmp_path / "bom.toml"
    bom.write_bytes(b"\xef\xbb\xbf" + BLOCK.encode())
    assert main(["check", str(bom)]) == 0
    capsys.readouterr()
    wide = tmp_path / "wide.toml"
    wide.write_text(BLOCK, encoding="utf-16")
    assert main(["check", str(wide)]) == 2
    assert "it is UTF-16: save it as UTF-8" in capsys.readouterr().err
    monkeypatch.setattr("multiscale.errors.MAX_TOML_BYTES", 100)
    assert main(["check", _write(tmp_path, BLOCK)]) == 2
    err = capsys.readouterr().err
    assert "is no scene file, it holds over" in err and "Traceback" not in err


def test_output_into_a_closed_pipe_ends_quietly(tmp_path, monkeypatch, capsys):
    """`multiscale surface FILE | head` ended with a BrokenPipeError traceback (a user trial): the
    reader is gone, the command ends with status 141 (a shell's 128 + SIGPIPE) and no traceback."""
    import numpy as np
    np.save(tmp_path / "h.npy", np.random.default_rng(0).normal(size=(32, 32)) * 1e-7)
    read, write = os.pipe()
    os.close(read)
    saved = os.dup(1)
    stream = open(os.dup(write), "w", buffering=1)          # line-buffered, as a pipe
    monkeypatch.setattr(sys, "stdout", stream)
    try:
        os.dup2(write, 1)
        assert main(["surface", str(tmp_path / "h.npy"), "--pixel-size", "1 um"]) == 141
    finally:
        os.dup2(saved, 1)
        os.close(saved)
        os.close(write)
        with contextlib.suppress(OSError):
            stream.close()                 # its last line cannot go anywhere
    assert "Traceback" not in capsys.readouterr().err


def test_a_run_into_a_closed_pipe_goes_on_to_its_results(tmp_path, monkeypatch, capsys):
    """`multiscale run SCENE | head`: the run went on after head left until its next line, where
    gmsh's SIGPIPE (set to the default by its initialisation) killed it, no result written (PETSc's
    handler aborted it otherwise). Now its console goes to /dev/null and the run ends as it would
    (on the code before, this test kills pytest with status 141)."""
    pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")
    folder = tmp_path / "out"
    path = _write(tmp_path, BLOCK.replace("../results/block_on_flat", str(folder)))
    read, write = os.pipe()
    os.close(read)
    saved = os.dup(1)
    stream = open(os.dup(write), "w", buffering=1)
    monkeypatch.setattr(sys, "stdout", stream)
    try:
        os.dup2(write, 1)
        assert main(["run", path]) == 0
    finally:
        os.dup2(saved, 1)
        os.close(saved)
        os.close(write)
        with contextlib.suppress(OSError):
            stream.close()
    assert json.loads((folder / "provenance.json").read_text())["status"] == "finished"
    assert (folder / "interface.h5").is_file() and "Traceback" not in capsys.readouterr().err
    # closed descriptors (`run >&- 2>&-`: Python's streams are None) ended the run at its first stage line
    monkeypatch.setattr(sys, "stdout", None)
    monkeypatch.setattr(sys, "stderr", None)
    assert main(["run", path, "--overwrite"]) == 0


def test_a_run_larger_than_the_free_memory_is_warned_at_once(tmp_path, monkeypatch, capsys):
    """Once the model is built, a run whose estimated peak (``memory.run_memory``) exceeds what the
    machine has free says so before its solves (else the OOM killer ends it without a word)."""
    pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")
    from multiscale.workflows import model
    monkeypatch.setattr(model, "memory_available", lambda: 1e6)
    path = _write(tmp_path, BLOCK.replace("../results/block_on_flat", str(tmp_path / "out")))
    assert main(["run", path]) == 0
    said = capsys.readouterr()
    err = said.err
    assert "  load: 1 MPa on block_top: 100 N\n" in said.out      # the meshed top's resultant, said once meshed
    assert re.search(r"warning: a transient run of [\d ]+ displacement dofs takes about [\d.]+ GB at its peak \(an "
                     r"estimate from measured runs, docs/performance.rst; up to 1.15 times that\), near or above the "
                     r"0.001 GB this machine has free: it may be killed", err), err


def test_check_without_dolfinx_says_that_run_needs_it(tmp_path, capsys, monkeypatch):
    """On a micro-only install check said OK alone; run then refused (a user trial)."""
    import importlib.util
    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "dolfinx" else real(name, *a))
    assert main(["check", _write(tmp_path, BLOCK)]) == 0
    assert "warning: multiscale run of this scene needs DOLFINx, not installed here: pip install -e '.[fem]'" in \
        capsys.readouterr().err


def test_check_good_scene_prints_summary(tmp_path, capsys):
    path = _write(tmp_path, BLOCK)
    assert main(["check", path]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("scene block_on_flat")
    assert any(line.startswith("  bodies    block (block: block) | flat (flat: flat)") for line in out)
    assert any(line.startswith("  effects   contact") for line in out)
    assert any("penalty K_n = 1e+13 Pa/m" in line for line in out)
    # the pressure's faces and force (the block's 10 x 10 mm top: 100 N; before, only "1 MPa")
    assert any(line.startswith("  loading   1 MPa on block_top (100 mm^2): 100 N, ") for line in out)
    assert out[-1] == f"{path}: OK"


def test_check_several_files_fails_if_one_fails(tmp_path, capsys):
    good, bad = _write(tmp_path, BLOCK, "a.toml"), _write(tmp_path, BLOCK.replace("nu = 0.3", "nu = 0.7"), "b.toml")
    assert main(["check", good, bad]) == 2
    captured = capsys.readouterr()
    assert f"{good}: OK" in captured.out
    assert "error: materials.flat.nu = 0.7: must be in (-1, 0.5)" in captured.err


def test_check_refuses_an_output_folder_run_cannot_create(tmp_path, capsys):
    """check said OK where run stopped at once ('cannot write into the output folder ...: Not a
    directory'): a folder under a file, in a folder without write permission, or in /proc."""
    (tmp_path / "notes.txt").write_text("mine")
    scene = BLOCK.replace('folder = "../results/block_on_flat"', 'folder = "notes.txt/run1"')
    assert main(["check", _write(tmp_path, scene)]) == 2
    err = capsys.readouterr().err
    assert err.splitlines()[0] == (f'error: output.folder = "{tmp_path / "notes.txt" / "run1"}": cannot be created: '
                                   f"{tmp_path / 'notes.txt'} is a file, not a folder")
    locked = tmp_path / "locked"
    locked.mkdir(mode=0o555)
    scene = BLOCK.replace('folder = "../results/block_on_flat"', 'folder = "locked/run1"')
    code = main(["check", _write(tmp_path, scene)])
    err = capsys.readouterr().err
    if os.geteuid() != 0:          # root writes anywhere
        assert code == 2 and f"cannot be created: {locked} is not writable" in err
    assert main(["check", _write(tmp_path, BLOCK.replace('"../results/block_on_flat"', '"new/deeper"'))]) == 0
    if os.path.isdir("/proc") and os.statvfs("/proc").f_blocks == 0:     # root "may write" in /proc, in vain
        assert main(["check", _write(tmp_path, BLOCK.replace('"../results/block_on_flat"', '"/proc/run1"'))]) == 2
        assert "cannot be created: /proc is on a file system without storage" in capsys.readouterr().err


@pytest.fixture
def fake_runner(monkeypatch):
    """A stand-in for multiscale.workflows recording its calls (no DOLFINx needed)."""
    calls = []
    module = types.ModuleType("multiscale.workflows")
    module.run = lambda scene, overwrite=False, resume=False, **kw: calls.append((scene.name, overwrite, resume))
    monkeypatch.setitem(sys.modules, "multiscale.workflows", module)
    return calls


def test_run_hands_the_scene_to_the_runner(tmp_path, fake_runner):
    path = _write(tmp_path, BLOCK.replace("../results/block_on_flat", "out"))
    assert main(["run", path]) == 0
    assert fake_runner == [("block_on_flat", False, False)]


def test_a_run_out_of_memory_says_so_without_a_traceback(tmp_path, capsys, fake_runner, monkeypatch):
    """A squeal run under `ulimit -v` ended in a traceback of numpy's allocation, also inside PETSc's
    callback (its error 101 caused by the MemoryError): now one error line with the memory the
    process may use and what to change, status 2."""
    def starved(scene, **kw):
        raise MemoryError("Unable to allocate 33.3 MiB for an array")
    monkeypatch.setattr(sys.modules["multiscale.workflows"], "run", starved)
    monkeypatch.setattr(cli, "memory_limit", lambda: 3.07e9)
    assert main(["run", _write(tmp_path, BLOCK.replace("../results/block_on_flat", "out"))]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: out of memory (Unable to allocate 33.3 MiB for an array): more than the 3.07 GB "
                          "this process may use") and "Traceback" not in err

    def starved_in_a_callback(scene, **kw):   # petsc4py's error 101 keeps the callback's MemoryError as its cause
        raise RuntimeError("error code 101") from MemoryError("Unable to allocate 8.00 MiB for an array")
    monkeypatch.setattr(sys.modules["multiscale.workflows"], "run", starved_in_a_callback)
    assert main(["run", _write(tmp_path, BLOCK.replace("../results/block_on_flat", "out"))]) == 2
    assert capsys.readouterr().err.startswith("error: out of memory (Unable to allocate 8.00 MiB for an array)")

    def failed(scene, **kw):                  # any other error is not hidden
        raise RuntimeError("error code 101")
    monkeypatch.setattr(sys.modules["multiscale.workflows"], "run", failed)
    with pytest.raises(RuntimeError, match="error code 101"):
        main(["run", _write(tmp_path, BLOCK.replace("../results/block_on_flat", "out"))])


def test_set_gives_scene_keys_over_the_files_to_check_and_run(tmp_path, capsys, monkeypatch):
    """``--set KEY=VALUE``: a value TOML reads (a number, a list, a quoted string) or else the text;
    check judges and summarises the scene with them, run hands it on with them (recorded in its
    overrides, which provenance.json lists); a bad key is the scene's error, a setting without "="
    the command line's; a key given twice takes the last, said."""
    path = _write(tmp_path, BLOCK.replace("../results/block_on_flat", "out"))
    assert main(["check", path, "--set", "loading.pressure=2 MPa", "--set", "interface.penalty=2e13"]) == 0
    out = capsys.readouterr().out
    assert "  loading   2 MPa" in out and "penalty K_n = 2e+13 Pa/m" in out
    assert out.splitlines()[1] == '  set       loading.pressure = "2 MPa", interface.penalty = 2e+13'
    assert main(["check", path, "--set", "loading.pressur=2"]) == 2
    assert 'error: loading.pressur: unknown key (did you mean "pressure"?)' in capsys.readouterr().err
    assert main(["check", path, "--set", "loading.pressure=2 MPa", "--set", "loading.pressure=3 MPa"]) == 0
    twice = capsys.readouterr()                                           # (kept silently: a user trial)
    assert "warning: --set loading.pressure given 2 times (2 MPa, 3 MPa): the last is taken" in twice.err
    assert "  loading   3 MPa" in twice.out
    with pytest.raises(SystemExit) as exit_:
        main(["check", path, "--set", "loading.pressure"])
    assert exit_.value.code == 2 and "KEY=VALUE" in capsys.readouterr().err
    with pytest.raises(SystemExit):                                       # the value left out (an MPI trial)
        main(["check", path, "--set", "output.folder="])
    assert "'output.folder=': no value after '=' (a key cannot be removed" in capsys.readouterr().err
    cooled = _write(tmp_path, COOLED.replace("../results/block_on_flat", "out"), "cooled.toml")
    for key in ("boundary[1].convection", "boundary.1.convection"):      # an entry of [[boundary]] (a user trial:
        assert main(["check", cooled, "--set", f"{key}=30"]) == 0          # "boundary is not a table")
        assert "free:block: convection h = 30 W/(m^2 K)" in capsys.readouterr().out
    assert main(["check", cooled, "--set", "boundary[2].convection=30"]) == 2
    assert "boundary[2].convection: cannot override, 2 is not one of the 1 entries" in capsys.readouterr().err
    assert main(["check", cooled, "--set", "boundary[1]=30"]) == 2
    assert "boundary[1]: cannot override an array of tables whole; give a key" in capsys.readouterr().err
    assert main(["check", cooled, "--set", "effects[2]=thermal"]) == 2     # a plain array (was: "of tables")
    assert "effects[2]: cannot override one item of an array; give the whole array" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exit_:     # meant as TOML (was read as the text "[2,2": a range error)
        main(["check", path, "--set", "micro.zones=[2,2"])
    assert exit_.value.code == 2 and "[2,2 is not a TOML value (Unclosed array" in capsys.readouterr().err
    handed = []
    module = types.ModuleType("multiscale.workflows")
    module.run = lambda scene, **kw: handed.append(scene)
    monkeypatch.setitem(sys.modules, "multiscale.workflows", module)
    settings = ["--set=output.fields=['displacement', 'contact_pressure']", "--set", "loading.pressure='3 MPa'",
                "--set", "output.folder=elsewhere/a", "--set", "interface.penalty=3e13", "--set", "output.figures=false"]
    assert main(["run", path, *settings]) == 0
    scene = handed[0]
    assert scene.output.fields == ("displacement", "contact_pressure") and scene.loading.pressure == 3e6
    assert scene.output.folder == tmp_path / "elsewhere" / "a" and scene.interface.penalty == 3e13
    assert scene.output.figures is False
    assert dict(scene.overrides) == {"output.fields": ["displacement", "contact_pressure"], "loading.pressure": "3 MPa",
                                     "output.folder": "elsewhere/a", "interface.penalty": 3e13, "output.figures": False}


def test_run_refuses_to_overwrite_results(tmp_path, capsys, monkeypatch):
    pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")   # the real workflow
    path = _write(tmp_path, BLOCK.replace("../results/block_on_flat", "out"))
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "history.h5").write_bytes(b"")
    assert main(["run", path]) == 2
    err = capsys.readouterr().err
    assert f'error: output.folder = "{tmp_path / "out"}": holds history.h5, named as this run\'s results but' in err
    assert "--overwrite" in err and "--resume" not in err and "Traceback" not in err
    fake_runner = []
    module = types.ModuleType("multiscale.workflows")
    module.run = lambda scene, overwrite=False, resume=False, **kw: fake_runner.append((scene.name, overwrite, resume))
    monkeypatch.setitem(sys.modules, "multiscale.workflows", module)
    assert main(["check", path]) == 0
    out = capsys.readouterr().out          # a transient scene cannot resume (it was advised to)
    assert ("the output folder already holds 1 entry: run needs --overwrite (deletes the 0 the run before wrote); it "
            "refuses to write over history.h5, not written by a run\n") in out       # (no run recorded it)
    assert main(["run", path, "--overwrite"]) == 0
    assert main(["run", path, "--resume"]) == 0
    assert fake_runner == [("block_on_flat", True, False), ("block_on_flat", False, True)]
    assert (tmp_path / "out" / "history.h5").exists()          # the CLI itself deletes nothing


def test_check_offers_resume_only_where_a_checkpoint_is(tmp_path, capsys):
    """A multiscale scene's output folder holding another file only: check's note asks for
    --overwrite, not --resume (there is nothing to resume from: it offered it, a user trial); with
    the run's checkpoint there, --resume too."""
    demo = Path(__file__).resolve().parents[1] / "demos" / "pin_on_disc.toml"
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("mine\n")
    for checkpoint in (False, True):
        if checkpoint:
            (out / "checkpoint.h5").write_bytes(b"")
        assert main(["check", str(demo), "--set", f'output.folder="{out}"']) == 0
        note = next(line for line in capsys.readouterr().out.splitlines() if "already holds" in line)
        assert ("or --resume" in note) == checkpoint, note


def test_heat_in_a_sliding_translating_body_is_refused_at_check(tmp_path, capsys):
    """The heat problem of a translating body runs only at rest: ``check`` says so (before: only
    ``run``, after meshing)."""
    path = _write(tmp_path, COOLED.replace("../results/block_on_flat", "out")
                  .replace('pressure = "1 MPa"', 'pressure = "1 MPa"\nsliding_speed = "0.1 m/s"'))
    for command in ("check", "run"):
        assert main([command, path]) == 2
        errors = [line for line in capsys.readouterr().err.splitlines() if line.startswith("error: ")]
        assert len(errors) == 1 and "loading.sliding_speed = 0.1 m/s: heat transport needs a rotating body" in errors[0]


def test_run_bad_scene_does_not_reach_the_runner(tmp_path, capsys, fake_runner):
    assert main(["run", _write(tmp_path, BLOCK.replace('"4 GPa"', '"4 GPa/m"'))]) == 2
    assert "materials.block.E" in capsys.readouterr().err and fake_runner == []


def test_run_without_runner_says_so(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "multiscale.workflows", None)   # import fails as if absent
    assert main(["run", _write(tmp_path, BLOCK.replace("../results/block_on_flat", "out"))]) == 2
    err = capsys.readouterr().err
    assert "multiscale.workflows" in err and "Traceback" not in err


def test_check_does_not_import_dolfinx(tmp_path):
    code = ("import sys; from multiscale.cli import main; rc = main(['check', sys.argv[1]]); "
            "assert not any(m.split('.')[0] in ('dolfinx', 'gmsh', 'petsc4py') for m in sys.modules), "
            "sorted(m for m in sys.modules if 'dolfinx' in m or 'gmsh' in m); sys.exit(rc)")
    result = subprocess.run([sys.executable, "-c", code, _write(tmp_path, BLOCK)], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr


# ---------------------------------------------------------------- issue 22: version, help, launcher, stages
def test_version_prints_the_package_version(capsys):
    from multiscale import __version__
    with pytest.raises(SystemExit) as stop:
        main(["--version"])
    assert stop.value.code == 0 and capsys.readouterr().out.strip() == f"multiscale {__version__}"
    # python -m multiscale is the command too (before: "No module named multiscale.__main__")
    ran = subprocess.run([sys.executable, "-m", "multiscale", "--version"], capture_output=True, text=True)
    assert ran.returncode == 0 and ran.stdout.strip() == f"multiscale {__version__}", ran.stderr


def _commands():
    """[] (the top level) and every subcommand the parser knows."""
    import argparse

    from multiscale.cli import build_parser
    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    return [[]] + [[name] for name in sub.choices]


@pytest.mark.parametrize("command", _commands(), ids=lambda c: " ".join(c) or "multiscale")
def test_help_is_plain_text_and_names_the_environments_mpiexec(command, capsys):
    import re
    with pytest.raises(SystemExit):
        main(command + ["--help"])
    text = capsys.readouterr().out
    assert not re.search(r"``|:(func|class|mod|meth|ref|doc):|\*\*|^\s*\.\. ", text, re.M), text
    assert "mpirun -n" not in text
    if command in ([], ["run"], ["study"]):
        assert f"{Path(sys.executable).parent / 'mpiexec'} -n N multiscale" in text


def test_a_foreign_mpi_launcher_is_detected(tmp_path, capsys, monkeypatch, fake_runner):
    from multiscale.cli import launcher_problem
    path = _write(tmp_path, BLOCK.replace("../results/block_on_flat", "out"))
    monkeypatch.setenv("OMPI_COMM_WORLD_SIZE", "2")
    monkeypatch.setenv("OMPI_COMM_WORLD_RANK", "0")
    assert main(["run", path]) == 2
    err = capsys.readouterr().err
    assert "started by the Open MPI launcher for 2 processes" in err and f"{Path(sys.executable).parent / 'mpiexec'} -n 2" in err
    assert fake_runner == []
    monkeypatch.setenv("OMPI_COMM_WORLD_RANK", "1")             # the other processes stay silent
    assert main(["run", path]) == 2 and capsys.readouterr().err == ""

    class World:
        size = 2
    assert launcher_problem(World(), {"PMI_SIZE": "2"}) is None   # the right launcher: a world of 2
    assert launcher_problem(types.SimpleNamespace(size=1), {}) is None


def test_one_process_commands_under_a_launcher_speak_once(tmp_path, capsys, monkeypatch):
    """`mpiexec -n 2 multiscale check scene.toml` printed the summary twice (every process checked,
    and with --cells meshed): check, surface and info now run on the launcher's rank 0 alone, the
    others end at once with 0 (rank 0's exit code is the job's)."""
    path = _write(tmp_path, BLOCK)
    monkeypatch.setenv("PMI_SIZE", "2")
    monkeypatch.setenv("PMI_RANK", "1")
    assert main(["check", path]) == 0 and main(["check", "missing.toml"]) == 0 and main(["info"]) == 0
    assert capsys.readouterr() == ("", "")
    monkeypatch.setenv("PMI_RANK", "0")
    assert main(["check", path]) == 0 and f"{path}: OK" in capsys.readouterr().out
    assert main(["check", "missing.toml"]) == 2
    capsys.readouterr()
    # a mistake on the command line: the usage and the error once, by rank 0 (every rank printed it)
    for rank, said in (("1", ""), ("0", "error: argument --max-cells: '0': a whole number >= 1")):
        monkeypatch.setenv("PMI_RANK", rank)
        with pytest.raises(SystemExit):
            main(["run", path, "--max-cells", "0"])
        err = capsys.readouterr().err
        assert (said in err) if said else err == "", (rank, err)


def test_info_under_mpiexec_ends(tmp_path):
    """`mpiexec -n 2 multiscale info` hung: rank 0 imported DOLFINx, whose PETSc start is collective,
    while rank 1 had ended (a user trial). Every rank now loads what rank 0 loads; it speaks once."""
    pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")
    bin_ = Path(sys.executable).parent
    done = subprocess.run([str(bin_ / "mpiexec"), "-n", "2", str(bin_ / "multiscale"), "info"], capture_output=True,
                          text=True, timeout=120, start_new_session=True)
    assert done.returncode == 0 and done.stdout.count("fft ") == 1 and " petsc " in done.stdout, done


def test_a_stopped_study_names_the_command_that_goes_on(tmp_path, capsys, monkeypatch):
    """Ctrl-C of a study: the command that runs the others is this environment's (with --report);
    under a launcher's rank > 0 ``study --problems`` prints nothing (every rank printed the list: an
    MPI trial)."""
    from multiscale import cli, studies
    monkeypatch.setattr(studies, "run_studies", lambda *a, **k: (_ for _ in ()).throw(KeyboardInterrupt))
    assert main(["study", "a.toml", "--report", "rep"]) == 130
    err = capsys.readouterr().err
    assert f"interrupted: the runs that ended are recorded; {cli.COMMAND[-1]} study a.toml --report rep runs the " \
        "others" in err
    monkeypatch.setenv("PMI_SIZE", "2")
    monkeypatch.setenv("PMI_RANK", "1")
    assert main(["study", "--problems"]) == 0 and capsys.readouterr().out == ""


def test_the_time_left_leaves_out_the_first_step(monkeypatch):
    """A first step 10 s (set-up, compilation), the others 1 s: at 2 of 11 the time left is 9 s,
    not the mean rate's 49.5 s (a long-run trial's first step took 4.5 times the later ones)."""
    import io as stdio

    from mpi4py import MPI

    from multiscale import io
    clock = iter([0.0, 10.0] + [10.0 + k for k in range(1, 20) for _ in range(2)])
    monkeypatch.setattr(io._time, "perf_counter", lambda: next(clock))
    out = stdio.StringIO()
    with io.Reporter(MPI.COMM_SELF, stream=out):
        list(io.bar(range(11), "macro steps"))
    assert out.getvalue().splitlines()[1] == "  macro steps: 2/11 steps, 11.0 s, ~9.0 s left"


def test_stage_lines_one_per_stage_quiet_and_timed():
    import io as stdio

    from mpi4py import MPI

    from multiscale import io
    out = stdio.StringIO()
    with io.Reporter(MPI.COMM_SELF, stream=out) as rep:
        with io.stage("meshing"):
            with io.stage("inner"):
                pass
        with io.stage("macro steps"):
            assert list(io.bar(range(3), "macro steps")) == [0, 1, 2]
            assert list(io.bar(range(2), "zone laws", unit="batch")) == [0, 1]
    lines = out.getvalue().splitlines()
    assert lines[0].startswith("meshing: ") and lines[-1].startswith("macro steps: ") and len(lines) == 7
    assert lines[1].startswith("  macro steps: 1/3 steps, ") and lines[5].startswith("  zone laws: 2/2 batches, ")
    assert lines[1].endswith(" s left") and not lines[3].endswith(" s left")     # the time left, until the end
    assert set(rep.times) == {"meshing", "inner", "macro steps"}
    quiet = stdio.StringIO()
    with io.Reporter(MPI.COMM_SELF, quiet=True, stream=quiet):
        with io.stage("meshing"):
            list(io.bar(range(3), "steps"))
    assert quiet.getvalue() == ""
    cut = stdio.StringIO()        # a stage an error or Ctrl-C ends is not told as done (a user trial)
    with pytest.raises(KeyboardInterrupt), io.Reporter(MPI.COMM_SELF, stream=cut), io.stage("eigen solve"):
        raise KeyboardInterrupt
    assert cut.getvalue().startswith("eigen solve: stopped after ") and cut.getvalue().endswith(" s\n")


def test_times_left_read_as_durations():
    from multiscale.io import duration
    assert [duration(t) for t in (0.04, 9.94, 35.4, 250.0, 7500.0)] == ["0.0 s", "9.9 s", "35 s", "4 min 10 s",
                                                                        "2 h 05 min"]


def test_output_times_are_exact_decimals():
    from multiscale.outputs import step_time
    t = 0.0
    for _ in range(30):
        t = step_time(t, 0.4)
    assert t == 12.0 and repr(t) == "12.0"
    for steps in (3, 7, 11, 13, 999):            # each step rounded to 12 digits, t drifted: 9.99999999999 (7)
        t = 0.0
        for _ in range(steps):
            t = step_time(t, 10.0 / steps)
        assert t == 10.0, steps
    assert step_time(0.25, 1.0) == 1.25           # not a multiple of dt: t + dt


def _scene_into(tmp_path, folder):
    """The block demo writing into ``folder``."""
    from multiscale.scene import load
    return load(_write(tmp_path, BLOCK.replace("../results/block_on_flat", str(folder)), name=f"{folder.name}.toml"))


def _earlier_run(folder, files):
    """A results folder as a run leaves it: its entries (a .bp folder among them) and the record."""
    folder.mkdir()
    for name in files:
        if name.endswith(".bp"):
            (folder / name).mkdir()
            (folder / name / "data.0").write_bytes(b"x")
        else:
            (folder / name).write_bytes(b"x")
    (folder / "provenance.json").write_text(json.dumps({"status": "finished", "files": files + ["provenance.json"]}))


def test_overwrite_deletes_what_the_run_before_wrote_and_keeps_the_rest(tmp_path):
    """--overwrite: the earlier run's results go (a field file or figure the new scene would not
    write is not left beside its results), with the .part a killed run left; the user's own
    entries and names only looking like results stay, and the message says so."""
    from mpi4py import MPI

    from multiscale.io import Reporter
    pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")   # multiscale.workflows
    from multiscale.workflows.output import clear, prepare_folder
    folder = tmp_path / "out"
    _earlier_run(folder, ["pad.xdmf", "pad.h5", "modes_pad.bp", "history.h5", "wear_map_b.png"])
    (folder / "history.h5.part").write_bytes(b"x")
    (folder / "notes.txt").write_text("mine")
    (folder / "disc.xdmf").write_bytes(b"x")            # not recorded: kept
    stream = io.StringIO()
    with Reporter(MPI.COMM_SELF, stream=stream):
        prepared = prepare_folder(_scene_into(tmp_path, folder), overwrite=True, resume=False, comm=MPI.COMM_SELF)
        assert "pad.xdmf" in [p.name for p in folder.iterdir()]      # kept until the run has something to write
        assert prepared.claim() == folder
    # the new run's provenance, written at once: a run killed now is known as such, with its files
    assert sorted(p.name for p in folder.iterdir()) == ["disc.xdmf", "notes.txt", "provenance.json", "scene.toml",
                                                        "scene_resolved.toml"]
    record = json.loads((folder / "provenance.json").read_text())
    assert record["status"] == "running (or killed: no end was recorded)" and "block.xdmf" in record["files"]
    assert f"--overwrite: 2 entries of {folder} stay (not written by the run before): disc.xdmf, notes.txt" \
        in stream.getvalue()
    (folder / "provenance.json").unlink()
    stream = io.StringIO()
    with Reporter(MPI.COMM_SELF, stream=stream):
        clear(folder, ["notes.txt"])                    # one entry: "stays" (it said "1 entry ... stay")
    assert f"--overwrite: 1 entry of {folder} stays (no record of a run" in stream.getvalue()



def test_overwrite_refuses_the_users_own_files_named_as_results(tmp_path, capsys):
    """A folder holding the user's own scene.toml and history.h5, which no run recorded writing:
    --overwrite refuses before any work and check says so (before: both were replaced, the run saying
    that the user's entries stay; a user trial); with a run's record of them, they go as before."""
    from mpi4py import MPI

    from multiscale.errors import SceneError
    pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")   # multiscale.workflows
    from multiscale.workflows.output import prepare_folder
    folder = tmp_path / "out"
    folder.mkdir()
    (folder / "scene.toml").write_text("# mine")
    (folder / "history.h5").write_text("mine")
    scene = _scene_into(tmp_path, folder)
    for overwrite in (True, False):         # without --overwrite too (before: "already holds results")
        with pytest.raises(SceneError, match=r'holds history.h5, scene.toml, named as this run\'s results but not '
                                             r"written by a run .*: a run would write over them, --overwrite too"):
            prepare_folder(scene, overwrite=overwrite, resume=False, comm=MPI.COMM_SELF)
    (folder / "notes.txt").write_text("mine")
    (folder / "history.h5").unlink()
    (folder / "scene.toml").unlink()
    with pytest.raises(SceneError, match=r"already holds 1 entry that no run wrote \(notes.txt\); use --overwrite to "
                                         r"write beside them \(it deletes only what a run wrote"):
        prepare_folder(scene, overwrite=False, resume=False, comm=MPI.COMM_SELF)
    (folder / "notes.txt").unlink()
    (folder / "scene.toml").write_text("# mine")
    (folder / "history.h5").write_text("mine")
    assert (folder / "scene.toml").read_text() == "# mine" and (folder / "history.h5").read_text() == "mine"
    assert main(["check", str(scene.source)]) == 0
    assert "it refuses to write over history.h5, scene.toml, not written by a run" in capsys.readouterr().out
    (folder / "provenance.json").write_text(json.dumps({"files": ["history.h5", "scene.toml"]}))
    prepare_folder(scene, overwrite=True, resume=False, comm=MPI.COMM_SELF).claim()
    assert not (folder / "history.h5").exists()


def test_a_provenance_write_that_fails_midway_leaves_the_earlier_record(tmp_path, monkeypatch):
    """The record is replaced whole: a write of provenance.json that fails after half its text (a
    full disk; a kill leaves its .part, which --overwrite clears) leaves the earlier record as it
    was, readable with its files, and no file beside it (before: the record was written in place
    and left truncated, so results_of no longer knew the folder's results)."""
    import errno

    from multiscale import provenance
    folder = tmp_path / "out"
    scene = _scene_into(tmp_path, folder)
    folder.mkdir()
    provenance.write(folder, scene, ranks=1, started=provenance.now(), stages={}, wall_time=0.0,
                     status=provenance.RUNNING)
    before = sorted(folder.iterdir())
    earlier = (folder / "provenance.json").read_text()
    written = Path.write_text

    def half_then_full(path, text, *args, **kwargs):
        if path.name.startswith("provenance.json"):
            written(path, text[:len(text) // 2], *args, **kwargs)
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return written(path, text, *args, **kwargs)
    monkeypatch.setattr(Path, "write_text", half_then_full)
    with pytest.raises(OSError, match="No space left on device"):
        provenance.write(folder, scene, ranks=1, started=provenance.now(), stages={"meshing": 1.0}, wall_time=1.0)
    assert (folder / "provenance.json").read_text() == earlier and sorted(folder.iterdir()) == before
    assert "block.xdmf" in provenance.results_of(folder)


def test_a_quiet_run_still_prints_what_its_results_leave_out(tmp_path, capsys):
    """run --quiet prints the run's warnings as it does the scene's (before: the scene's only; the
    small-strain warning of a 200 MPa load on the 4 GPa block was in provenance.json alone)."""
    pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")
    folder = tmp_path / "out"
    path = _write(tmp_path, BLOCK.replace("../results/block_on_flat", str(folder)).replace('"1 MPa"', '"200 MPa"'))
    assert main(["run", path, "--quiet"]) == 0
    err = capsys.readouterr().err
    record = json.loads((folder / "provenance.json").read_text())
    assert [w for w in record["warnings"] if "softer side's E" in w] == \
        [line.removeprefix("warning: ") for line in err.splitlines() if "softer side's E" in line] != []


def test_a_load_beyond_small_strains_is_said_at_the_first_contact_solve(tmp_path, capsys):
    """A run with steps to go says the small-strain warning of its first contact solve at once (before:
    only after the whole run; a 20 um pin under 200 N ran to its end first), and the run's at its
    end, which the record holds; a run without steps says the run's only (above)."""
    pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")
    folder = tmp_path / "out"
    text = THERMAL.replace("../results/block_on_flat", str(folder)).replace('"1 MPa"', '"200 MPa"')
    assert main(["run", _write(tmp_path, text), "--quiet"]) == 0
    said = [line.removeprefix("warning: ") for line in capsys.readouterr().err.splitlines() if "softer side's E" in line]
    record = json.loads((folder / "provenance.json").read_text())
    assert len(said) == 2 and said[0].startswith("at the first contact solve, the contact pressure reached 2e+08 Pa")
    assert said[0].endswith("the run goes on (Ctrl-C stops it after a step, with its results written)")
    assert [w for w in record["warnings"] if "softer side's E" in w] == said[1:]


def test_overwrite_keeps_the_earlier_results_when_the_run_fails_before_writing(tmp_path, capsys):
    """run --overwrite of a scene refused at meshing (--max-cells): the earlier run's results and
    its provenance stay as they were (before: deleted, then the refusal); the same run that meshes
    replaces them."""
    pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")
    folder = tmp_path / "out"
    _earlier_run(folder, ["block.xdmf", "block.h5", "history.h5"])
    before = {p.name: p.read_bytes() for p in folder.iterdir()}
    path = _write(tmp_path, BLOCK.replace("../results/block_on_flat", str(folder)))
    assert main(["run", path, "--overwrite", "--quiet", "--max-cells", "50"]) == 2
    assert "error: geometry.max_cells = 50" in capsys.readouterr().err
    assert {p.name: p.read_bytes() for p in folder.iterdir()} == before
    assert main(["run", path, "--overwrite", "--quiet"]) == 0
    record = json.loads((folder / "provenance.json").read_text())
    # a fresh folder: the refused run leaves nothing that makes the next run need --overwrite
    fresh = _write(tmp_path, BLOCK.replace("../results/block_on_flat", str(tmp_path / "fresh")), name="fresh.toml")
    assert main(["run", fresh, "--quiet", "--max-cells", "50"]) == 2
    assert list((tmp_path / "fresh").iterdir()) == [] and main(["run", fresh, "--quiet"]) == 0
    assert record["status"] == "finished" and (folder / "block.xdmf").read_bytes() != b"x"


def test_overwrite_without_a_record_deletes_nothing_and_resume_never_does(tmp_path, capsys):
    """Only what a run recorded writing is deleted; a record that cannot be read is said so (a user
    trial's corrupted provenance.json: --overwrite called the results "not written by a run", and
    --resume dropped the earlier parts' record without a word)."""
    from mpi4py import MPI

    from multiscale.errors import SceneError
    from multiscale.io import Reporter
    pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")   # multiscale.workflows
    from multiscale.workflows.output import prepare_folder
    folder = tmp_path / "out"
    _earlier_run(folder, ["pad.xdmf"])
    (folder / "provenance.json").write_text(json.dumps({"files": ["../x", "..", "pad.xdmf"]}))
    (tmp_path / "x").write_text("outside")
    scene = _scene_into(tmp_path, folder)
    prepare_folder(scene, overwrite=False, resume=True, comm=MPI.COMM_SELF)
    assert sorted(p.name for p in folder.iterdir()) == ["pad.xdmf", "provenance.json"]   # --resume: as it was
    prepare_folder(scene, overwrite=True, resume=False, comm=MPI.COMM_SELF).claim()
    assert not (folder / "pad.xdmf").exists() and (tmp_path / "x").exists()     # only entries of the folder
    _earlier_run(tmp_path / "other", ["a.csv"])
    (tmp_path / "other" / "provenance.json").write_text("{not json")      # another program's record: not replaced
    with pytest.raises(SceneError, match=r"holds provenance.json, named as this run's results; \S+/other/provenance"
                                         r"\.json cannot be read \(Expecting property name .*\): which of them a run "
                                         r"wrote is unknown: a run would write over them, --overwrite too"):
        prepare_folder(_scene_into(tmp_path, tmp_path / "other"), overwrite=True, resume=False, comm=MPI.COMM_SELF)
    capsys.readouterr()
    prepare_folder(_scene_into(tmp_path, tmp_path / "other"), overwrite=False, resume=True, comm=MPI.COMM_SELF)
    err = capsys.readouterr().err
    assert "provenance.json cannot be read (Expecting property name" in err
    assert "the record of the run's earlier parts is lost; the new provenance.json records the resumed part only" in err
    (tmp_path / "other" / "provenance.json").unlink()
    stream = io.StringIO()
    with Reporter(MPI.COMM_SELF, stream=stream):
        prepare_folder(_scene_into(tmp_path, tmp_path / "other"), overwrite=True, resume=False,
                       comm=MPI.COMM_SELF).claim()
    assert "a.csv" in [p.name for p in (tmp_path / "other").iterdir()]
    assert "stays (no record of a run (provenance.json with its files)): a.csv" in stream.getvalue()


def test_a_scene_in_its_own_output_folder_is_not_a_result(tmp_path, capsys):
    """output.folder = "." beside the scene (and its measured surface): the scene and the files it
    reads are not earlier results (a first run was refused for them), and --overwrite never deletes
    them (it deleted the scene file itself, recorded as the copy scene.toml, and wrote the resolved
    scene in its place)."""
    from mpi4py import MPI

    from multiscale.errors import SceneError
    from multiscale.scene import load
    pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")   # multiscale.workflows
    from multiscale.workflows.output import prepare_folder
    text = BLOCK.replace("../results/block_on_flat", ".") + "\n# the user's comment\n"
    path = _write(tmp_path, text)
    assert main(["check", path]) == 0 and "already holds" not in capsys.readouterr().out
    scene = load(path)
    assert scene.inputs == {Path(path).resolve()} and scene.earlier_results() == []
    prepare_folder(scene, overwrite=False, resume=False, comm=MPI.COMM_SELF)     # refused before
    for _ in range(2):
        prepare_folder(scene, overwrite=True, resume=False, comm=MPI.COMM_SELF).claim()
        assert Path(path).read_text() == text
    assert sorted(p.name for p in tmp_path.iterdir()) == ["provenance.json", "scene.toml", "scene_resolved.toml"]
    # another scene run there with --overwrite deleted that scene file (recorded as the copy scene.toml)
    # and wrote its own in its place (an adversarial trial): refused, the file kept
    other = load(_write(tmp_path, text.replace("# the user's comment", "# another scene"), "other.toml"))
    with pytest.raises(SceneError, match=r'holds scene.toml, an input of the run before \(a scene run in its own '
                                         r"folder\); this run would write over it: choose another folder"):
        prepare_folder(other, overwrite=True, resume=False, comm=MPI.COMM_SELF)
    assert Path(path).read_text() == text


@pytest.mark.parametrize("law, line", [
    ('friction_curve = [["0 m/s", 0.6], ["1 m/s", 0.2]]', "mu(slip speed) from friction_curve: 0.6 at 0 m/s, 0.2 at 1 m/s"),
    ('[loading.stribeck]\nstatic = 0.5\nkinetic = 0.3\nspeed = "0.5 m/s"',
     "Stribeck mu(v) = 0.3 + (0.5 - 0.3) exp(-(v / 0.5 m/s)^1)")])
def test_check_summarises_a_friction_law_falling_with_speed(tmp_path, capsys, law, line):
    """check of a squeal scene with mu(v): the summary names the law (before: a TypeError
    traceback formatting the absent constant mu; found by an adversarial test)."""
    text = (Path(__file__).resolve().parents[1] / "demos" / "brake_squeal.toml").read_text()
    assert "friction = 0.4\n" in text
    text = text.replace("friction = 0.4\n", law.split("\n")[0] + "\n" if law.startswith("friction_curve") else "")
    if law.startswith("[loading.stribeck]"):
        text += "\n" + law + "\n"
    assert main(["check", _write(tmp_path, text.replace("../results/", str(tmp_path) + "/"))]) == 0
    assert line in capsys.readouterr().out


def test_ctrl_c_in_a_command_without_its_own_words_is_one_line(monkeypatch, capsys):
    """Ctrl-C during `multiscale check --cells` (gmsh trials) printed a KeyboardInterrupt traceback
    (a user trial); every command now ends with one line and exit code 130."""
    from multiscale import cli

    def meshing(args):
        raise KeyboardInterrupt
    monkeypatch.setattr(cli, "_check", meshing)
    assert main(["check", "scene.toml", "--cells"]) == 130
    assert capsys.readouterr().err == "interrupted: multiscale check\n"


def test_the_command_a_hint_repeats_is_the_one_launched():
    """`python -m multiscale` from a checkout on PYTHONPATH: the resume hint after a Ctrl-C named the
    environment's console script, which runs the installed copy (a rank-consistency audit)."""
    import multiscale
    main_py = str(Path(multiscale.__file__).with_name("__main__.py"))
    python = os.path.abspath(sys.executable)     # the child's, also where pytest was started as ../venv/bin/python
    for argv0, expected in ((main_py, [python, "-m", "multiscale"]),
                            (str(Path(python).with_name("multiscale")), [str(Path(python).with_name("multiscale"))])):
        code = f"import sys; sys.argv = [{argv0!r}]; import multiscale.cli as c; print(c.COMMAND)"
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
        assert out.strip() == str(expected)

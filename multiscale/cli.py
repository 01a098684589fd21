"""Command line: ``multiscale <command>``. User errors print one line each and exit 2.

Help texts are plain text (no reST markup); parallel runs name the ``mpiexec`` of the environment
that holds multiscale (``.venv/bin/mpiexec``), and a run started by another MPI's launcher is
stopped with a message saying so (``launcher_problem``).
"""
from __future__ import annotations

import argparse
import contextlib
import dataclasses
import importlib.util
import os
import shlex
import sys
import tomllib
import warnings
from pathlib import Path

from mpi4py import MPI

from multiscale import __version__
from multiscale.errors import InputError, MultiscaleError, OutputError, SceneError, behind
from multiscale.geometry import too_many_cells
from multiscale.io import CtrlCWatch, Outliving, abort, ended_together, reason
from multiscale.memory import SPREAD, memory_available, memory_limit, remedy
from multiscale.micro.outliers import DESPIKE
from multiscale.micro.reading import COMMAND_LINE, TopographyWarning, formats, read_topography
from multiscale.micro.spectrum import statistics_memory, surface_statistics
from multiscale.micro.topography import DETREND, MAX_UNDEFINED, condition
from multiscale.mode_pairs import mirrored, pair, read_modes, report, write_pairs
from multiscale.outputs import CHECKPOINT, checkpointed, folder_problem, plan
from multiscale.outputs import summary as plan_summary
from multiscale.provenance import finished, versions
from multiscale.scene import load
from multiscale.scene_plain import pixel_problem, plain
from multiscale.scene_summary import cells_line, memory_line, modes_problem, reference, summary, table_reference
from multiscale.units import UnitError, to_si

DESCRIPTION = """Multi-scale thermo-mechanical simulation of frictional sliding contacts (disc brakes,
pin-on-disc): validate a scene file (check), run it (run), sweep parameters (study), analyse a
measured topography (surface), print the versions (info)."""
INTERRUPTED = 130        # exit code after Ctrl-C (128 + SIGINT, as shells report it)
MPIEXEC = f"{Path(sys.executable).parent / 'mpiexec'}"
# this environment's (also where it is not on PATH), or its interpreter's ``-m multiscale`` as launched
# (a checkout on PYTHONPATH: the console script runs the installed copy)
COMMAND = ([sys.executable, "-m", "multiscale"] if Path(sys.argv[0]).parts[-2:] == ("multiscale", "__main__.py")
           else [f"{Path(sys.executable).parent / 'multiscale'}"])
EPILOG = f"""Parallel runs: {MPIEXEC} -n N multiscale run scene.toml
Use the mpiexec of this environment: the launcher of another MPI (a system mpirun or mpiexec)
starts N separate serial runs, or stops with a PMI error."""


def _info(args) -> int:
    """The versions a run's provenance.json records (``provenance.versions``; a user trial found
    PETSc, SLEPc, MPI, gmsh and Python missing here) and the FFT backend."""
    # local: numba, scipy, pyfftw and DOLFINx take seconds to load, which `check` must not pay
    from multiscale.micro.fft import get_threads, pyfftw
    try:
        import multiscale.macro  # noqa: F401  (DOLFINx is optional; this loads its prerequisites first)
        import dolfinx  # noqa: F401
    except ImportError:
        print("dolfinx not installed (macro models unavailable)")
    print("  ".join(f"{name} {version}" for name, version in versions().items()))
    print(f"fft {'pyfftw' if pyfftw else 'scipy'} ({get_threads()} thread(s))")
    return 0


def _check(args) -> int:
    """Validate scene files: a short summary for a good one, every problem of a bad one."""
    if args.keys is not None:
        if args.keys.lower().endswith(".toml"):     # check --keys SCENE: the format, then the scene
            args.scenes, args.keys = [args.keys, *args.scenes], ""
        print("\n".join(table_reference(args.keys) if args.keys else reference()))
    elif not args.scenes:
        raise MultiscaleError("multiscale check: give scene file(s), or --keys for the scene format")
    failed = 0
    for path in args.scenes:
        try:
            scene = load(path, overrides=_overrides(args.settings))
        except SceneError as exc:
            for line in exc.problems:
                print(f"error: {line}", file=sys.stderr)
            n = len(exc.problems)
            print(f"{path}: {n} problem{'s' if n > 1 else ''}", file=sys.stderr)
            failed += 1
            continue
        print("\n".join(summary(scene) + plan_summary(plan(scene))))
        if importlib.util.find_spec("dolfinx") is None:         # a micro-only install (said OK alone: a trial)
            print("warning: multiscale run of this scene needs DOLFINx, not installed here: pip install -e "
                  "'.[fem]'", file=sys.stderr)
        unwritable = folder_problem(scene.output.folder)          # what run would stop at
        if unwritable is not None:
            print(f'error: output.folder = "{scene.output.folder}": {unwritable}', file=sys.stderr)
            print(f"{path}: 1 problem", file=sys.stderr)
            failed += 1
            continue
        if args.cells:
            try:                        # (meshes: a part nothing holds is what run refuses at meshing)
                line, estimate = cells_line(scene)
            except InputError as exc:
                print(f"error: {exc}\n{path}: 1 problem", file=sys.stderr)
                failed += 1
                continue
            if (why := modes_problem(scene, estimate)) is not None:     # what run refuses after its preload
                print(f"error: {why}\n{path}: 1 problem", file=sys.stderr)
                failed += 1
                continue
            need, free = memory_line(scene, estimate), memory_available()
            print(f"{line}\n{need[0]}")
            if free is not None and SPREAD * need[1] > free:    # (a ~1M-dof squeal was "OK": a user trial)
                print(f"warning: up to {SPREAD:g} times that is near or above the {free / 1e9:.2g} GB this machine has free: "
                      f"{remedy(scene.has('stability'))}", file=sys.stderr)
            if estimate.cells > scene.geometry.max_cells:      # what run would refuse
                print(f"error: {too_many_cells(estimate, scene.geometry.max_cells)}", file=sys.stderr)
                print(f"{path}: 1 problem", file=sys.stderr)
                failed += 1
                continue
        print(f"{path}: OK")
    return 2 if failed else 0


# environment variables that MPI launchers set: (size, rank)
LAUNCHERS = {"Open MPI": ("OMPI_COMM_WORLD_SIZE", "OMPI_COMM_WORLD_RANK"),
             "MPICH/Intel MPI (PMI)": ("PMI_SIZE", "PMI_RANK"), "PMIx": ("PMIX_SIZE", "PMIX_RANK"),
             "MVAPICH": ("MV2_COMM_WORLD_SIZE", "MV2_COMM_WORLD_RANK"),
             "Slurm srun": ("SLURM_STEP_NUM_TASKS", "SLURM_PROCID")}


SERIAL = ("info", "check", "surface", "modes")    # commands of one process: under a launcher its rank 0 alone runs them
LONG = ("run", "study")     # commands whose results outlive their console (``io.Outliving``)


def launched_rank(environ=None) -> int:
    """The rank a launcher gave this process, read from its environment (``LAUNCHERS``) without
    starting MPI; 0 without a launcher."""
    environ = os.environ if environ is None else environ
    for _, rank_var in LAUNCHERS.values():
        if environ.get(rank_var, "").isdigit():
            return int(environ[rank_var])
    return 0


def launcher_problem(comm, environ=None) -> tuple[str, bool] | None:
    """(message, print it) when a launcher started several processes that all see an MPI world
    of size 1: ``mpiexec``/``mpirun`` of another MPI than the one mpi4py was built with. ``print
    it`` is true on the launcher's rank 0 only (every process thinks it is rank 0 of 1)."""
    environ = os.environ if environ is None else environ
    if comm.size != 1:
        return None
    for name, (size_var, rank_var) in LAUNCHERS.items():
        try:
            size = int(environ.get(size_var, "1"))
        except ValueError:
            continue
        if size > 1:
            mpiexec = Path(sys.executable).parent / "mpiexec"
            message = (f"started by the {name} launcher for {size} processes ({size_var}={size}), but every process "
                       f"sees an MPI world of 1: that launcher belongs to another MPI than the one multiscale "
                       f"uses. Start parallel runs with the mpiexec of this environment: {mpiexec} -n {size} "
                       f"multiscale ...")
            return message, environ.get(rank_var, "0") == "0"
    return None


def _world():
    """MPI.COMM_WORLD, or None without mpi4py."""
    try:
        from mpi4py import MPI   # initialises MPI: only `run` needs it
    except ImportError:
        return None
    return MPI.COMM_WORLD


def _run(args) -> int:
    """Validate the scene and hand it to its workflow (``multiscale.workflows.run``).

    Under ``mpiexec`` every rank runs this; user errors are raised on every rank (scene validation
    is deterministic, the output folder is judged by rank 0 for all, solver failures are decided
    collectively) and printed by rank 0. An error met by some ranks only (the others wait in a
    collective operation) is printed by the rank that met it, which then aborts the job: nothing
    hangs. Ctrl-C ends every rank with exit code 130 and one line (``multiscale.io.CtrlCWatch``)."""
    comm = _world()
    rank = comm.rank if comm is not None else 0
    foreign = launcher_problem(comm) if comm is not None else None
    if foreign is not None:
        message, shown = foreign
        if shown:
            print(f"error: {message}", file=sys.stderr)
        return 2
    scene = None
    watch = None if comm is None else CtrlCWatch(comm, lambda: f"interrupted: {_kept(scene, args, comm.size)}",
                                                    INTERRUPTED)
    with watch or contextlib.nullcontext():     # a Ctrl-C that a rank's main thread cannot meet
        try:
            scene = load(args.scene, overrides=_overrides(args.settings))
            if args.max_cells is not None:
                scene = dataclasses.replace(scene, geometry=dataclasses.replace(scene.geometry,
                                                                                max_cells=args.max_cells))
            try:
                from multiscale.workflows import run   # DOLFINx: optional ([fem] extra), slow to import
            except ModuleNotFoundError as exc:
                raise MultiscaleError(f"multiscale run needs DOLFINx and the macro workflows ({exc}); install "
                                      "them with pip install -e '.[fem]'") from None
            run(scene, overwrite=args.overwrite, resume=args.resume, verbose=not args.quiet)   # warns first
        except MultiscaleError as exc:
            if comm is not None and not ended_together(comm):
                print(f"error (rank {rank} of {comm.size}): {exc}", file=sys.stderr)
                abort(comm, 2)
            if rank == 0:
                raise
            return 2
        except KeyboardInterrupt as exc:       # Ctrl-C (mpiexec hands SIGINT to every rank)
            sys.unraisablehook = lambda unraisable: None   # finalizers of what the interrupt left half-built
            line = f"interrupted {exc}".strip() + f": {_kept(scene, args, 1 if comm is None else comm.size)}"
            if watch is None:
                print(line, file=sys.stderr, flush=True)
            else:
                watch.end(line)                # every rank, or one that ends the job: no rank left waiting
            return INTERRUPTED
    return 0


def _command(ranks: int, *words: str) -> str:
    """This environment's multiscale with ``words``, under its mpiexec for ``ranks`` > 1: the command
    a hint repeats (a copy of the bare name failed where the environment was not activated)."""
    return shlex.join([*([MPIEXEC, "-n", str(ranks)] if ranks > 1 else []), *COMMAND, *words])


def _kept(scene, args, ranks: int = 1) -> str:
    """What a run interrupted by Ctrl-C leaves (``scene``: None if it was still being read), and the
    command that goes on (``_command``, with the scene's absolute path: a job script's next step may
    start elsewhere); --resume is advised
    only with a checkpoint (before its first macro step ended it refused to resume), --overwrite
    when the folder holds files (a user trial was told to start again and refused)."""
    if scene is None:
        return "nothing was written"
    command = _command(ranks, "run", os.path.abspath(args.scene),                    # (from any folder)
                       *(f"--set={k}={text}" for k, _, text in args.settings))
    folder = Path(scene.output.folder)
    written = folder.is_dir() and any(folder.iterdir())
    again = f"{command}{' --overwrite' if written else ''} starts again"
    if checkpointed(scene) and not (folder / CHECKPOINT).is_file():
        return f"no macro step ended, there is nothing to resume; {again}"
    if not written:
        return f"nothing was written; {again}"
    if args.overwrite and finished(folder):     # stopped before it replaced them (it advised --resume: an MPI trial)
        return f"the earlier results in {folder} stay as they were; {again}"
    how = f"{command} --resume continues from the last finished step" if checkpointed(scene) else again
    return f"what was written stays in {folder} (its provenance.json says so); {how}"


def _study(args) -> int:
    """Run parametric studies; every problem of every study file is reported before anything runs."""
    from multiscale.studies import problems_text, run_studies  # local: loads the numba micro modules
    if args.problems:
        if launched_rank() == 0:          # once under mpiexec (every rank printed it: an MPI trial)
            print(problems_text())
        return 0
    if not args.studies:
        raise MultiscaleError("multiscale study: give study file(s), or --problems for the problems and their keys")
    comm = _world()
    foreign = launcher_problem(comm) if comm is not None else None
    if foreign is not None:
        if foreign[1]:
            print(f"error: {foreign[0]}", file=sys.stderr)
        return 2
    command = " ".join(["multiscale study", *args.studies] + (["--report", args.report] if args.report else []))
    try:
        failed = run_studies(args.studies, rerun_failed=args.rerun_failed, report_folder=args.report,
                             processes=args.processes, command=command)
    except KeyboardInterrupt:                # Ctrl-C: the runs that ended are recorded, the others stopped
        if comm is None or comm.rank == 0:
            again = _command(comm.size if comm is not None else 1, "study", *args.studies,   # (mpiexec was
                             *(["--report", args.report] if args.report else []))                 # left out: a trial)
            print(f"interrupted: the runs that ended are recorded; {again} runs the others", file=sys.stderr,
                  flush=True)
        return INTERRUPTED
    except MultiscaleError:                  # raised on every rank (running: collective): one speaks
        if comm is None or comm.rank == 0:
            raise
        return 2
    except OSError as exc:                   # a results or report folder that cannot be written
        raise OutputError(f"cannot write {exc.filename}: {reason(exc)}") from None
    return 1 if failed else 0


def _count(text: str) -> int:
    """A positive whole number of the command line ("2000000" or "2e6")."""
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not (value >= 1 and value == int(value)):
        raise argparse.ArgumentTypeError(f"{text!r}: a whole number >= 1")
    return int(value)


def _overrides(settings: list) -> dict:
    """The scene keys of the ``--set`` options (``_setting``), the last of a key given twice, which is
    said (once under mpiexec; it was kept silently: a user trial)."""
    keys = [k for k, _, _ in settings]
    for key in dict.fromkeys(k for k in keys if keys.count(k) > 1):
        if launched_rank() == 0:
            given = ", ".join(text for k, _, text in settings if k == key)
            print(f"warning: --set {key} given {keys.count(key)} times ({given}): the last is taken", file=sys.stderr)
    return {k: v for k, v, _ in settings}


def _setting(text: str) -> tuple[str, object, str]:
    """A ``--set KEY=VALUE`` of the command line: the dotted scene key, the value as TOML reads it
    (40, 0.3, false, [4, 4], "300 N") or else the text itself (300 N, runs/a), and the text."""
    key, equals, value = text.partition("=")
    if not equals or not key.strip() or not value.strip():
        lack = "no value after '=' (a key cannot be removed: one given replaces the file's alternatives to it); " \
            if equals and key.strip() else ""          # (it said only KEY=VALUE: an MPI trial)
        raise argparse.ArgumentTypeError(f"{text!r}: {lack}KEY=VALUE, a scene key and its value, e.g. time.steps=40 "
                                         'or "loading.normal_force=300 N"')
    try:
        read = tomllib.loads(f"value = {value}")["value"]
    except tomllib.TOMLDecodeError as exc:
        if value.strip()[:1] in "[{\"'":            # meant as TOML: "[2,2" is an unclosed array, not a text
            raise argparse.ArgumentTypeError(f"{text!r}: {value.strip()} is not a TOML value ({exc})") from None
        read = value.strip()
    return key.strip(), read, value


def _number_or_text(text: str):
    """A command-line value as a number if it is one (then SI), else the text."""
    try:
        return float(text)
    except ValueError:
        return text


def _length(option: str, text: str | None, unit_name: bool = False) -> float | None:
    """A length option ("0.8 mm", or a number in metres; with ``unit_name`` also a unit's name,
    "um", as in a scene's ``roughness.height_unit``) in metres."""
    if text is None:
        return None
    value = _number_or_text(text)
    try:
        return to_si(value, "length")
    except UnitError as exc:
        if unit_name and isinstance(value, str):
            try:
                return to_si(f"1 {value}", "length")
            except UnitError:
                pass
        raise InputError(option, text, str(exc)) from None


def surface_memory(shape) -> float:
    """Peak memory [bytes] of ``multiscale surface``'s analysis of a map of ``shape`` (ny, nx): its
    statistics and the two height maps held meanwhile (the measurement and the conditioned surface,
    8 bytes a point each); 41 bytes a point traced on white noise from 512 x 640 to 1000² points."""
    return statistics_memory(shape) + 16.0 * shape[0] * shape[1]


def _modes(args) -> int:
    """Pair the modes of two squeal runs by MAC: a table, and the matrix as CSV or a figure."""
    from multiscale.plots import figure_problem, path_problem   # local: as the figures themselves, where drawn
    if args.csv and (why := path_problem(Path(args.csv))):
        raise InputError("--csv", args.csv, f"cannot write the table there: {why}")   # (after the work: a user trial)
    if args.figure and (why := figure_problem(Path(args.figure))):
        raise InputError("--figure", args.figure, f"cannot write the figure there: {why}")
    b = read_modes(args.runs[1])
    pairs = pair(read_modes(args.runs[0]), mirrored(b, args.mirror) if args.mirror else b, transfer=bool(args.mirror))
    print("\n".join(report(pairs)))
    if args.csv:
        print(f"MAC matrix: {write_pairs(pairs, args.csv)}")
    if args.figure:
        from multiscale.plots.squeal import plot_mac    # local: matplotlib only when a figure is drawn
        axes = (f"mode of B: {args.runs[1]}", f"mode of A: {args.runs[0]}")
        print(f"figure: {plot_mac(pairs.mac, 'MAC', args.figure, axes)}")
    return 0


def _surface(args) -> int:
    """Read, condition and analyse a measured topography: the steps, the statistics, a figure."""
    if args.formats:
        print("\n".join(formats()))
        return 0
    if not args.file:
        raise MultiscaleError("multiscale surface: give a topography file, or --formats for the formats it reads")
    pixel, cutoff = _length("--pixel-size", args.pixel_size), _length("--cutoff", args.cutoff)
    if pixel is not None and (problem := pixel_problem(pixel, _number_or_text(args.pixel_size))):
        raise InputError("--pixel-size", args.pixel_size, problem)
    unit = _length("--height-unit", args.height_unit, unit_name=True)
    figure = None if args.figure in (None, "none") else Path(args.figure)
    if figure is not None:
        from multiscale.plots import figure_problem   # local: as the figures themselves, only where drawn
        if why := figure_problem(figure):     # said before the analysis (minutes on a large file), not after
            raise InputError("--figure", args.figure, f"cannot write the figure there: {why}")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TopographyWarning)      # the report's "warning:" lines say them
        measurement = read_topography(args.file, args.channel, pixel_size=pixel, height_unit=unit, prefix=COMMAND_LINE)
        need, free = surface_memory(measurement.shape), memory_available()
        if free is not None and need > free:      # the OOM killer ended it, without a word (8000² points)
            raise InputError("FILE", measurement.path.name, f"{measurement.shape[1]} x {measurement.shape[0]} "
                             f"points: their statistics need about {need / 1e9:.2g} GB of memory, {free / 1e9:.2g} GB "
                             "are available: crop or coarsen the map first")
        if cutoff is not None and plain(_number_or_text(args.cutoff)) and cutoff > min(measurement.size):
            (Lx, Ly), unit = measurement.size, ("mm", 1e3) if min(measurement.size) >= 1e-3 else ("um", 1e6)
            fits = 2 * max(measurement.dx, measurement.dy) <= 1e-3 * cutoff <= min(measurement.size)
            hint = f'did you mean "{args.cutoff} mm"?' if fits else "give a unit"   # (suggested mm beyond the map)
            raise InputError("--cutoff", args.cutoff, f"{cutoff:g} m, longer than the measurement ({Lx * unit[1]:.4g} x "
                             f"{Ly * unit[1]:.4g} {unit[0]}); plain numbers are metres: {hint} "
                             f'("{args.cutoff} m" filters at {cutoff:g} m anyway)')   # ISO's λc are in mm: "--cutoff
            #                                                0.8" was 0.8 m, silently; "0.8 m" is taken as meant
        done = condition(measurement, args.detrend, cutoff, args.max_undefined, prefix=COMMAND_LINE,
                         despike=args.despike)      # errors and notes name the options as given here
    stats = surface_statistics(done.surface)
    print("\n".join(done.report))
    print(f"statistics of the {'roughness' if done.waviness is not None else 'surface'}:")
    print("\n".join(stats.table(filtered=done.waviness is not None)))
    if figure is None:        # a figure only where asked: nothing lands in the working folder
        if args.figure is None:
            print("figure: none written (--figure PATH.png draws the height map and the PSD with its fit)")
    else:
        from multiscale.plots.surface import surface_figure   # local: matplotlib only when a figure is drawn
        try:
            surface_figure(done.surface, stats, figure, f"{Path(args.file).name}, channel {measurement.channel}",
                           waviness=done.waviness)
        except (OSError, ValueError) as exc:   # a folder it may not write into, a full disk
            raise InputError("--figure", str(figure), f"cannot write the figure there: {exc}") from None
        print(f"figure: {figure}")
    return 0


# --set KEY=VALUE of check and run: scene keys over the file's (a study's overrides, by hand)
SET = dict(type=_setting, action="append", default=[], dest="settings", metavar="KEY=VALUE",
           help='a scene key\'s value over the file\'s, repeatable: time.steps=40, "loading.normal_force=300 N", '
                "micro.zones=[4,4], output.folder=runs/a (a value TOML does not read is text; paths from the "
                "scene file's folder; loading.pressure replaces the file's normal_force, and so on for every "
                "pair of alternatives); provenance.json records them")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="multiscale", description=DESCRIPTION, epilog=EPILOG,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=f"multiscale {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    sub.add_parser("info", help="versions and settings", description="Print the versions of multiscale and "
                   "of the libraries it uses.").set_defaults(func=_info)
    check = sub.add_parser("check", help="validate scene files: every problem at once, or a summary",
                           description="Validate scene files without running them: every problem at once, "
                           "or a summary of what a run computes and the files it writes.")
    check.add_argument("scenes", nargs="*", metavar="SCENE", help="scene TOML file(s)")
    check.add_argument("--keys", nargs="?", const="", metavar="TABLE", help="print the scene format: every "
                       "table and key; with a TABLE (e.g. loading, materials), that table with what its keys do")
    check.add_argument("--cells", action="store_true", help="estimate the mesh's cell count and memory (trial "
                       "meshes, seconds) and check that the supports hold every part, as run does at meshing")
    check.add_argument("--set", **SET)
    check.set_defaults(func=_check)
    run = sub.add_parser("run", help=f"run a scene (in parallel: {MPIEXEC} -n N multiscale run SCENE)",
                         description="Run a scene: its effects decide the analysis (transient, multiscale loop "
                         "or squeal); the results, their provenance and a ParaView script go to output.folder. "
                         "One line per stage on the terminal.", epilog=EPILOG,
                         formatter_class=argparse.RawDescriptionHelpFormatter)
    run.add_argument("scene", metavar="SCENE", help="scene TOML file")
    again = run.add_mutually_exclusive_group()
    again.add_argument("--overwrite", action="store_true",
                       help="delete the results of the run before (the entries its provenance.json lists) and run again")
    again.add_argument("--resume", action="store_true", help="continue from the last checkpoint in the output folder "
                       "(runs with macro steps write one after each: the multiscale loop and the thermal runs; the "
                       "squeal analysis and a single contact solve refuse it: run them again with --overwrite)")
    run.add_argument("--set", **SET)
    run.add_argument("--quiet", action="store_true", help="no stage lines or summary (warnings and errors only)")
    run.add_argument("--max-cells", type=_count, metavar="N", help="largest mesh (cells) the run may build; "
                                                                   "overrides geometry.max_cells (default 1e6)")
    run.set_defaults(func=_run)
    study = sub.add_parser("study", help=f"parametric study: sweep, resumable runs, accuracy-vs-time report "
                                         f"(in parallel: {MPIEXEC} -n N multiscale study STUDY)",
                           description="Sweep the knobs of a problem, run what is missing (resumable) and "
                           "write tables, plots and a Markdown report.",
                           epilog=EPILOG.replace("multiscale run scene.toml", "multiscale study STUDY.toml"),
                           formatter_class=argparse.RawDescriptionHelpFormatter)
    study.add_argument("studies", nargs="*", metavar="STUDY", help="study TOML file(s)")
    study.add_argument("--rerun-failed", action="store_true", help="run the failed runs again")
    study.add_argument("--report", metavar="DIR", help="write every report into DIR, with an index README.md")
    study.add_argument("--processes", type=_count, metavar="N", help="runs at a time (overrides [run] processes)")
    study.add_argument("--problems", action="store_true", help="list the problems, their parameters and metrics")
    study.set_defaults(func=_study)
    modes = sub.add_parser("modes", help="pair the modes of two squeal runs of one mesh by MAC",
                           description="Pair each mode of squeal run A with the mode of run B it resembles most "
                           "(modal assurance criterion of the complex mode shapes in their results folders): "
                           "forward against reverse rotation, with or without damping, serial against parallel.")
    modes.add_argument("runs", nargs=2, metavar="RUN", help="results folders of the two runs (A, then B)")
    modes.add_argument("--mirror", choices=("x", "y", "z"), help="compare B mirrored in the plane normal to this "
                       "axis through the middle of its mesh (a reverse run of a brake symmetric about that plane; "
                       "the built-in brake: x), its shapes taken at A's nodes from the nearest of its own")
    modes.add_argument("--csv", metavar="FILE", help="write the MAC matrix (A's modes x B's) as CSV")
    modes.add_argument("--figure", metavar="FILE", help="draw the MAC matrix (PNG, PDF, SVG)")
    modes.set_defaults(func=_modes)
    surface = sub.add_parser("surface", help="measured topography: conditioning, statistics (Sq, Sdq, Ssk, Sku, "
                                             "Nayak, summits, PSD fit), a figure with --figure",
                             description="Read a measured topography (through SurfaceTopography), remove its form, "
                             "warn of outliers, fill undefined points (and outliers with --despike), optionally "
                             "split waviness from roughness, and print its statistics; with --figure, a figure of "
                             "the height map and the PSD with its fit.")
    surface.add_argument("file", nargs="?", metavar="FILE", help="topography file (x3p, sur, plu, opd, ...; "
                                                                 "--formats lists them)")
    surface.add_argument("--channel", type=int, metavar="N", help="channel index (default: the file's default)")
    surface.add_argument("--detrend", choices=list(DETREND), default="plane", help="form removal (default plane)")
    surface.add_argument("--cutoff", metavar="LENGTH", help='Gaussian filter cut-off λc, e.g. "0.8 mm": '
                                                            "keep the roughness, report the waviness")
    surface.add_argument("--max-undefined", type=float, default=MAX_UNDEFINED, metavar="FRACTION",
                         help=f"largest share of undefined points that is filled (default {MAX_UNDEFINED})")
    surface.add_argument("--despike", type=float, metavar="K", help="remove the outliers (points deviating from "
                         "their neighbourhood's median by more than K times the other heights' Sq) and fill them "
                         f"like undefined points; default: warn of those beyond {DESPIKE:g}")
    surface.add_argument("--pixel-size", metavar="LENGTH", help="override the file's pixel size")
    surface.add_argument("--height-unit", metavar="LENGTH",
                         help='override the file\'s height unit, e.g. "um" or "1 um"')
    surface.add_argument("--figure", metavar="PATH", help="write a figure of the height map and the PSD with its fit "
                         "there (.png, .pdf, .svg); default: no figure")
    surface.add_argument("--formats", action="store_true", help="list the file formats")
    surface.set_defaults(func=_surface)
    return parser


def main(argv: list[str] | None = None) -> int:
    with open(os.devnull, "w") as void, contextlib.ExitStack() as quiet:
        if launched_rank() > 0:       # the usage and its errors once under mpiexec, by rank 0 (a user trial)
            quiet.enter_context(contextlib.redirect_stderr(void))
            quiet.enter_context(contextlib.redirect_stdout(void))
        args = build_parser().parse_args(argv)
    if args.command in SERIAL and launched_rank() > 0:      # `mpiexec -n 4 multiscale check`: said once, not 4 times
        if args.command == "info":     # rank 0 starts PETSc and SLEPc, collective: every rank does what it does
            with open(os.devnull, "w") as void, contextlib.redirect_stdout(void):     # (mpiexec -n 2 multiscale
                _info(args)                                                           # info hung: a user trial)
        return 0
    try:
        with contextlib.ExitStack() as steady:
            if args.command in LONG:
                steady.enter_context(contextlib.redirect_stdout(Outliving(sys.stdout)))
                steady.enter_context(contextlib.redirect_stderr(Outliving(sys.stderr)))
            return int(args.func(args) or 0)
    except SceneError as exc:
        for line in exc.problems:
            print(f"error: {line}", file=sys.stderr)
        return 2
    except MultiscaleError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:     # Ctrl-C in a command without its own words (check --cells: a traceback)
        print(f"interrupted: multiscale {args.command}", file=sys.stderr)
        return 130
    except BrokenPipeError:       # `multiscale surface FILE | head`: the reader left; no traceback
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())    # (nor at the interpreter's flush)
        return 141
    except Exception as exc:      # (a squeal run under ulimit -v ended in a traceback of numpy's allocation)
        lack = behind(exc, MemoryError)
        if lack is None:
            raise
        print(f"error: out of memory ({lack or 'MemoryError'}): more than the {memory_limit() / 1e9:.3g} GB this "
              "process may use (the machine's, a container's or batch job's limit, ulimit -v); what a run wrote "
              f"stays, its provenance.json says it failed: {remedy(squeal=True)}", file=sys.stderr)
        if MPI.COMM_WORLD.size > 1:      # the other ranks wait in a collective: ended with this one
            abort(MPI.COMM_WORLD, 2)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

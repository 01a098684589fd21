"""The shape of the house (docs/architecture.md): imports in one direction, no private names
across modules, local imports only for optional heavy dependencies (with a reason), figures only
in ``multiscale.plots``, modules of reasonable size, each importable on its own."""
import ast
import multiprocessing
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("multiscale", "meshes")
MAX_LINES = 600
# what a function may import locally (each such import carries a comment saying why)
OPTIONAL = ("dolfinx", "dolfinx_solver", "ufl", "basix", "petsc4py", "slepc4py", "gmsh", "matplotlib", "numba",
            "numpy", "scipy", "pyfftw", "mpi4py", "multiscale.workflows", "multiscale.macro", "multiscale.plots",
            "multiscale.studies", "multiscale.micro.fft", "SurfaceTopography", "adios2", "hypothesis")


def has_reason(lines: list[str], line: int) -> bool:
    """A comment on the import's line, or on the line above its block of imports."""
    if "#" in lines[line - 1]:
        return True
    k = line - 2
    while k >= 0 and lines[k].strip().startswith(("import ", "from ")):
        k -= 1
    return k >= 0 and lines[k].strip().startswith("#")


def module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {module_name(p): p for pkg in PACKAGES for p in sorted((ROOT / pkg).rglob("*.py"))}


def imports(name: str):
    """(imported module, names, is_local, line number) of every import of module ``name``."""
    path = MODULES[name]
    tree = ast.parse(path.read_text(), str(path))
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    local = {id(n) for f in ast.walk(tree) if isinstance(f, (ast.FunctionDef, ast.AsyncFunctionDef))
             for n in ast.walk(f) if isinstance(n, (ast.Import, ast.ImportFrom))}
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name, (), id(node) in local, node.lineno
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parent = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join(parent + ([base] if base else []))
            names = tuple(a.name for a in node.names)
            submodules = [f"{base}.{n}" for n in names if f"{base}.{n}" in MODULES]
            yield base, tuple(n for n in names if f"{base}.{n}" not in MODULES), id(node) in local, node.lineno
            for sub in submodules:
                yield sub, (), id(node) in local, node.lineno


def ours(target: str) -> str | None:
    """The module of ours that an import of ``target`` loads (None: a third-party module)."""
    while target and target not in MODULES:
        target = target.rpartition(".")[0]
    return target or None


def graph() -> dict:
    out = {}
    for name in MODULES:
        deps = set()
        for target, _, _, _ in imports(name):
            dep = ours(target)
            if dep and dep != name:
                deps.add(dep)
                # importing a.b.c runs a/__init__ and a.b/__init__ first
                parts = dep.split(".")
                deps.update(".".join(parts[:k]) for k in range(1, len(parts)) if ".".join(parts[:k]) in MODULES)
        deps.discard(name)
        out[name] = deps
    return out


def test_no_import_cycle_local_imports_included():
    g = graph()
    # packages are entered by their children; an edge from a package to its own child is fine
    edges = {m: {d for d in deps if not (d.startswith(m + ".") or m.startswith(d + "."))} for m, deps in g.items()}
    index, low, stack, on, cycles = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in edges[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                cycles.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in edges:
        if v not in index:
            visit(v)
    assert cycles == []


def test_layers_point_one_way():
    g = graph()

    def reach(start):
        seen, todo = set(), [start]
        while todo:
            for d in g[todo.pop()]:
                if d not in seen:
                    seen.add(d)
                    todo.append(d)
        return seen

    assert not {m for m in reach("multiscale.scene") if m.startswith(("meshes", "multiscale.macro"))}
    for name in MODULES:
        below = reach(name)
        if name.startswith(("multiscale.micro", "multiscale.references")):
            assert not {m for m in below if m.startswith(("multiscale.macro", "multiscale.workflows",
                                                          "multiscale.coupling", "multiscale.pool"))}, name
        if name.startswith("multiscale.references"):
            assert not {m for m in below if m.startswith("multiscale.micro")}, name
        if name.startswith("multiscale.macro"):
            assert "multiscale.scene" not in below and not {m for m in below if m.startswith("multiscale.workflows")}, name


def test_no_private_name_across_modules():
    bad = []
    for name in MODULES:
        for target, names, _, line in imports(name):
            module = ours(target)
            if module is None:
                continue
            private = [n for n in names if n.startswith("_") and n != "__version__"]
            if private or any(part.startswith("_") and part != "__init__" for part in target.split(".")):
                bad.append(f"{name}:{line} imports {target} {private}")
    assert bad == []


def test_local_imports_are_optional_heavy_dependencies_with_a_reason():
    bad = []
    for name, path in MODULES.items():
        lines = path.read_text().splitlines()
        for target, _, local, line in imports(name):
            if not local:
                continue
            reason = has_reason(lines, line)
            if not target.startswith(OPTIONAL) or not reason:
                bad.append(f"{name}:{line} imports {target} in a function" + ("" if reason else " without a reason"))
    assert bad == []


def test_figures_only_in_the_plotting_modules_and_modules_stay_small():
    drawing = [n for n in MODULES if not n.startswith("multiscale.plots")
               and any(t.startswith("matplotlib") for t, _, _, _ in imports(n))]
    assert drawing == []
    long = {n: len(p.read_text().splitlines()) for n, p in MODULES.items()}
    assert {n: k for n, k in long.items() if k > MAX_LINES} == {}


# Third-party packages loaded once in a fork server; each module of the package is imported in a
# child forked from it, where no module of the package is loaded yet. A fresh interpreter per module
# took 86 s of the suite, this 15-23 s (DOLFINx's pure-Python ufl and ffcx preloaded too: 22.3 s
# then 20.4 s on a quiet machine). MPI (mpi4py, dolfinx, PETSc) is not preloaded: a child
# initialises it; nor h5py, which must come before dolfinx_solver in our modules' own imports.
PRELOAD = ["numpy", "scipy.fft", "scipy.sparse.linalg", "scipy.special", "scipy.optimize", "matplotlib.figure",
           "numba", "pyfftw", "ufl", "ffcx", "basix", "cffi", "tqdm"]
ALONE = "import sys\nassert not [m for m in sys.modules if m.split('.')[0] in {packages}]\nimport {name}"


@pytest.mark.slow
def test_every_module_imports_on_its_own_in_a_fresh_process():
    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload(PRELOAD)
    with context.Pool(2, maxtasksperchild=1) as pool:  # (not ProcessPoolExecutor's max_tasks_per_child: it can deadlock,
        done = {name: pool.apply_async(exec, (ALONE.format(packages=PACKAGES, name=name), {}))   # CPython
                for name in sorted(MODULES)}                                               # gh-115634, here 3.12.1)
        failed, deadline = {}, time.monotonic() + 600
        for name, result in done.items():
            try:
                result.get(timeout=max(deadline - time.monotonic(), 1.0))   # (a child that died: its task is lost)
            except multiprocessing.TimeoutError:
                failed[name] = "no answer: its child died or hung while importing it"
            except Exception as exc:             # (a child's failed import, re-raised here)
                failed[name] = repr(exc)
    assert failed == {}


def test_a_run_without_figures_never_loads_matplotlib():
    """The workflows and the CLI import the plotting modules where a figure is drawn: matplotlib
    took 0.6-1.3 s of each ``multiscale run`` process (every MPI rank) with ``figures = false``."""
    pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")      # the workflows import it
    code = ("import sys, multiscale.cli, multiscale.workflows.squeal, multiscale.workflows.squeal_map, "
            "multiscale.workflows.multiscale, multiscale.studies.worker\n"
            "print(' '.join(m for m in sys.modules if m.startswith('matplotlib')))")
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == []

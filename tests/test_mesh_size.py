"""The cell count of a mesh, estimated before meshing (issue 21: a 0.05 mm mesh size used to start
meshing without end): trial meshes with every element size scaled up, extrapolated as a volume
mesh (``multiscale.geometry.estimate_cells``); a mesh estimated above ``geometry.max_cells`` is
refused before meshing, on every rank, with one message."""
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

gmsh = pytest.importorskip("gmsh")

from multiscale.errors import InputError  # noqa: E402
from multiscale.geometry import MAX_CELLS, builder, check_cells, estimate_cells, mesh_counts  # noqa: E402

TINY = {"mesh_size": 5e-5, "holder_mesh_size": 5e-5, "interface_mesh_size": 5e-5}


def mesh() -> tuple[np.ndarray, np.ndarray]:
    """Node coordinates and tetrahedra (node tags) of gmsh's current model."""
    _, x, _ = gmsh.model.mesh.getNodes()
    return x, np.concatenate(gmsh.model.mesh.getElements(3)[2])


def real(name: str, params: dict) -> tuple[np.ndarray, np.ndarray]:
    """The builder's real mesh, built in a session of its own."""
    gmsh.initialize(interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("real")
        builder(name).generate(gmsh.model, params)
        return mesh()
    finally:
        gmsh.finalize()


def cells(name: str, params: dict) -> int:
    """Tetrahedra of the builder's real mesh."""
    return len(real(name, params)[1]) // 4


@pytest.mark.parametrize("name, params", [
    ("pin_on_disc", {"interface_mesh_size": 1e-3, "mesh_size": 6e-3}),
    ("block_on_flat", {"mesh_size": 0.4e-3}),
    ("disc_brake", {}),                         # its coarsest trials fail in the CAD kernel: skipped
    ("disc_brake", {"mesh_size": 6e-3}),
])
def test_the_estimate_is_within_a_factor_two_and_a_half(name, params):
    """From trial meshes of >= 5000 cells (coarser than the mesh: factor > 1), the estimate lies
    between 0.9x (mesh-to-mesh noise of gmsh) and 2.5x the real count (measured: 1.0-2.1x; the
    disc brake's circles keep their curvature-based cells in coarse trials; 1.0-1.3x from the
    default 20 000-cell trials)."""
    estimate = estimate_cells(builder(name), params, target=5000)
    real = cells(name, params)
    assert estimate.factor > 1 and estimate.trial >= 5000 and not estimate.exact
    assert 0.9 * real <= estimate.cells <= 2.5 * real, (estimate, real)


@pytest.mark.parametrize("name, params", [
    ("pin_on_disc", {"disc_thickness": 1.5e-3}),
    ("block_on_flat", {"length": 0.08e-3, "width": 0.2e-3, "height": 0.1e-3, "flat_thickness": 0.1e-3,
                       "flat_length": 0.08e-3, "flat_width": 0.2e-3, "mesh_size": 0.05e-3,
                       "interface_mesh_size": 0.05e-3}),
])
def test_small_geometries_find_their_faces(name, params):
    """A builder's faces are picked by boxes a margin of 1e-4 of its smallest dimension wider,
    and OpenCASCADE widens every entity's box by 1e-7 m: with a 1.5 mm disc (the pin_on_disc
    works from 1.6 mm) or a 0.08 mm block no face fitted, and meshing ended in "builder selected no
    entities for physical group" (found by a user trial); the query boxes are now 2e-7 m wider."""
    x, tets = real(name, params)
    assert len(tets) > 0 and np.isfinite(x).all()


def test_the_estimate_of_a_small_mesh_is_its_count():
    """A mesh smaller than the trial target is meshed at its size: the exact count."""
    estimate = estimate_cells(builder("block_on_flat"), {})
    assert estimate.exact and estimate.cells == cells("block_on_flat", {})


def test_a_small_mesh_above_the_limit_is_refused_with_its_exact_count():
    """Counted on the mesh itself (factor 1), the refusal gives the count, not 'a trial mesh 1x
    coarser' (multiscale run of the perfect pin-on-disc with geometry.max_cells = 100 said so)."""
    estimate = estimate_cells(builder("block_on_flat"), {})
    with pytest.raises(InputError) as info:
        check_cells(builder("block_on_flat"), {}, 100)
    assert estimate.exact and f"the mesh would have {estimate.cells} cells (exact): " in str(info.value)
    assert "coarser" not in str(info.value)


def test_an_absurd_mesh_size_is_refused_before_meshing():
    """0.05 mm everywhere on the pin-on-disc: ~1e10 cells, refused from one trial mesh 64x coarser;
    the message names the limit and what to change."""
    with pytest.raises(InputError, match=r"geometry.max_cells = 1000000: the mesh would have about 1\.\d+e\+10 "
                                         r"cells .*geometry.mesh_size.*--max-cells") as info:
        check_cells(builder("pin_on_disc"), TINY, MAX_CELLS)
    assert "64x coarser" in str(info.value)


def test_a_mesh_size_far_below_the_geometry_starts_from_coarse_enough_trials():
    """1 um on the 10 mm block: a first trial 64x coarser has elements of 64 um, millions of cells
    (a 12 um size on a CAD brake meshed for minutes, "check --cells" and "run" alike: an adversarial
    test). With the geometry's size the first trial's elements are at least 1/16 of it; the
    estimate still refuses the mesh, from a trial of at most a few times the target."""
    spec = builder("block_on_flat").describe({"mesh_size": 1e-6})
    estimate = estimate_cells(builder("block_on_flat"), {"mesh_size": 1e-6}, enough=MAX_CELLS,
                              length_scale=spec.length_scale)
    assert estimate.cells > 1e9 and estimate.trial < 200_000 and estimate.factor > 64
    from multiscale.scene import loads
    from test_faults import SCENE
    bare = loads(SCENE.format(folder="out").replace('mesh_size = "5 mm"', "mesh_size = 5"))
    assert "geometry.mesh_size = 5 m is larger than the geometry (0.01 m across): a bare number is in metres; " \
           'give a unit ("12 mm")' in bare.warnings


def test_a_mesh_below_the_limit_is_settled_by_a_coarse_trial():
    """The estimate over-estimates, so a coarse trial below the limit settles it: the mesh itself
    is not built twice."""
    estimate = check_cells(builder("pin_on_disc"), {}, MAX_CELLS)
    assert estimate.factor > 2 and 0.9 * cells("pin_on_disc", {}) <= estimate.cells <= MAX_CELLS


def test_a_mesh_within_the_limit_is_not_refused_for_the_over_estimate():
    """An estimate above the limit but within ``OVER`` times it is refined on towards the real
    mesh: a limit halfway between the disc brake's real count (175 230 cells at 5 mm) and the
    estimate from its 28 000-cell trial (1.28x more) accepts it (before: refused; the car brake
    at 2.5 / 1.2 mm, about 0.8M cells, was refused at the default 1M). Far above the limit the
    coarse trial still settles it."""
    params = {"mesh_size": 5e-3}
    rough, real = estimate_cells(builder("disc_brake"), params), cells("disc_brake", params)
    assert not rough.exact and rough.cells > 1.1 * real            # the over-estimate this is about
    limit = (real + rough.cells) // 2
    estimate = check_cells(builder("disc_brake"), params, limit)
    assert 0.9 * real <= estimate.cells <= limit and estimate.factor < rough.factor
    with pytest.raises(InputError, match="coarser"):               # 3x over: refused from a trial
        check_cells(builder("disc_brake"), params, real // 3)


@pytest.mark.parametrize("name", ["pin_on_disc", "disc_brake"])
def test_a_kept_session_holds_the_builders_own_mesh(name):
    """With keep, the trials' model is remeshed at the builder's sizes in their session (one
    reading of a CAD file): node for node and tetrahedron for tetrahedron the mesh of a fresh
    run of the builder. The disc brake's coarsest trials fail, so its session is begun anew."""
    estimate = check_cells(builder(name), {}, MAX_CELLS, keep=True)
    try:
        assert gmsh.isInitialized() and not estimate.exact
        x, tets = mesh()
    finally:
        gmsh.finalize()
    x_ref, tets_ref = real(name, {})
    assert np.array_equal(x, x_ref) and np.array_equal(tets, tets_ref)


def test_a_refused_mesh_leaves_no_session():
    with pytest.raises(InputError, match="geometry.max_cells"):
        check_cells(builder("pin_on_disc"), TINY, MAX_CELLS, keep=True)
    assert not gmsh.isInitialized()


def test_gmsh_is_left_as_found():
    """Each trial is a gmsh session of its own; a caller's session is refused, not disturbed."""
    estimate_cells(builder("block_on_flat"), {})
    assert not gmsh.isInitialized()
    gmsh.initialize(interruptible=False)
    try:
        with pytest.raises(RuntimeError, match="before gmsh.initialize"):
            estimate_cells(builder("block_on_flat"), {})
    finally:
        gmsh.finalize()


def test_the_limit_of_a_run_two_ranks(tmp_path):
    """multiscale run on 2 ranks of a scene whose mesh exceeds --max-cells: both ranks end with
    exit code 2 and one error line, before meshing."""
    pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")
    from test_faults import MPIEXEC, SCENE
    scene = tmp_path / "scene.toml"
    scene.write_text(SCENE.format(folder=tmp_path / "out"))
    done = subprocess.run([str(MPIEXEC), "-n", "2", str(Path(sys.executable).with_name("multiscale")), "run",
                           str(scene), "--max-cells", "50"], capture_output=True, text=True, timeout=300,
                          start_new_session=True)
    errors = [line for line in done.stderr.splitlines() if line.startswith("error")]
    assert done.returncode == 2, done.stderr[-2000:]
    assert len(errors) == 1 and re.search(r"geometry.max_cells = 50: the mesh would have \d+ cells \(exact\)", errors[0])


def test_vertices_and_edges_are_counted_per_body():
    """Two tetrahedra sharing a face: 5 vertices and 9 edges in one body; as two bodies (each a mesh
    of its own in a run) 4 + 4 and 6 + 6; a body of other cells is not counted."""
    gmsh.initialize(interruptible=False)
    try:
        model = gmsh.model
        model.add("two")
        for entity in (1, 2):
            model.addDiscreteEntity(3, entity)
        model.mesh.addNodes(3, 1, [1, 2, 3, 4, 5], [0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1])
        model.mesh.addElements(3, 1, [4], [[1]], [[1, 2, 3, 4]])
        model.mesh.addElements(3, 2, [4], [[2]], [[2, 3, 4, 5]])
        model.addPhysicalGroup(3, [1], 10)
        model.addPhysicalGroup(3, [2], 20)
        model.addPhysicalGroup(3, [1, 2], 30)
        assert mesh_counts(model, [[10, 20]]) == mesh_counts(model, [[30]]) == (5, 9)
        assert mesh_counts(model, [[10], [20]]) == (8, 12)
        model.addDiscreteEntity(3, 3)
        model.mesh.addNodes(3, 3, [6, 7, 8, 9, 10], [2, 0, 0, 3, 0, 0, 2, 1, 0, 3, 1, 0, 2, 0, 1])
        model.mesh.addElements(3, 3, [7], [[3]], [[6, 7, 9, 8, 10]])       # a pyramid
        model.addPhysicalGroup(3, [3], 40)
        assert mesh_counts(model, [[10], [40]]) == (0, 0)
    finally:
        gmsh.finalize()


@pytest.mark.parametrize("name, params", [("pin_on_disc", {}), ("disc_brake", {"mesh_size": 12e-3})])
def test_the_dofs_a_cell_from_trial_meshes(name, params):
    """Vertices and edges estimated from trials (volume and surface terms through the last two)
    against the real mesh's: quadratic dofs a cell within 4 % (measured 2.6 % and 0.8 %), from
    trials far from the mesh (its cells over-estimated 2.2x and 2.1x)."""
    module = builder(name)
    bodies = [[r.tag for r in b.regions] for b in module.describe(module.parameters(params)).bodies]
    exact = estimate_cells(module, params, target=10**8, bodies=bodies)
    rough = estimate_cells(module, params, target=2000, bodies=bodies)
    assert exact.exact and not rough.exact and rough.cells > 1.5 * exact.cells
    per_cell = [3 * (e.nodes + e.edges) / e.cells for e in (exact, rough)]
    assert per_cell[1] == pytest.approx(per_cell[0], rel=0.04), per_cell
    assert rough.nodes / rough.cells == pytest.approx(exact.nodes / exact.cells, rel=0.1)


def test_check_cells_estimates_the_runs_memory_and_warns_beyond_the_free(tmp_path, capsys, monkeypatch):
    """check --cells gives the memory a run of the mesh takes (a 3 mm CAD brake of ~1M dofs, some
    40 GB, was checked "OK" without a word: a user trial), and warns beyond what the machine has
    free; still OK: an estimate."""
    from multiscale import cli
    from multiscale.memory import HEAT_DOFS, run_memory
    from multiscale.scene import load
    from multiscale.scene_summary import linear_heat
    from test_faults import SCENE
    path = tmp_path / "scene.toml"
    path.write_text(SCENE.format(folder=tmp_path / "out"))
    monkeypatch.setattr(cli, "memory_available", lambda: 1e6)
    assert cli.main(["check", str(path), "--cells"]) == 0
    captured = capsys.readouterr()
    g = load(path).geometry
    bodies = [[r.tag for r in b.regions] for b in g.spec.bodies]
    mesh = estimate_cells(g.module(), dict(g.params), bodies=bodies)
    assert mesh.exact and f"  mesh      {mesh.cells:,} cells (exact)" in captured.out
    scene = load(path)                                    # with heat: 1.7 temperature dofs a displacement dof
    heat = HEAT_DOFS * 3 * mesh.nodes if scene.has("thermal") else 0.0
    need = run_memory(3 * mesh.nodes, "transient", heat_dofs=heat, linear_heat=linear_heat(scene))  # 3 dofs a vertex
    assert f"  memory    about {need / 1e9:.2g} GB at the peak of a transient run on one rank, each more adding " \
        "about 0.33 GB (about " in captured.out
    assert "warning: up to 1.15 times that is near or above the 0.001 GB this machine has free: a coarser mesh " \
        "(geometry.mesh_size) or ranks on more machines" in captured.err
    # a multiscale run adds its zones' (before: the macro part alone, 0.41 GB for 0.55 to 1.75 GB measured)
    from multiscale.memory import micro_memory
    from test_coupling import POD
    path.write_text(POD.format(folder=tmp_path / "rough"))
    assert cli.main(["check", str(path), "--cells"]) == 0
    out, scene = capsys.readouterr().out, load(path)
    g = scene.geometry
    mesh = estimate_cells(g.module(), dict(g.params), bodies=[[r.tag for r in b.regions] for b in g.spec.bodies])
    heat = HEAT_DOFS * 3 * mesh.nodes if scene.has("thermal") else 0.0
    need = run_memory(3 * mesh.nodes, "transient", heat_dofs=heat, linear_heat=linear_heat(scene)) + \
        micro_memory(25 * 16**2)                                                    # 5 x 5 zones of 16^2
    assert f"  memory    about {need / 1e9:.2g} GB at the peak of a multiscale run on one rank, each more adding " \
        "about 0.48 GB (about " in out and "; its zones 6,400 grid points; " in out


def test_max_cells_in_the_scene_and_on_the_command_line(tmp_path, capsys):
    from multiscale.cli import main
    from multiscale.scene import loads
    from test_faults import SCENE
    text = SCENE.format(folder=tmp_path / "out")
    assert loads(text).geometry.max_cells == MAX_CELLS
    assert loads(text.replace('mesh_size = "5 mm"', 'mesh_size = "5 mm"\nmax_cells = 2_000_000')).geometry.max_cells \
        == 2_000_000
    with pytest.raises(InputError, match="geometry.max_cells"):
        loads(text.replace('mesh_size = "5 mm"', 'mesh_size = "5 mm"\nmax_cells = 0'))
    path = tmp_path / "scene.toml"
    path.write_text(text)
    assert main(["check", str(path), "--cells"]) == 0
    out = capsys.readouterr().out
    line = next(x for x in out.splitlines() if x.startswith("  mesh "))
    assert line.endswith("cells (exact); within geometry.max_cells = 1,000,000") and "about" not in line
    # a mesh above the limit is a problem for check too (before: "refused by run", then OK, exit 0)
    path.write_text(text.replace('mesh_size = "5 mm"', 'mesh_size = "5 mm"\nmax_cells = 100'))
    assert main(["check", str(path), "--cells"]) == 2
    captured = capsys.readouterr()
    assert "refused by run geometry.max_cells = 100" in captured.out and "scene.toml: OK" not in captured.out
    errors = [x for x in captured.err.splitlines() if x.startswith("error: ")]
    assert len(errors) == 1 and re.match(r"error: geometry.max_cells = 100: the mesh would have \d+ cells \(exact\)",
                                         errors[0])
    with pytest.raises(SystemExit):
        main(["run", str(path), "--max-cells", "2.5"])
    assert "a whole number" in capsys.readouterr().err


def test_a_multiscale_runs_memory_counts_each_interfaces_own_zones():
    """Zones of each rough interface's own micro table: the brake's inner pad 3 x 3 zones, the outer
    2 x 2, both 16^2 (before: the scene-wide 2 x 2 for both, 2 048 points for 3 328)."""
    from multiscale.geometry import CellEstimate
    from multiscale.memory import micro_memory, run_memory
    from multiscale.scene import load
    from multiscale.scene_summary import memory_line
    scene = load(Path(__file__).resolve().parents[1] / "demos" / "brake_squeal.toml", {
        "effects": ["contact", "friction", "roughness"], "roughness": {"rms": "3 um", "hurst": 0.8, "k_min": 1,
                                                                    "k_max": 6},
        "micro": {"zones": [2, 2], "grid": [16, 16]}, "interfaces.inner_pad.micro.zones": [3, 3]})
    line, need = memory_line(scene, CellEstimate(1000, 1000, 1.0, nodes=500))
    assert "its zones 3,328 grid points" in line
    assert need == pytest.approx(run_memory(1500, "transient") + micro_memory(3328), rel=1e-12)


def test_the_memory_estimate_counts_a_linear_heat_problems_double_factors():
    """A heat problem with constant properties and no radiation keeps double-precision LU factors
    (the Newton's are single): the thesis pin-on-disc (39 072 displacement dofs, 63 733 temperature
    dofs) peaked at 1.20 GB where check said 0.81 GB (a user trial); the car brake's heat is not linear."""
    from multiscale.geometry import CellEstimate
    from multiscale.scene import load
    from multiscale.scene_summary import linear_heat, memory_line
    demos = Path(__file__).resolve().parents[1] / "demos"
    pod = load(demos / "pin_on_disc_perfect.toml")
    assert linear_heat(pod) and not linear_heat(load(demos / "car_brake_stop.toml"))
    assert not linear_heat(load(demos / "pin_on_disc_perfect.toml", {"boundary": [{"surfaces": ["free:disc"],
                                                                                    "emissivity": 0.5}]}))
    line, need = memory_line(pod, CellEstimate(60_699, 60_699, 1.0, nodes=13_024))      # 39 072 dofs
    assert need / 1e9 == pytest.approx(1.20, rel=0.12)
    assert "about 39,072 displacement dofs, 66,422 temperature dofs (a linear heat problem: double-precision " \
        "factors)" in line


def test_a_stability_maps_memory_is_more_than_one_analysis():
    """A stability map holds two points' systems and modes at once: the built-in brake at 20 mm (30
    modes to 8 kHz) peaked at 1.30 GB alone, 1.72 / 1.76 GB with a friction map of 3 / 5 points,
    1.50 GB with a speed map of 3 (serial, /usr/bin/time -v, 2026-12-05); check said 1.3 GB for both
    (a user trial measured 1.35x)."""
    from multiscale.geometry import CellEstimate
    from multiscale.scene import load
    from multiscale.scene_summary import memory_line
    demo = Path(__file__).resolve().parents[1] / "demos" / "brake_squeal.toml"
    mesh = CellEstimate(8_796, 8_796, 1.0, nodes=3_000, edges=13_335)          # 49 005 quadratic dofs
    common = {"stability.modes": 30}
    alone = memory_line(load(demo, common), mesh)[1] / 1e9
    for sweep, measured in (({"stability.sweep.friction": [0.2, 0.6], "stability.sweep.points": 3}, 1.72 / 1.30),
                            ({"stability.sweep.speed": ["10 rad/s", "100 rad/s"], "stability.sweep.points": 3},
                             1.50 / 1.30)):
        line, need = memory_line(load(demo, {**common, **sweep}), mesh)
        assert need / 1e9 / alone == pytest.approx(measured, rel=0.05) and "of a squeal map run" in line
    assert alone == pytest.approx(1.30, rel=0.07)

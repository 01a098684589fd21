"""The user guide's reference pages are generated from the schemas and name every key (issue 22);
the guide itself is built by `make docs` (part of `make test`), failing on any warning."""
import dataclasses
import re
from pathlib import Path

import pytest

from multiscale.reference_docs import key_paths, scene_rst, study_rst
from multiscale.schema import Section, fields_of
from multiscale.scene import EFFECTS, OUTPUT_FIELDS, Scene
from multiscale.scene_summary import reference, table_reference, tables


def _all_keys(cls, seen=None):
    """Every (leaf) key name of the schema below ``cls`` (through the sections' dataclasses)."""
    seen = set() if seen is None else seen
    names = set()
    if cls in seen:
        return names
    seen.add(cls)
    for name, spec in fields_of(cls):
        if not isinstance(spec.parser, Section):
            names.add(name)
        elif dataclasses.is_dataclass(spec.parser.cls):
            names |= _all_keys(spec.parser.cls, seen)
    return names


def test_every_scene_key_appears_in_the_generated_reference():
    text = scene_rst()
    paths = key_paths()
    assert {p.rsplit(".", 1)[-1] for p in paths} >= _all_keys(Scene) - {"geometry"}
    missing = [p for p in paths if f"``{p}``" not in text]
    assert missing == []
    for name in EFFECTS:
        assert f"``{name}``" in text
    for name in OUTPUT_FIELDS:
        assert f"``{name}``" in text
    assert "``loading.normal_force``" in text and "| N" not in text            # units in their own column
    assert "``geometry.track_radius``" in text and "``materials.<name>.kappa``" in text


def test_a_sections_text_keeps_its_literals_in_the_reference():
    """A section's text in the generated reference keeps its ``literals`` (they rendered as
    ''literals'': a user trial); table cells, where RST literals could break the table, do not."""
    text = scene_rst()
    assert "``friction_curve`` or ``stribeck``" in text and "''friction_curve''" not in text


def test_check_keys_and_the_generated_reference_name_the_same_keys():
    """`multiscale check --keys` (scene_summary.reference) and the user guide's page list the same
    key names: the page lacked geometry.builder and geometry.max_cells. Each builder's text on the
    page ends with a whole sentence (it was cut at 60 words, mid-sentence)."""
    leaves = {p.rsplit(".", 1)[-1] for p in key_paths()}
    lines = reference()
    keys = lines[lines.index("top level:"):]                      # after the effects and output fields
    assert {m.group(1) for line in keys if (m := re.match(r" {2,4}(\w+) {2,}", line))} == leaves
    text = scene_rst()
    assert "``geometry.builder``" in text and "``geometry.max_cells``" in text
    builders = re.findall(r'^builder = "\w+"\n~+\n\n(.*)$', text, re.M)
    assert len(builders) == 3 and all(b.endswith(".") for b in builders), builders


def test_check_keys_of_a_table_says_what_its_keys_do(tmp_path, capsys):
    """`check --keys TABLE` prints the table's text before its keys (check --keys gave a key's type
    and range only, not what it does: a user trial); every table has a text; a misspelt table is
    named with the nearest; `check --keys SCENE` still checks the scene after the format."""
    from multiscale.cli import main
    assert main(["check", "--keys", "loading"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0] == "[loading]" and "ramp_steps: the first contact solve" in " ".join(out[1:out.index("")])
    assert any(re.match(r" +ramp_steps +an integer >= 1", line) for line in out)
    for name in tables():
        lines = table_reference(name)
        assert len(lines[1].split()) >= 10 and lines[2] == "" and len(lines) > 3, name
    assert table_reference("[materials.<name>]") == table_reference("materials") == table_reference("MATERIALS")
    assert table_reference("geometry.bodies")[0] == "[geometry.bodies.<name>]"       # a geometry file's tables too
    assert main(["check", "--keys", "loading.friction"]) == 2                           # a key, not a table
    assert "a key of [loading]: multiscale check --keys loading" in capsys.readouterr().err
    assert main(["check", "--keys", "loadng"]) == 2
    assert 'not a table of the scene format (did you mean "loading"?)' in capsys.readouterr().err
    scene = tmp_path / "s.toml"
    scene.write_text((Path(__file__).parents[1] / "demos" / "pin_on_disc.toml").read_text())
    assert main(["check", "--keys", str(scene)]) == 0
    assert capsys.readouterr().out.rstrip().endswith(f"{scene}: OK")


def test_an_optional_key_without_default_says_what_its_absence_means():
    """`check --keys` and the page say what an optional key without a default means when left out
    (they said "[optional]" and "none": geometry.unit without a value is the unit a STEP file
    declares, not none), and the sweep's preload text is what the scene does."""
    from multiscale.scene_stability import Sweep
    lines = reference()
    unit = next(line for line in lines if re.match(r" +unit +a length unit", line))
    assert unit.endswith("[optional; without it: a STEP/IGES file's declared unit (mm if it declares none); "
                         "metres for .msh, .geo, .brep]")
    assert "| a STEP/IGES file's declared unit" in scene_rst().replace("\n     - ", " | ")
    assert [Sweep(**{p: (1.0, 2.0)}).preload_mode for p in ("friction", "speed", "pressure", "rms")] == \
        ["each", "once", "each", "each"]


def test_every_optional_key_without_default_says_what_its_absence_means():
    """No key of `check --keys` is a bare "[optional]" (56 were): an optional key without a default says
    what leaving it out does (a new key must too), and the page's default column never says "none"
    (a key without a default that an effect needs says "required with" it; 8 said "none")."""
    lines = reference()
    assert [line for line in lines if line.endswith("[optional]")] == []
    assert sum("[optional; without it: " in line for line in lines) >= 64
    rows = scene_rst().split("   * - ")
    assert [r.split("\n")[0] for r in rows if "\n     - none\n" in r] == []
    bare = [r.split("\n")[0] for r in rows if "\n     - required with " in r]
    needed = {f"``{p}``" for p in ("materials.<name>.rho", "materials.<name>.kappa", "materials.<name>.alpha",
                                   "interface.penalty", "interface.partition", "interface.conductance", "time.end",
                                   "layers.layer.kappa")}
    assert set(bare) == needed, set(bare) ^ needed


def test_the_absence_texts_say_what_the_code_does(tmp_path):
    """Some absence texts against the code that reads the key: output.folder and output.fields, a
    boundary's ambient and convection, an interface's friction, the load factor and the speed, the
    micro grid, remote temperatures and coupling, and the wear rate."""
    from multiscale.scene import loads
    from multiscale.scene_output import Output, Probe
    from multiscale.scene_sections import DEFAULT_GRID, Boundary, InterfaceSettings, Loading, Micro
    from multiscale.scene_wear import FIG_7_9_WEAR_RATE, Wear
    text = (Path(__file__).parents[1] / "demos" / "block_on_flat.toml").read_text()
    text = text.replace('folder = "../results/block_on_flat"', "")
    scene = loads(text, tmp_path, name="x")
    assert _absent(Output, "folder") == "results/<name> next to the scene file"
    assert scene.output.folder == tmp_path.resolve() / "results" / "block_on_flat"
    assert _absent(Output, "fields") == "every field the effects produce"
    assert scene.output.fields == ("displacement", "von_mises", "contact_pressure", "interface")
    assert _absent(Probe, "body").startswith("the body holding the point")   # macro.probes: bodies [0, 1] searched
    assert _absent(Boundary, "ambient") == "time.initial_temperature"       # read in workflows.model
    assert Boundary(surfaces=("a",), fix=("z",)).h(10.0) == 0.0 and _absent(Boundary, "convection") == "no convection"
    assert _absent(InterfaceSettings, "friction").startswith("loading.friction")
    pin = loads((Path(__file__).parents[1] / "demos" / "pin_on_disc.toml").read_text(), tmp_path, name="x")
    assert pin.interfaces == {} and pin.interface_settings("interface").friction == pin.loading.friction == 0.4
    assert _absent(Loading, "load_profile") == "factor 1 throughout" and Loading().factor(5.0) == 1.0
    assert _absent(Loading, "rotation_speed").endswith("else at rest") and Loading().angular_speed(1.0) == 0.0
    assert _absent(Micro, "grid").startswith(f"{DEFAULT_GRID[0]} x {DEFAULT_GRID[1]};")
    assert [Micro().remote(e) for e in (set(), {"conductance"})] == ["bulk", "rough"]
    assert _absent(Micro, "remote_temperatures") == '"bulk"; "rough" with effect conductance'
    assert [Micro().coupling_scheme(e) for e in (set(), {"conductance"})] == ["implicit", "explicit"]
    assert _absent(Wear, "k_w").endswith("else thesis Fig. 7.9") and Wear().rate == tuple(zip(*FIG_7_9_WEAR_RATE))
    assert (Wear().given, Wear(specific_rate=1e-14).per_load, Wear(k_w=1e-14).per_load) == (None, True, False)


def _absent(cls, name: str) -> str:
    return dict(fields_of(cls))[name].absent


def test_every_study_key_appears_in_the_generated_study_format():
    from multiscale.studies.spec import StudyFile
    text = study_rst()
    for path in key_paths(StudyFile):
        assert f"``{path}``" in text, path
    # in words, not Python's reprs; paths as they are read (a user trial read "FrozenMap({})", the
    # dataclass signatures of [run] and [report], and "relative to the scene file")
    assert "FrozenMap" not in text and "Options(" not in text and "the scene file" not in text
    assert text.count("relative to the study file") == 4


def test_the_micro_patch_tutorial_runs_and_gives_the_numbers_it_quotes(capsys):
    """The tutorial's first code block, run as shown (256², seconds), prints the 256² numbers its
    text quotes: area, approach and iterations (the first of each quoted triple); then its
    stiffness block the stiffness it quotes."""
    text = (Path(__file__).resolve().parents[1] / "docs" / "tutorials" / "micro_patch.rst").read_text()
    block = re.search(r"\.\. code-block:: python\n\n((?:    .*\n|\n)+)", text).group(1)
    scope = {}
    exec("\n".join(line[4:] for line in block.splitlines()), scope)
    assert "real contact area" in capsys.readouterr().out
    r = scope["r"]
    approach = float(re.search(r"approach settles .*?\((\S+),", text).group(1))
    area = float(re.search(r"real contact area still\s+moves .*?\((\S+),", text, re.S).group(1))
    iterations = int(re.search(r"\((\d+), \d+, \d+ here\)", text).group(1))
    assert 1e6 * r.approach == pytest.approx(approach, abs=5e-4)       # quoted to 1e-3 um
    assert 100 * r.area_fraction == pytest.approx(area, abs=5e-3)      # quoted to 0.01 %
    assert r.iterations == iterations
    block = re.search(r"\.\. code-block:: python\n\n((?:    .*\n|\n)+)", text[text.index("contact_stiffness`;"):]).group(1)
    exec("\n".join(line[4:] for line in block.splitlines()), scope)
    stiffness = float(re.search(r"It gives (\S+) MPa/µm", text).group(1))
    assert 1e-12 * scope["k"].stiffness == pytest.approx(stiffness, abs=5e-4)   # quoted to 1e-3 MPa/um


def test_the_readme_names_every_tutorial_of_the_user_guide():
    """README's summary of the user guide names each tutorial by its title (before: the braking
    cycle tutorial was missing from it)."""
    root = Path(__file__).resolve().parents[1]
    readme = " ".join((root / "README.md").read_text().split())
    for page in sorted((root / "docs" / "tutorials").glob("*.rst")):
        title = page.read_text().splitlines()[0].removeprefix("Tutorial: ")
        assert title in readme, f"{page.name}: {title!r}"


def test_the_readme_says_where_each_demo_finds_a_file_from_outside_the_repository():
    """A demo scene reading a file outside the repository (the measured pin face) has it named in
    README's table of demos (before: the table did not say that pin_on_disc_measured.toml needs
    ../shared/data beside the repository; `multiscale check` of it elsewhere: 'no such file')."""
    import tomllib
    root = Path(__file__).resolve().parents[1]
    readme = (root / "README.md").read_text()
    for scene in sorted((root / "demos").glob("*.toml")):
        data = tomllib.loads(scene.read_text())
        for file in (section.get("file") for section in data.values() if isinstance(section, dict)):
            if file and not (scene.parent / file).resolve().is_relative_to(root):
                row = next(line for line in readme.splitlines() if line.startswith(f"| `{scene.name}`"))
                assert Path(file).name in row and f"{Path(file).parent.name}/" in row, scene.name

"""The user guide's reference pages are generated from the schemas and name every key (issue 22);
the guide itself is built by `make docs` (part of `make test`), failing on any warning."""
import dataclasses
import re

from multiscale.reference_docs import key_paths, scene_rst, study_rst
from multiscale.schema import Section, fields_of
from multiscale.scene import EFFECTS, OUTPUT_FIELDS, Scene
from multiscale.scene_summary import reference


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


def test_every_study_key_appears_in_the_generated_study_format():
    from multiscale.studies.spec import StudyFile
    text = study_rst()
    for path in key_paths(StudyFile):
        assert f"``{path}``" in text, path

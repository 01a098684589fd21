"""Sphinx directives that put the generated reference pages into the guide:
``.. scene-reference::`` and ``.. study-reference::`` (``multiscale.reference_docs``), and a hook
that turns the Markdown pages' links to source files (outside docs/) into plain text."""
import re

from docutils import nodes
from docutils.statemachine import StringList
from sphinx.util.docutils import SphinxDirective

from multiscale.reference_docs import scene_rst, study_rst


class Generated(SphinxDirective):
    make = None

    def run(self):
        container = nodes.container()
        self.state.nested_parse(StringList(type(self).make().splitlines(), "generated"), self.content_offset,
                                container, match_titles=True)
        return container.children


class SceneReference(Generated):
    make = staticmethod(scene_rst)


class StudyReference(Generated):
    make = staticmethod(study_rst)


SOURCE_LINK = re.compile(r"\[([^\]]+)\]\((\.\./[^)#]*|[^)#:]*\.(?:py|toml|txt))(#[^)]*)?\)")


def plain_source_links(app, docname, source):
    """[`x.py`](../multiscale/x.py) -> `x.py`: the guide has no pages for source files."""
    if docname in ("architecture",):
        source[0] = SOURCE_LINK.sub(r"\1", source[0])


def plain_docstrings(app, what, name, obj, options, lines):
    """The docstrings are plain text with ``literals``: |k| is an absolute value and *batch a
    Python unpacking, not reST substitutions or emphasis."""
    for i, line in enumerate(lines):
        parts = line.split("``")
        for k in range(0, len(parts), 2):
            parts[k] = STAR.sub(r"\\*", parts[k].replace("|", "\\|"))
        lines[i] = "``".join(parts)


STAR = re.compile(r"(?<=[(,] )\*|(?<=\()\*")


def setup(app):
    app.connect("autodoc-process-docstring", plain_docstrings)
    app.add_directive("scene-reference", SceneReference)
    app.add_directive("study-reference", StudyReference)
    app.connect("source-read", plain_source_links)
    return {"parallel_read_safe": True, "parallel_write_safe": True}

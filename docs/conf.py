"""Sphinx configuration of pendular's documentation site.

Build (from the repository root, after ``pip install -e '.[docs]'``):

    python -m sphinx -j auto -W --keep-going -b html docs docs/_build/html

Pages are Markdown (MyST); the tutorials (docs/tutorials/) and the examples (examples/) are
Python scripts that sphinx-gallery runs at every build, so their figures and printed numbers
come from the code as it is; the outputs reference, the command help and the API pages are
generated from the code (docs/_ext/pendular_docs.py).
"""

import json
import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "_ext"))

from pendular.utils.version import software_version  # noqa: E402

project = "pendular"
author = "the pendular developers"
copyright = "the pendular developers, MIT licence"
release = software_version()
version = release

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "sphinx_gallery.gen_gallery",
    "pendular_docs",
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
# the generated tables and help are included by outputs.md and commands.md, not pages of their own
exclude_patterns = ["_build", "**/GALLERY_HEADER.rst", "tutorials/runs", "Thumbs.db",
                    ".DS_Store", "_generated/outputs_tables.md", "_generated/commands.md"]

# MyST: headings get anchors (links such as yade_crosscheck.md#periodic-cell), ::: fences
myst_enable_extensions = ["colon_fence", "deflist", "substitution"]
myst_heading_anchors = 3
# numbers measured by the scripts of docs/figures (make_*.py), each written with its figures
# into a JSON beside them: a page quotes {{ readme_peak_q_kpa }}, never a copy of the number
myst_substitutions = {}
for _name in sorted(os.listdir(os.path.join(HERE, "figures"))):
    if _name.endswith(".json"):
        with open(os.path.join(HERE, "figures", _name), encoding="utf-8") as _numbers:
            myst_substitutions.update(json.load(_numbers).get("substitutions", {}))

# autodoc: the docstrings are short plain text with units, not numpydoc or Google sections, so
# napoleon is left out (it would read "name: text" lines of attribute docs as types); members in
# source order
autodoc_member_order = "bysource"
autodoc_typehints = "signature"
autodoc_default_options = {"undoc-members": False}
# the API's functions and classes stay out of the tables of contents (the API pages list each
# module's section there): the theme draws the whole site's tree into every page, and with an
# entry per object that tree took half of each build; the search and the index still hold them
toc_object_entries = False

# sphinx-gallery: every script of docs/tutorials and examples/ runs at each build, at the
# small sizes they set (a few seconds to half a minute each on the 2-core machine), one per
# core side by side (their samples are small enough to run on one Numba thread); the first
# tutorial runs alone before the others, as the second reads its run folder
# (``sphinx_gallery_parallel = False`` in it)
sphinx_gallery_conf = {
    "examples_dirs": ["tutorials", os.path.join("..", "examples")],
    "gallery_dirs": ["auto_tutorials", "auto_examples"],
    "filename_pattern": r".*\.py",
    "within_subsection_order": "FileNameSortKey",
    "abort_on_example_error": True,
    "download_all_examples": False,
    "remove_config_comments": True,
    "image_scrapers": ("matplotlib",),
    "matplotlib_animations": False,
    "capture_repr": ("_repr_html_", "__repr__"),
    "show_memory": False,
    "show_signature": False,
    "plot_gallery": "True",
    "parallel": max(1, min(4, len(os.sched_getaffinity(0)))),
}

html_theme = "furo"
html_title = f"pendular {release}"
html_static_path = []
html_theme_options = {"navigation_with_keys": True}

# The docstrings are plain text (the style guide's short docstrings with units), read here as
# reST with two conventions of their own made explicit:
# - |x| is a norm, never a reST substitution: the bars are escaped outside inline literals;
# - a hanging indent ("name: text" and its continuation lines indented further) continues the
#   line above it; reST would read it as a definition list or a block quote and warn. Lines of
#   a literal block (after "::") and of a list item (indented to the item's text) are kept.
_LITERAL = re.compile(r"(``.*?``)")
_ITEM = re.compile(r"\s*(?:[-*+]|\d+[.)])\s+")


def _plain_bars(app, what, name, obj, options, lines):
    for index, line in enumerate(lines):
        if "|" in line:
            lines[index] = "".join(part if part.startswith("``") else part.replace("|", r"\|")
                                   for part in _LITERAL.split(line))


def _hanging_indents(app, what, name, obj, options, lines):
    literal = start = text = None      # indentations: literal block's parent, item, item's text
    for index, line in enumerate(lines):
        if not line.strip():
            start = None
            continue
        indent = len(line) - len(line.lstrip())
        if literal is not None and indent > literal:
            continue
        literal = None
        if start is None or indent <= start:
            item = _ITEM.match(line)
            start, text = indent, item.end() if item else indent
        elif indent != text:
            lines[index] = " " * text + line.lstrip()
        if line.rstrip().endswith("::"):
            literal = start


def setup(app):
    app.connect("autodoc-process-docstring", _plain_bars)
    app.connect("autodoc-process-docstring", _hanging_indents)

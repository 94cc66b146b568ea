# Sphinx configuration of the API reference: `make docs` builds it into build/docs.
# It documents the installed package (the one `make` installs) from its docstrings.
import principled_brdf

project = "principled-brdf"
author = "principled-brdf contributors"
release = principled_brdf.__version__
version = release

extensions = ["sphinx.ext.autodoc", "sphinx.ext.napoleon"]
root_doc = "index"
exclude_patterns = ["_build"]

autodoc_default_options = {"members": True, "member-order": "bysource"}
autodoc_typehints = "description"      # types under Parameters rather than in long signatures
autodoc_preserve_defaults = True       # defaults as written (1 << 16, not 65536)
autoclass_content = "both"             # a class's docstring and its __init__'s
napoleon_google_docstring = False
napoleon_numpy_docstring = True

html_theme = "alabaster"
html_title = f"principled-brdf {release}: API reference"
html_theme_options = {"nosidebar": False}


def _literal_block_after_summary(app, what, name, obj, options, lines):
    """A summary line ending in ``::`` whose block is indented like the rest of the
    docstring loses the block once the docstring is dedented (the summary line has
    no indentation of its own); indent that block so it renders as the literal block
    it is meant to be."""
    if len(lines) > 2 and lines[0].rstrip().endswith("::") and not lines[1].strip() and lines[2][:1] not in " \t":
        for i in range(2, len(lines)):
            if not lines[i].strip():
                break
            lines[i] = "    " + lines[i]


def setup(app):
    app.connect("autodoc-process-docstring", _literal_block_after_summary)

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


"""Sphinx configuration of softgym's documentation site (built offline, warnings as errors).

Build: ``pip install -e ".[docs]" && sphinx-build -W -b html docs docs/_build/html``.
"""

import sys
from importlib.metadata import version as _version
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent / "_ext"))

project = "softgym"
author = "softgym developers"
copyright = "softgym developers, MIT licence"  # noqa: A001
release = _version("softgym")  # pyproject.toml is the one place
version = release

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.viewcode",
    "softgym_tasks",  # docs/_ext: one page per task, generated from the registry
]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build", "_ext", "figures", "study/claims.json"]
myst_heading_anchors = 3
myst_enable_extensions = ["colon_fence"]

# numpydoc docstrings through napoleon; members in source order, no network
autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_default_options = {"show-inheritance": True}
napoleon_google_docstring = False
napoleon_numpy_docstring = True
napoleon_use_rtype = False
# the env docstrings' Gymnasium sections (Gymnasium's cartpole: Description, Action Space,
# ... Version History), rendered as headed sections like numpydoc's Notes
napoleon_custom_sections = [
    "Description", "Action Space", "Observation Space", "Rewards", "Starting State",
    "Episode End", "Info", "Version History",
]  # fmt: skip
nitpicky = False
# An unqualified name in a numpydoc type ("ndarray, shape (n, 3)", "Terrain") may match an
# object documented both where it is defined and where a package re-exports it: Sphinx
# then links the first and warns; the warning is about ambiguity, not a broken page.
suppress_warnings = ["ref.python"]

html_theme = "alabaster"
html_title = f"softgym {release}"
html_static_path = []

# docs/PHYSICS.md (the physics, written on its own branch) joins the engine's toctree
# where it exists: index.md lists the placeholder PHYSICS_IF_PRESENT.
_PHYSICS = Path(__file__).parent / "PHYSICS.md"


def _physics_in_toctree(app, docname, source):
    if docname == "index":
        source[0] = source[0].replace(
            "PHYSICS_IF_PRESENT\n", "PHYSICS\n" if _PHYSICS.exists() else ""
        )


def setup(app):
    """Sphinx hooks of this configuration."""
    app.connect("source-read", _physics_in_toctree)

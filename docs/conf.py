"""Sphinx configuration of the manakov documentation site.

Build it with ``bash .ci/docs`` (installs the ``docs`` extra, runs the doctests and
``sphinx-build -W --keep-going -n``). The tutorials are MyST-NB notebooks, executed
at every build; the API reference is generated from the numpydoc docstrings.
"""

from __future__ import annotations

import os
import shutil
import sys

import manakov

project = "manakov"
author = "the manakov developers"
copyright = "the manakov developers"
version = release = manakov.__version__

extensions = [
    "myst_nb",  # MyST Markdown pages and text-based notebooks executed at build
    "numpydoc",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx_copybutton",
]

source_suffix = {".rst": "restructuredtext", ".md": "myst-nb", ".ipynb": "myst-nb"}
root_doc = "index"
exclude_patterns = ["_build", "_generated/*.md", "jupyter_execute", ".jupyter_cache"]
templates_path = ["_templates"]

# Every reference must resolve: a broken cross-reference is a warning, and the
# build runs with -W (warnings are errors).
nitpicky = True
# Names that appear as types in numpydoc "Parameters" sections are plain text
# (numpydoc_xref_param_type is off), so nothing needs ignoring but the Python
# builtins that autodoc writes into signatures of exceptions.
nitpick_ignore: list[tuple[str, str]] = []

# --- MyST and MyST-NB --------------------------------------------------------
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 3
myst_dmath_double_inline = True
# Notebooks run at every build, in order, and a cell that raises fails the build.
nb_execution_mode = "force"
nb_execution_timeout = 120
nb_execution_raise_on_error = True
nb_execution_show_tb = True
nb_merge_streams = True
nb_execution_excludepatterns: list[str] = []

# --- autodoc, autosummary, numpydoc ------------------------------------------
autosummary_generate = True
autosummary_imported_members = True
autodoc_typehints = "none"  # the numpydoc sections carry the types
autodoc_default_options = {"members": True, "inherited-members": False}
autoclass_content = "class"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
numpydoc_attributes_as_param_list = True

# --- HTML --------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"manakov {release}"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
}
html_static_path: list[str] = []
html_last_updated_fmt = None

# Matplotlib in notebooks: no GUI backend on a build machine.
os.environ.setdefault("MPLBACKEND", "Agg")


# --- API reference pages -------------------------------------------------------
# One page per public module, written here from the modules' ``__all__`` so that
# every public name is in the reference (a name added to ``__all__`` appears at the
# next build; tests/test_docs.py checks the list of modules). Names re-exported by
# the package are documented once, under ``manakov.<name>``, and the submodule's
# page points there.
PUBLIC_MODULES = [
    ("manakov.problems", "Built-in tops and problem files"),
    ("manakov.top", "The top: Frahm's equations (1)-(7)"),
    ("manakov.integrate", "Integrators and trajectories"),
    ("manakov.theta", "Theta functions (34)-(36)"),
    ("manakov.riemann", "Hyperelliptic curves: periods, Abel map, inversion"),
    ("manakov.curve", "The curve (8) and the Wurzelfunktionen (27)-(33)"),
    ("manakov.reduction", "Schottky-Kötter reduction (11)-(26), (37)-(42)"),
    ("manakov.solution", "The Theorem (9)-(10)"),
    ("manakov.tori", "Real tori, frequencies and frequency maps"),
    ("manakov.fluid", "A rigid body in an ideal fluid"),
    ("manakov.plots", "Figures"),
    ("manakov.cli", "The command line"),
]


def _write_api_pages(app, config) -> None:  # noqa: ARG001 (Sphinx passes them)
    import importlib
    from pathlib import Path

    here = Path(__file__).resolve().parent / "api"
    here.mkdir(exist_ok=True)
    # autosummary writes stubs but never removes one whose name left __all__.
    shutil.rmtree(here / "generated", ignore_errors=True)
    top = {name: getattr(manakov, name) for name in manakov.__all__}
    top_names = {f"manakov.{name}" for name in top}

    def section(title: str, names: list[str], template: str | None) -> str:
        if not names:
            return ""
        opts = "   :toctree: generated\n" + (f"   :template: {template}\n" if template else "")
        body = "".join(f"   {n}\n" for n in names)
        return f"{title}\n{'-' * len(title)}\n\n.. autosummary::\n{opts}\n{body}\n"

    def split(mod, names):
        import inspect

        classes = [n for n in names if inspect.isclass(getattr(mod, n))]
        funcs = [n for n in names if n not in classes and callable(getattr(mod, n))]
        data = [n for n in names if n not in classes and n not in funcs]
        return classes, funcs, data

    def page(modname: str, title: str, names: list[str], also: list[str]) -> str:
        mod = importlib.import_module(modname)
        classes, funcs, data = split(mod, names)
        head = f"``{modname}``: {title}"
        text = f".. This page is written by docs/conf.py at every build.\n\n{head}\n"
        text += "=" * len(head) + "\n\n"
        # manakov.theta is both a module and the package's function theta: the
        # function keeps the name, the module page is not indexed.
        noindex = "   :no-index:\n" if modname in top_names else ""
        text += f".. automodule:: {modname}\n   :no-members:\n{noindex}\n"
        text += f".. currentmodule:: {modname}\n\n"
        text += section("Classes", classes, "class.rst")
        # autosummary would import "manakov.theta" as the module of that name:
        # the package's function theta is documented directly instead.
        shadowed = [n for n in funcs if f"{modname}.{n}" in sys.modules]
        text += section("Functions", [n for n in funcs if n not in shadowed], None)
        for n in shadowed:
            text += f".. autofunction:: {n}\n\n"
        text += section("Constants", data, None)
        if also:
            refs = ", ".join(f":obj:`manakov.{n}`" for n in also)
            text += f"Also in this module\n{'-' * 19}\n\n"
            text += f"Re-exported by the package and documented there: {refs}.\n"
        return text

    pages = {"manakov": page("manakov", "the package", list(manakov.__all__), [])}
    for modname, title in PUBLIC_MODULES:
        mod = importlib.import_module(modname)
        names = list(getattr(mod, "__all__", []))
        if modname == "manakov.cli":
            names = ["main", "Command", "COMMANDS"]
        own = [n for n in names if not (n in top and top[n] is getattr(mod, n))]
        also = [n for n in names if n not in own]
        pages[modname] = page(modname, title, own, also)
    for modname, text in pages.items():
        path = here / f"{modname}.rst"
        if not path.exists() or path.read_text() != text:
            path.write_text(text)


def _resolve_short_names(app, env, node, contnode):
    """Resolve a docstring's short reference (``STATUS_NAMES``, ``Solution.constants``).

    The docstrings name things as their own module sees them; on the site a
    re-exported object is documented under ``manakov.<name>``, so its docstring's
    short names are looked up in the package and in every public module.
    """
    if node.get("refdomain") != "py":
        return None
    target = node["reftarget"].lstrip("~.")
    domain = env.get_domain("py")
    candidates = [f"manakov.{target}"] + [f"{m}.{target}" for m, _ in PUBLIC_MODULES]
    for name in candidates:
        if name in domain.objects:
            found = domain.resolve_any_xref(env, node["refdoc"], app.builder, name, node, contnode)
            if found:
                return found[0][1]
    return None


def setup(app):
    app.connect("config-inited", _write_api_pages)
    app.connect("missing-reference", _resolve_short_names)

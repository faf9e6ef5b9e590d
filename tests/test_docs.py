"""The documentation site covers the whole public API.

docs/conf.py writes one API page per public module from its ``__all__``; this
checks that its list of modules is every public module of the package, so that a
new module cannot be left out of the reference.
"""

import importlib.util
from pathlib import Path

import manakov

DOCS = Path(__file__).resolve().parents[1] / "docs"


def _conf():
    spec = importlib.util.spec_from_file_location("docs_conf", DOCS / "conf.py")
    assert spec is not None and spec.loader is not None
    conf = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(conf)
    return conf


def test_every_public_module_has_an_api_page():
    package = Path(manakov.__file__).parent
    public = {
        f"manakov.{p.stem}"
        for p in package.glob("*.py")
        if not p.stem.startswith("_") and p.stem != "__main__"
    }
    documented = {name for name, _ in _conf().PUBLIC_MODULES}
    assert public == documented


def test_every_page_is_in_the_site():
    index = (DOCS / "index.md").read_text(encoding="utf-8")
    pages = {p.stem for p in DOCS.glob("*.md")}
    missing = [p for p in sorted(pages) if p != "index" and f"\n{p}\n" not in index]
    assert not missing, f"pages not in the toctree of docs/index.md: {missing}"

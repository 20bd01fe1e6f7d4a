"""The documentation site's configuration (mkdocs.yml; `make docs` builds it, strict, in CI): every page in
docs/ is in the navigation and every navigation entry is a page, the API reference covers the public
modules, and the home page (the README) keeps its links into docs/ working on the site."""
from __future__ import annotations

import importlib.util
import re
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
CONFIG = yaml.safe_load((ROOT / "mkdocs.yml").read_text(encoding="utf-8"))

#: Public modules and names every build must document (an API page holds ``::: NAME`` for each).
DOCUMENTED = ["infomarket.simulate", "infomarket.Simulation", "infomarket.load_experiment",
              "infomarket.register_behaviour", "infomarket.register_payment", "infomarket.config",
              "infomarket.registry", "infomarket.checks", "infomarket.store", "infomarket.behaviours.api",
              "infomarket.behaviours.market", "infomarket.payments", "infomarket.rl.envs",
              "infomarket.rl.parallel", "infomarket.errors"]


def _nav_pages(node) -> list[str]:
    if isinstance(node, str):
        return [node]
    if isinstance(node, list):
        return [p for item in node for p in _nav_pages(item)]
    if isinstance(node, dict):
        return [p for value in node.values() for p in _nav_pages(value)]
    raise TypeError(node)


def test_navigation_lists_every_page_of_docs_and_nothing_else():
    pages = {p.relative_to(DOCS).as_posix() for p in DOCS.rglob("*.md")}
    nav = _nav_pages(CONFIG["nav"])
    assert len(nav) == len(set(nav)), "a page is listed twice"
    assert "index.md" in nav  # the home page: the README, added by the build (tools/docs/hooks.py)
    assert set(nav) - {"index.md"} == pages


def test_the_build_is_strict_and_reads_google_style_docstrings():
    assert CONFIG["strict"] is True
    (mkdocstrings,) = [p["mkdocstrings"] for p in CONFIG["plugins"] if isinstance(p, dict) and "mkdocstrings" in p]
    assert mkdocstrings["handlers"]["python"]["options"]["docstring_style"] == "google"


def test_api_reference_documents_the_public_modules():
    directives = set()
    for page in (DOCS / "api").glob("*.md"):
        directives |= set(re.findall(r"^::: (\S+)$", page.read_text(encoding="utf-8"), re.MULTILINE))
    assert not set(DOCUMENTED) - directives


def _hooks():
    spec = importlib.util.spec_from_file_location("docs_hooks", ROOT / CONFIG["hooks"][0])
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_home_page_links_point_at_the_site_pages():
    home = _hooks().readme_as_home("[m](docs/model.md) and ![i](docs/images/terrain.png) [x](https://a/docs/y)")
    assert home == "[m](model.md) and ![i](images/terrain.png) [x](https://a/docs/y)"


def test_readme_links_the_site_pages():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    linked = set(re.findall(r"\]\(docs/([^)#]+\.md)", readme))
    top_pages = {p.name for p in DOCS.glob("*.md")}
    assert top_pages <= linked
    assert "api/infomarket.md" in linked
    for page in linked:
        assert (DOCS / page).is_file(), page

"""MkDocs hooks for the documentation site (mkdocs.yml names this file).

The home page is the README itself, so the project's front page and the site's never drift apart: it is
added to the site as ``index.md`` when the site is built, with its links into ``docs/`` made relative to
the site (``docs/model.md`` -> ``model.md``).  Any other link the README makes to a file outside docs/
stays as it is, and the strict build reports it as a broken link.
"""
from __future__ import annotations

import re
from pathlib import Path

#: A Markdown link or image target that starts with docs/ (the README's links into the documentation).
_DOCS_LINK = re.compile(r"(\]\()docs/")


def readme_as_home(readme: str) -> str:
    """The README's text with its links into docs/ pointing at the site's pages."""
    return _DOCS_LINK.sub(r"\1", readme)


def on_files(files, config):
    """Add the README to the site as its home page (index.md)."""
    # imported here, so the tests can import readme_as_home without mkdocs installed
    from mkdocs.structure.files import File

    readme = Path(config["config_file_path"]).parent / "README.md"
    if files.get_file_from_path("index.md") is None:
        files.append(File.generated(config, "index.md", content=readme_as_home(readme.read_text(encoding="utf-8"))))
    return files

"""`infomarket list`: columns aligned whatever a name's length, descriptions wrapped in full, never cut
mid-sentence (issue 21: long names pushed their row out of line, and an experiment's description was the
first line of its file's comment, cut mid-sentence)."""
from __future__ import annotations

import re
import tomllib

from infomarket.cli import main
from infomarket.config import shipped_experiments
from infomarket.registry import behaviours, payments


def _listing(capsys) -> str:
    assert main(["list"]) == 0
    return capsys.readouterr().out


def _flat(text: str) -> str:
    return re.sub(r"\s+", " ", text)


def test_every_description_is_printed_in_full(capsys):
    out = _listing(capsys)
    # a wrapped description reads back whole once its column is taken line by line
    sections = out.split("\n\n")
    exps = next(s for s in sections if s.lstrip().startswith("shipped experiments"))
    start = exps.splitlines()[1].index("description")
    column = _flat(" ".join(line[start:] for line in exps.splitlines()[3:]))
    for name, path in shipped_experiments().items():
        description = tomllib.loads(path.read_text())["description"]
        assert _flat(description) in column, name
    for title, specs in (("behaviours", behaviours()), ("payment schemes", payments())):
        section = next(s for s in sections if s.lstrip().startswith(title)).splitlines()
        a, b = section[1].index("description"), section[1].index("parameters")
        column = _flat(" ".join(line[a:b] for line in section[3:]))
        for spec in specs.values():
            assert _flat(spec.description) in column, spec.name


def test_columns_line_up_whatever_the_names_length(capsys):
    out = _listing(capsys)
    section = next(s for s in out.split("\n\n") if s.lstrip().startswith("behaviours"))
    lines = section.splitlines()
    header = lines[1]
    robots_at, description_at = header.index("robots"), header.index("description")
    names = set(behaviours())
    rows = [ln for ln in lines[3:] if ln.split() and ln.split()[0] in names]
    assert len(rows) == len(names)
    for row in rows:
        assert row[robots_at:].split()[0] in ("honest", "byzantine"), row
        assert row[robots_at - 1] == " " and row[description_at - 1] == " ", row
        name = row.split()[0]
        assert row.index(name) == 0 and len(name) < robots_at  # the name stays in its column

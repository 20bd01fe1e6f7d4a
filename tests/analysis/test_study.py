"""The declared-study pipeline (analysis.study): a declaration file's record of amendments and deviations
is read, checked and printed in every report of its study, and it is no declaration (a store's lock check
leaves it out)."""
from __future__ import annotations

import copy

import pandas as pd
import pytest

from infomarket.analysis import chain_study, future, sensitivity_report, study, terrain
from infomarket.analysis.declared import ADDED, DECLARED, EDITED
from infomarket.analysis.report import TOLERANCES
from infomarket.errors import ConfigError
from infomarket.search.study import DECLARATION as SEARCH
from infomarket.store.declarations import fingerprint_file

FILE = """[questions.q1]
question = "Does it?"
rule = "p < 0.05"

[[amendments]]
date = "2026-01-02 10:00 UTC"
seen = "before any result"
questions = ["q1"]
what = "alpha 0.05 instead of 0.1."
why = "The field's convention."

[[deviations]]
date = "2026-01-03"
seen = "after the first runs"
what = "12 runs per condition, not 24."
why = "The machine was slower than planned."
"""


def test_the_record_is_printed_whole_and_in_order(tmp_path):
    (tmp_path / "q.toml").write_text(FILE)
    d = study.Declaration.read(tmp_path / "q.toml")
    assert [r.kind for r in d.records()] == ["amendment", "deviation"]
    assert d.record_markdown() == [
        "## Amendments and deviations (q.toml)", "",
        "- **Amendment, 2026-01-02 10:00 UTC** (q1), before any result: alpha 0.05 instead of 0.1. *Why:* The "
        "field's convention.",
        "- **Deviation, 2026-01-03**, after the first runs: 12 runs per condition, not 24. *Why:* The machine was "
        "slower than planned.", ""]
    assert "<li>Deviation, 2026-01-03, after the first runs: 12 runs per condition" in d.record_html()


def test_a_file_without_a_record_says_so(tmp_path):
    (tmp_path / "q.toml").write_text(FILE.split("[[amendments]]")[0])
    record = study.Declaration.read(tmp_path / "q.toml").record_markdown()
    assert record[2] == "q.toml records none: the study ran as declared."


@pytest.mark.parametrize("old, new, words", [
    ('why = "The field\'s convention."', "", "q.toml: amendments[0] lacks why"),
    ('seen = "after the first runs"', "", "q.toml: deviations[0] lacks seen"),
    ('what = "alpha', 'when = "x"\nwhat = "alpha', "q.toml: amendments[0]: unknown key 'when'; allowed: date, seen")])
def test_a_malformed_record_is_refused_naming_it(tmp_path, old, new, words):
    (tmp_path / "q.toml").write_text(FILE.replace(old, new))
    with pytest.raises(ConfigError) as e:
        study.Declaration.read(tmp_path / "q.toml")
    assert words in str(e.value)


def test_the_record_is_no_declaration_for_the_lock_check(tmp_path):
    """A store recorded before the file had a record: every declaration still reads as declared; an
    edited rule still reads as edited."""
    (tmp_path / "q.toml").write_text(FILE)
    d = study.Declaration.read(tmp_path / "q.toml")
    now = fingerprint_file(d.path)
    before = copy.deepcopy(now)
    for key in ("amendments", "deviations"):
        before["sections"].pop(key)
    assert {(lk.section, lk.status) for lk in d.locks({"q.toml": before})} == {("questions.q1", DECLARED)}
    before["sections"]["questions.q1"] = "0" * 64
    assert {lk.status for lk in d.locks({"q.toml": before})} == {EDITED}
    before["sections"].pop("questions.q1")
    assert {lk.status for lk in d.locks({"q.toml": before})} == {ADDED}


SHIPPED = {"chain": chain_study.DECLARATION, "terrain": terrain.DECLARATION,
           "sensitivity": sensitivity_report.DECLARATION, "tolerances": TOLERANCES, "search": SEARCH}


@pytest.mark.parametrize("name", SHIPPED)
def test_every_shipped_study_records_its_history_in_fields(name):
    records = SHIPPED[name].records()
    assert records and all(r.date[:4] == "2026" and r.what and r.why for r in records)


def test_the_chain_report_prints_every_amendment_and_deviation():
    md = chain_study.markdown(chain_study.answer(pd.DataFrame(columns=["experiment"])))
    for r in chain_study.DECLARATION.records():
        assert r.markdown() in md
    assert md.count("- **Amendment, ") == 2 and md.count("- **Deviation, ") == 4


def test_the_shipped_records_are_printed_by_their_reports(paper_report):
    _, out, _ = paper_report
    md = (out / "report.md").read_text()
    assert all(r.markdown() in md for r in TOLERANCES.records()) and md.count("- **Amendment, ") == 3
    assert "Amendments and deviations (tolerances.toml)" in (out / "report.html").read_text()
    assert "issue" not in md.lower()


def test_md_and_html_tables():
    df = pd.DataFrame({"a": ["x|y"], "verdict": ["inconclusive (n too small)"]})
    assert study.md_table(df) == "| a | verdict |\n|---|---|\n| x\\|y | inconclusive (n too small) |"
    assert '<tr class="inconclusive"><td>x|y</td>' in study.html_table(df, verdicts=True)


def test_out_must_be_a_folder(tmp_path):
    (tmp_path / "f").write_text("")
    with pytest.raises(study.UsageError, match="exists and is not a directory"):
        study.out_dir(tmp_path / "f")
    files = study.write(tmp_path / "o", "s", "# md\n", table=pd.DataFrame({"a": [1]}), extra=[("s.json", "{}")])
    assert [f.name for f in files] == ["s.md", "s.csv", "s.json"] and (tmp_path / "o" / "s.csv").read_text() == "a\n1\n"


def test_out_is_checked_once_for_every_study_command(tmp_path):
    with pytest.raises(study.UsageError, match=r"^attack-search needs --out FOLDER \(the store and the report go"):
        study.out_dir(None, "attack-search")
    with pytest.raises(study.UsageError, match=r"^--out ' ': give a folder for the checkpoint"):
        study.out_dir(" ", holds="the checkpoint")
    with pytest.raises(study.UsageError, match=r"^--questions .*nope.toml: no such file$"):
        study.questions_path(str(tmp_path / "nope.toml"), tmp_path)
    assert study.questions_path(None, tmp_path / "shipped.toml") == tmp_path / "shipped.toml"
    study.refuse_declared_seed(7, 7, [])  # the whole declared study may use its seed
    with pytest.raises(study.UsageError,
                       match=r"^--seed 7 is the declared study.s own; this run differs in 2 of 4 cells"):
        study.refuse_declared_seed(7, 7, ["2 of 4 cells"])


def test_a_report_is_written_whole_or_not_at_all(tmp_path):
    """Each part by its kind; a part that fails leaves the files before it, no half-written file and no
    temporary one behind."""
    def broken(path):
        path.write_text("half")
        raise RuntimeError("the figure failed")

    frame = pd.DataFrame({"a": [1, 2]})
    report = study.Report([("r.md", "# é\n"), ("r.parquet", frame), ("r.png", broken)])
    with pytest.raises(RuntimeError, match="the figure failed"):
        report.write(tmp_path / "o")
    assert sorted(p.name for p in (tmp_path / "o").iterdir()) == ["r.md", "r.parquet"]
    assert (tmp_path / "o" / "r.md").read_bytes() == "# é\n".encode()
    assert pd.read_parquet(tmp_path / "o" / "r.parquet").equals(frame)


def test_the_settings_parser_names_the_key_and_what_it_expects():
    from dataclasses import dataclass

    @dataclass(frozen=True)
    class Plan:
        runs: int = 8
        share: float = 0.5
        paired: bool = True

    rules = {"whole": {"runs": 2}, "flags": ("paired",), "numbers": (("share", 0.0, 1.0),)}
    assert study.settings(Plan, {"runs": 4}, {"runs": 16, "share": None}, "q.toml [plan]", **rules) == Plan(16)
    head = "q.toml [plan]: invalid settings\n  "
    for table, message in (({"run": 4}, "run: unknown key; allowed keys here: runs, share, paired"),
                           ({"runs": 1}, "runs: a whole number of at least 2 is expected (got 1)"),
                           ({"runs": True}, "runs: a whole number of at least 2 is expected (got True)"),
                           ({"paired": 1}, "paired: true or false is expected (got 1)"),
                           ({"share": 0.0}, "share: a number in (0, 1] is expected (got 0.0)"),
                           ({"share": 2, "runs": 0}, "runs: a whole number of at least 2 is expected (got 0)\n  "
                                                     "share: a number in (0, 1] is expected (got 2)")):
        with pytest.raises(study.UsageError) as err:
            study.settings(Plan, table, None, "q.toml [plan]", **rules)
        assert str(err.value) == head + message


# ------------------------------------------------------------------------------------------ verdicts
def test_a_one_sided_rule_answers_no_only_with_the_power_to_have_said_yes():
    assert study.by_power(True, 0.0) == "yes"          # met: yes whatever the power
    assert study.by_power(False, 0.80) == "no"         # not met at the target power: a finding
    assert study.by_power(False, 0.79) == "inconclusive"
    assert study.by_power(False, 0.5, target=0.5) == "no"


def test_every_study_answers_with_the_one_verdict():
    v = study.Verdict("inconclusive", note="n too small")
    assert v.shown == "inconclusive (n too small)" and study.Verdict("yes").shown == "yes"
    assert chain_study.Verdict is future.Verdict is study.Verdict
    assert chain_study.NOT_RUN == terrain.NOT_RUN == study.NOT_RUN == "not run"

"""Questions locked to the store (issue 24): the store records the declaration files' hashes when it is
created, and a report flags any rule edited (or added) after the store's first run."""
from __future__ import annotations

import json
import shutil

import pytest

from infomarket.analysis import declared, future
from infomarket.store import declarations
from infomarket.analysis.frames import Frames
from infomarket.analysis.report import build_report
from infomarket.store import Store

from .synthetic import _runs, write_store
from .test_future import rescued, sweep


@pytest.fixture
def files(tmp_path, monkeypatch):
    """Copies of the declaration files, standing in for the package's (so a test may edit them)."""
    copies = {}
    for name, path in declared.FILES.items():
        copies[name] = tmp_path / name
        shutil.copy(path, copies[name])
    monkeypatch.setattr(declarations, "FILES", copies)  # the store records them (store.declarations)
    monkeypatch.setattr(declared, "FILES", copies)
    return copies


def _edit(path, old, new):
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new, 1))


def test_a_new_store_records_every_declaration(tmp_path, files):
    store = Store(tmp_path / "s").create()
    rec = store.declarations()
    assert set(rec) == set(files)
    assert "questions.liar_recovered" in rec["tolerances.toml"]["sections"]
    assert "rows.fig2A_median" in rec["tolerances.toml"]["sections"]
    assert "questions.chain_blocked" in rec["terrain_questions.toml"]["sections"]
    assert all(lk.status == declared.DECLARED for lk in declared.check(rec))


def test_comments_are_not_edits_but_a_changed_parameter_is(tmp_path, files):
    rec = Store(tmp_path / "s").create().declarations()
    tol = files["tolerances.toml"]
    tol.write_text("# a new comment\n" + tol.read_text())
    assert all(lk.status == declared.DECLARED for lk in declared.check(rec))
    _edit(tol, "min_angles = 2", "min_angles = 1")  # liar_improved_reputation_sceptic, the first one
    locks = {(lk.file, lk.section): lk.status for lk in declared.check(rec)}
    assert locks["tolerances.toml", "questions.liar_improved_reputation_sceptic"] == declared.EDITED
    assert locks["tolerances.toml", "questions.liar_improved_adaptive_theta"] == declared.DECLARED
    _edit(tol, "[statistics]", "[questions.new_one]\nquestion = \"?\"\nrule = \"r\"\n\n[statistics]")
    locks = {(lk.file, lk.section): lk.status for lk in declared.check(rec)}
    assert locks["tolerances.toml", "questions.new_one"] == declared.ADDED


def test_a_store_whose_question_file_was_edited_after_its_first_run_is_flagged_in_the_report(tmp_path, files):
    robots = sweep(rescued)
    store = write_store(tmp_path / "store", {"future": (robots, _runs(robots, 30000, 20000,
                                                                       ("byzantines", "defence")), None)})
    table = future.question_table(Frames.of(store))
    assert (table["declared"] == declared.DECLARED).all()
    _edit(files["tolerances.toml"], 'alpha = 0.05\nmin_angles = 2\nfamily = "4 angles below Theta"',
          'alpha = 0.10\nmin_angles = 2\nfamily = "4 angles below Theta"')
    table = future.question_table(Frames.of(store)).set_index("id")
    assert table.loc["liar_improved_reputation_sceptic", "declared"] == declared.EDITED
    assert table.loc["liar_recovered", "declared"] == declared.DECLARED
    build_report(store, tmp_path / "out")
    md = (tmp_path / "out" / "report.md").read_text()
    assert "EDITED after its first run: questions.liar_improved_reputation_sceptic" in md


def test_a_store_made_before_the_record_says_it_cannot_tell(tmp_path, files):
    store = Store(tmp_path / "s").create()
    meta = store.meta()
    del meta["declarations"]
    store.meta_path.write_text(json.dumps(meta))
    assert store.declarations() is None
    locks = declared.check(store.declarations())
    assert {lk.status for lk in locks} == {declared.NOT_RECORDED}
    assert "holds no record" in declared.summary(locks, "tolerances.toml", "questions.")


def test_answering_with_another_run_count_says_so():
    assert declared.size_note(32, [32, 32]) == ""
    assert declared.size_note(32, [2, 2]) == "answered with 2 runs per condition, not the 32 declared"
    assert declared.size_note(None, [2, 2]) == ""


def test_a_paper_rule_edited_after_the_first_run_is_flagged_in_the_paper_report(tmp_path, files):
    from .synthetic import paper_like

    store = write_store(tmp_path / "store", paper_like(), only=("fig2",))
    _edit(files["tolerances.toml"], "min = 18\nmax = 22", "min = 17\nmax = 22")  # rows.fig2A_median
    build_report(store, tmp_path / "out")
    md = (tmp_path / "out" / "report.md").read_text()
    assert "EDITED after its first run: rows.fig2A_median" in md

"""A report's provenance: the code's commit and whether the tree matched it, the questions file's commit,
in a git checkout made here (commit, then a modified file, then an untracked one inside and outside the
package)."""
from infomarket.search import provenance


def _git(procs, repo, *args):
    return procs.run(["git", "-C", str(repo), *args], check=True).stdout.strip()


def test_code_commit_and_a_clean_or_modified_tree(tmp_path, procs):
    repo = tmp_path / "repo"
    pkg = repo / "src" / "pkg"
    pkg.mkdir(parents=True)
    (pkg / "mod.py").write_text("x = 1\n")
    (pkg / "questions.toml").write_text("a = 1\n")
    _git(procs, repo.parent, "init", "-q", str(repo))
    _git(procs, repo, "add", ".")
    _git(procs, repo, "-c", "user.name=t", "-c", "user.email=t@t", "commit", "-qm", "first")
    head = _git(procs, repo, "rev-parse", "HEAD")
    assert provenance.code(pkg) == {"commit": head, "tree_clean": True}
    (repo / "notes.txt").write_text("untracked, outside the package\n")
    assert provenance.code(pkg)["tree_clean"] is True
    (pkg / "new.py").write_text("y = 2\n")  # untracked code inside the package: runs no commit replays
    assert provenance.code(pkg) == {"commit": head, "tree_clean": False}
    (pkg / "new.py").unlink()
    (pkg / "mod.py").write_text("x = 2\n")
    assert provenance.code(pkg)["tree_clean"] is False
    q = provenance.questions(pkg / "questions.toml")
    assert q["questions_commit"] == head and q["questions_modified"] is False


def test_outside_a_checkout_the_commit_is_unknown(tmp_path, procs):
    (tmp_path / "q.toml").write_text("a = 1\n")
    assert provenance.code(tmp_path) == {"commit": None, "tree_clean": None}
    assert provenance.questions(tmp_path / "q.toml")["questions_commit"] is None


def test_a_study_resumed_under_other_code_names_both_commits(tmp_path, procs):
    (tmp_path / "q.toml").write_text("a = 1\n")
    h = provenance.report_header({"commit": "0" * 40, "questions_commit": "q" * 40}, tmp_path / "q.toml")
    assert h["first_run_commit"] == "0" * 40 and h["questions_commit"] == "q" * 40

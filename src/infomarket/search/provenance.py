"""Where a report's numbers come from: the code's commit (and whether the working tree matched it) and
the questions file's commit, recorded in every attack-search report.

A study's answers are only as reproducible as the code that made its runs: a reviewer who reruns a
confirmation run from its seed needs the commit, and a run made from a modified tree cannot be traced
to any commit, so the report says so (``tree_clean`` false) instead of naming a commit it did not run.
"""
from __future__ import annotations

import hashlib
import subprocess
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent.parent  # the infomarket package folder


def git(folder, *args) -> str | None:
    """``git -C folder args``'s output, or None where git or the checkout is missing."""
    try:
        out = subprocess.run(["git", "-C", str(folder), *args], capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.strip() if out.returncode == 0 else None


def code(package: Path = PACKAGE) -> dict:
    """The code's commit (None outside a git checkout) and whether the tree is clean: no tracked file
    modified and no untracked file inside the package (either would make runs no commit can replay)."""
    commit = git(package, "rev-parse", "HEAD")
    if commit is None:
        return {"commit": None, "tree_clean": None}
    tracked = git(package, "status", "--porcelain", "--untracked-files=no")
    inside = git(package, "status", "--porcelain", "--untracked-files=all", "--", ".")
    clean = tracked == "" and inside == ""
    return {"commit": commit, "tree_clean": clean}


def questions(path: Path) -> dict:
    """The questions file's identity: its last commit (``modified``: the file differs from it) and its
    SHA-256."""
    path = Path(path)
    folder = path.parent
    commit = git(folder, "log", "-1", "--format=%H", "--", path.name) or None
    modified = bool(git(folder, "status", "--porcelain", "--", path.name)) if commit else None
    return {"questions_file": path.name, "questions_commit": commit, "questions_modified": modified,
            "questions_sha256": hashlib.sha256(path.read_bytes()).hexdigest()}


def report_header(first: dict | None, questions_path: Path) -> dict:
    """What every report records at its top: the code's commit now (the code that wrote it and made this
    invocation's runs), the questions file's commit, and the store's record of the first run (its code
    commit and time), so a study resumed under other code shows both."""
    first = dict(first or {})
    now = code()
    q = questions(questions_path)
    out = {"commit": now["commit"], "tree_clean": now["tree_clean"],
           "questions_commit": first.get("questions_commit", q["questions_commit"]),
           "questions_modified": first.get("questions_modified", q["questions_modified"])}
    if first.get("commit") and first.get("commit") != now["commit"]:
        out["first_run_commit"] = first["commit"]
    return out

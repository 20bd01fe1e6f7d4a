"""The commands that README.md and docs/*.md show are real: each one is parsed by the CLI's own parser
(so a renamed command or option fails here), and run: the cheap ones as written, the others with only
their size changed (SMALL, REDUCED).  Every console line must be listed below, as run, as run at a
reduced size, or as not run with the reason, so a new or edited command needs a decision."""
from __future__ import annotations

import json
import re
import shlex
import shutil
import sys
from pathlib import Path

import pytest

from infomarket.cli import build_parser, main

ROOT = Path(__file__).parents[1]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]

#: Run as written (in a scratch folder holding README's minimal experiment file as my.toml).
RUN = {
    "infomarket list",
    "infomarket check my.toml",
    "infomarket check corridor",
    "infomarket check corridor_waypoints",
    "infomarket check attack_search",
    "infomarket check chain_paper",
    "infomarket defence-search attack_search --list-families",
}
#: Parsed only, with the reason they are not run here.
NOT_RUN = {
    "make demo": "the same as `infomarket demo`, run with --runs 1 in tests/test_commands.py",
    "make test": "the test suite itself",
    "infomarket run path/to/original/fig4C.json": "a placeholder path; the format is tested in tests/config",
    "infomarket reproduce paper --out results/paper": "the whole paper (2 656 runs)",
    "infomarket reproduce paper --out /tmp/quick --scale 0.125": "332 runs; --scale: tests/test_commands.py",
    "infomarket reproduce paper --out results/paper --scale 0.125": "332 runs, as above",
    "infomarket sweep fig7 --out results/fig7 --dask-local 4": "1 280 runs on a Dask cluster",
    "infomarket sweep fig7 --out results/fig7": "1 280 runs",
    "infomarket sweep my.toml --out store --dask-local 4": "16 full runs on a Dask cluster",
    "infomarket sweep my.toml --out store --scheduler tcp://head:8786": "needs a Dask scheduler at that address",
    "infomarket chain demo --robots 25 --steps 15000 --scheme staking":
        "a paper-length replay on the EVM (revm, cold storage: 86 s CPU, 7 min wall on the busy machine, "
        "2026-11-24); tests/evm/test_cli.py runs short ones",
    "infomarket chain demo --chain-period 5":
        "a 3 000-step chain run replayed block by block (~15 s); tests/evm/test_block_replay.py runs this very command",
    "infomarket ros swarm fig4C --robots 6 --steps 2000 --seed 3 --out runs/ros6":
        "six agent processes and a chain node for minutes; tests/ros/test_swarm.py runs three agents",
    "infomarket ros swarm fig4C --robots 6 --steps 2000 --seed 3 --out runs/kill --fault kill:2@800":
        "as above; tests/ros/test_swarm.py kills an agent in the middle of a sale",
    "infomarket ros swarm fig4C --robots 6 --steps 2000 --seed 3 --out runs/drop --fault drop:0.05":
        "as above; tests/ros/test_swarm.py drops a fifth of the agents' messages",
    "infomarket ros swarm fig4C --robots 3 --steps 750 --seed 18 --out runs/declined --controlled all "
    "--agents-per-process 3": "needs the example controller running; tests/ros/test_controller.py runs it",
    "infomarket ros swarm fig4C --robots 25 --steps 300 --seed 3 --agents-per-process 5 --out runs/at-once":
        "25 agents in 5 processes and a chain node for minutes; tests/ros/test_schedule.py checks the rule",
    "infomarket ros swarm fig4C --robots 25 --steps 300 --seed 3 --agents-per-process 5 --out runs/in-order "
    "--parallel-trades 1 --window 0": "as above, trades one at a time (the lock step tests/ros/test_swarm.py runs)",
    "infomarket ros swarm fig4C --robots 25 --steps 15000 --seed 3 --agents-per-process 5 --out runs/long":
        "hours of trades (docs/ros.md estimates 3 to 5); not run anywhere yet",
    "infomarket bench --scaling": "96 timed runs; tests/bench runs the same code with 2 runs of 200 steps",
    "infomarket sweep future --out results/future --workers 1":
        "4 736 runs of 30 000 steps; tests/test_commands.py plans it and its --scale",
    "infomarket sweep future --out /tmp/future-small --scale 0.0625":
        "296 runs of 30 000 steps; the plan and --scale are tested in tests/test_commands.py",
    "infomarket figures results/future --out results/future-report":
        "needs the future sweep's store; tests/analysis/test_future.py draws it from a synthetic one",
    # docs/terrain.md
    "infomarket sweep two_food --out results/two_food":
        "128 full runs; the store's sites table: tests/terrain/test_cli.py",
    "infomarket sweep corridor --out results/corridor": "128 full runs; sweeps are tested in tests/runner",
    "infomarket sweep crowd --out results/crowd": "128 full runs (100 robots); sweeps are tested in tests/runner",
    "infomarket terrain-report results --out results/terrain":
        "needs the three full stores; tests/terrain/test_report.py runs it on small ones",
    "infomarket sweep corridor_waypoints --out results/corridor_waypoints":
        "128 full runs; sweeps are tested in tests/runner, the waypoint rules in tests/terrain/test_waypoints.py",
    "infomarket view corridor": "a web server that runs until stopped; tests/viewer",
    "infomarket sweep sensitivity --out results/sensitivity --workers 2":
        "the full study, 5 120 runs (~18 min on 2 cores)",
    "infomarket sweep sensitivity_local --out results/sensitivity_local":
        "576 runs of 15 000 steps; tests/analysis/test_sensitivity.py judges a local design",
    "infomarket sensitivity results/sensitivity --out report --local results/sensitivity_local":
        "needs both full stores; tests/analysis/test_sensitivity.py runs --local on a small one",
    "infomarket sweep sensitivity --samples 16 --out /tmp/sens-quick":
        "320 runs; tests/analysis/test_sensitivity.py runs the study with --samples 2",
    "infomarket sensitivity /tmp/sens-quick --out /tmp/sens-quick-report":
        "needs the store above; tests/analysis/test_sensitivity.py runs it on --samples 2",
    # docs/research.md, the chain study
    "infomarket sweep chain_paper --out results/chain/chain_paper --workers 2":
        "432 runs (288 on the chain model); tests/analysis/test_chain_study.py answers synthetic stores",
    "infomarket sweep chain_fig7 --out results/chain/chain_fig7 --workers 2 --runs 12": "144 runs of 30 000 steps",
    "infomarket sweep chain_sweep --out results/chain/chain_sweep --workers 2 --runs 12": "336 chain runs",
    "infomarket sweep chain_fig7_sweep --out results/chain/chain_fig7_sweep --workers 2 --runs 12":
        "336 chain runs of 30 000 steps",
    "infomarket sweep chain_partition --out results/chain/chain_partition --workers 2":
        "96 chain runs (45 s); tests/ledger/test_chain_partition.py runs partitioned swarms",
    "infomarket chain-study results/chain/chain_paper results/chain/chain_fig7 results/chain/chain_sweep "
    "results/chain/chain_fig7_sweep results/chain/chain_partition --out results/chain/report":
        "needs the study's stores; tests/analysis/test_chain_study.py runs it on a synthetic one",
    # docs/attack-search.md
    "infomarket attack-search attack_search --questions src/infomarket/search/questions_v4.toml "
    "--out results/attack_search_v4": "the fourth version's declared study, about 100 000 runs",
    "infomarket attack-search attack_search --defence staking,theta20 --byzantines 3 --dask tcp://head:8786 "
    "--out results/as-dask": "needs a Dask scheduler at that address; tests/search runs one on a LocalCluster",
    # docs/defences.md
    "infomarket defence-search attack_search --out results/defence --workers 2":
        "the declared study, about 176 000 runs",
    "infomarket defence-search attack_search --family robust_median --byzantines 3 --candidates 2 --refine 0 "
    "--steps 3000 --transitory 1000 --inner-budget 4 --inner-runs 2 --inner-grid-step 90 --inner-race 2,4 "
    "--cost-runs 4 --frontier 2 --confirmation-runs 8 --seed 7 --out /tmp/defence":
        "minutes of runs; tests/defence/test_cli.py runs a tiny declared study",
}


def console_commands() -> list[tuple[str, str]]:
    """(file, command) for every line of every ```console block, without prompts, the .venv/bin/
    prefix and trailing comments."""
    out = []
    for doc in DOCS:
        for block in re.findall(r"```console\n(.*?)```", doc.read_text(), re.S):
            for line in block.splitlines():
                cmd = line.split(" #")[0].strip().removeprefix("$ ").removeprefix(".venv/bin/")
                if cmd:
                    out.append((doc.name, " ".join(shlex.split(cmd))))
    return out


COMMANDS = console_commands()


def test_every_documented_command_is_classified():
    found = {cmd for _, cmd in COMMANDS}
    assert len(found) >= 15
    unlisted = found - RUN - set(NOT_RUN) - set(REDUCED) - set(SMALL)  # SMALL: the small-run pages' own forms
    assert not unlisted, f"documented commands neither run nor listed as not run: {sorted(unlisted)}"
    assert not set(NOT_RUN) & (set(REDUCED) | set(SMALL)), "a command run at a reduced size is listed as not run"
    stale = (RUN | set(NOT_RUN) | set(REDUCED)) - found
    assert not stale, f"listed here but no longer in the docs: {sorted(stale)}"


@pytest.mark.parametrize("doc, cmd", COMMANDS, ids=[c for _, c in COMMANDS])
def test_documented_command_parses(doc, cmd):
    words = shlex.split(cmd)
    if words[0] == "make":
        targets = re.findall(r"^([\w-]+):", (ROOT / "Makefile").read_text(), re.M)
        assert words[1] in targets, f"{doc}: no make target {words[1]!r}"
        return
    assert words[0] == "infomarket", f"{doc}: {cmd}"
    build_parser().parse_args(words[1:])  # exits with status 2 on an unknown command or option


def readme_minimal_experiment() -> str:
    text = (ROOT / "README.md").read_text()
    return re.findall(r"```toml\n(.*?)```", text, re.S)[0]


@pytest.mark.parametrize("cmd", sorted(RUN))
def test_cheap_documented_command_runs(cmd, tmp_path, monkeypatch, capsys):
    (tmp_path / "my.toml").write_text(readme_minimal_experiment())
    monkeypatch.chdir(tmp_path)
    assert main(shlex.split(cmd)[1:]) == 0
    assert capsys.readouterr().out.strip()



# ------------------------------------------------------------------ docs run at a small size
#: These pages' commands are all run, each at a small size: every command they show (console blocks, plain
#: blocks, and `infomarket ...` in the text) maps here to the same command with only SIZE_OPTIONS changed
#: (and placeholders filled), run in a scratch folder.  A new or edited command there needs an entry.
SMALL_DOCS = ("attack-search.md", "rl.md", "chain-model.md")
#: Options that change how much is run, not what: a small run may set these, and nothing else.
SIZE_OPTIONS = frozenset({"steps", "transitory", "budget", "popsize", "runs", "restarts", "finalists", "race",
                          "keep", "confirmation_runs", "grid_step", "adaptive_budget", "iterations",
                          "pairs", "eval_runs", "repeats", "batch", "robots", "out", "workers", "defence",
                          "byzantines", "store", "chain_period", "validation_repeats",
                          # a reduced form of a declared study must take another seed than the study's
                          # (search/questions.toml [seed_sets]; the CLI refuses it otherwise)
                          "seed"})
TINY_SEARCH = ("--defence staking --byzantines 3 --budget 2 --popsize 2 --restarts 1 --runs 1 --finalists 1 "
               "--race 2 --confirmation-runs 2 --grid-step 90 --adaptive-budget 0 --steps 60 --transitory 20 "
               "--workers 1")
SMALL = {
    "infomarket attack-search --validate --questions src/infomarket/search/questions_v3.toml --kinds trust_gate "
    "--validation-repeats 1":
        "infomarket attack-search --validate --questions src/infomarket/search/questions_v3.toml --kinds trust_gate "
        "--validation-repeats 1 --budget 24 --popsize 4 --runs 2 --race 2,4 --grid-step 90",
    "infomarket attack-search --validate --questions src/infomarket/search/questions_v3.toml":
        "infomarket attack-search --validate --questions src/infomarket/search/questions_v3.toml "
        "--validation-repeats 1 --budget 24 --popsize 4 --runs 2 --race 2,4 --grid-step 90",
    "infomarket check attack_search": "infomarket check attack_search",
    "infomarket check chain_partition": "infomarket check chain_partition",
    "infomarket attack-search attack_search --out results/attack_search":
        f"infomarket attack-search attack_search {TINY_SEARCH} --seed 7 --out as",
    "infomarket attack-search attack_search --defence staking --byzantines 3 --budget 48 --runs 4 "
    "--confirmation-runs 16 --seed 7 --out /tmp/attack-reduced":
        f"infomarket attack-search attack_search {TINY_SEARCH} --seed 7 --out as",
    "infomarket bench --env --json": "infomarket bench --env --json --steps 60 --repeats 1 --batch 2",
    "infomarket rl-train --steps 4000 --transitory 1000 --iterations 60 --pairs 32 --eval-runs 32 --seed 0 "
    "--out rl-train.json": "infomarket rl-train --steps 60 --transitory 20 --iterations 1 --pairs 1 --eval-runs 2 "
                           "--seed 0 --out rl-train.json",
    "infomarket rl-train --steps 10000 --transitory 5000 --iterations 60 --pairs 16 --eval-runs 32 --seed 0":
        "infomarket rl-train --steps 60 --transitory 20 --iterations 1 --pairs 1 --eval-runs 2 --seed 0",
    "infomarket bench": "infomarket bench --steps 40 --repeats 1",
    "infomarket bench --steps 15000": "infomarket bench --steps 40 --repeats 1",
    "infomarket bench --robots 25,250,2500,10000 --steps 1000 --chain":
        "infomarket bench --robots 25,30 --steps 40 --chain",
    "infomarket store sql STORE 'SELECT * FROM chain'": "infomarket store sql chainstore 'SELECT * FROM chain'",
    "infomarket store verify DIR/store": "infomarket store verify chainstore",
    "infomarket bench --env": "infomarket bench --env --steps 60 --repeats 1 --batch 2",
    "infomarket rl-train": "infomarket rl-train --steps 60 --transitory 20 --iterations 1 --pairs 1 --eval-runs 2",
    "infomarket adaptive-attack attack_search --defence staking --byzantines 3 --budget 170 --seed 0 "
    "--out results/adaptive-staking3": "infomarket adaptive-attack attack_search --defence staking --byzantines 3 "
                                      "--budget 3 --pairs 1 --runs 1 --steps 60 --transitory 20 --eval-runs 2 "
                                      "--seed 0 --out adaptive",
    "infomarket adaptive-attack attack_search --defence staking --byzantines 3 --budget 180 --pairs 4 --runs 8 "
    "--lr 0.01 --seed 0 --eval-runs 0 --out results/adaptive-staking3-b":
        "infomarket adaptive-attack attack_search --defence staking --byzantines 3 --budget 3 --pairs 1 --runs 1 "
        "--steps 60 --transitory 20 --lr 0.01 --seed 0 --eval-runs 0 --out adaptive",
    "infomarket adaptive-attack attack_search --defence staking --byzantines 3 --budget 170 --seed 0 --eval-runs 0 "
    "--out results/adaptive-staking3-c":
        "infomarket adaptive-attack attack_search --defence staking --byzantines 3 --budget 3 --pairs 1 --runs 1 "
        "--steps 60 --transitory 20 --seed 0 --eval-runs 0 --out adaptive",
}
#: Shown in these pages but not run here, with the reason.
SMALL_NOT_RUN = {
    "infomarket attack-search attack_search --questions src/infomarket/search/questions_v4.toml "
    "--out results/attack_search_v4": "its small form would change the questions file's sizes, not an option; "
                                      "tests/search/test_validate.py runs a study from a small questions file",
    "infomarket attack-search attack_search --defence staking,theta20 --byzantines 3 --dask tcp://head:8786 "
    "--out results/as-dask": "needs a Dask scheduler at that address; tests/search runs one on a LocalCluster",
    "infomarket view": "a web server that runs until stopped; tests/viewer",
    "infomarket replay --movie":
        "the command's name in the text (rl.md's rendering); tests/viewer/test_movie.py runs it",
    "infomarket attack-search": "the command's name in the text; its commands are the ones above",
    "infomarket attack-search --validate": "the command's name in a heading; its commands are the ones above",
    "infomarket adaptive-attack": "the command's name in the text (rl.md); its command is the one above",
    "infomarket sweep attack_search": "sweep has no --steps: 24 runs of 30 000 steps at the least; `check "
                                      "attack_search` (run above) builds and validates each of its conditions",
    "infomarket chain demo --chain-period P":
        "an EVM replay of a 3 000-step run; tests/evm/test_block_replay.py runs `chain demo --chain-period 5`",
}


def small_doc_commands() -> list[str]:
    out = []
    for name in SMALL_DOCS:
        text = (ROOT / "docs" / name).read_text()
        lines, fence = [], None  # fence: the open block's language ("" for a plain block), None outside one
        for ln in text.splitlines():
            if ln.startswith("```"):
                fence = ln[3:].strip() if fence is None else None
            elif fence in ("", "console"):
                lines.append(ln)
        lines += re.findall(r"`(infomarket [^`]+)`", text)
        for line in lines:
            cmd = line.split(" #")[0].strip().removeprefix("$ ").removeprefix(".venv/bin/")
            if cmd.startswith("infomarket"):
                out.append(shlex.join(shlex.split(cmd)))
    return sorted(set(out))


def test_every_command_of_the_small_run_pages_has_a_small_form():
    found = set(small_doc_commands())
    assert {"infomarket rl-train --steps 10000 --transitory 5000 --iterations 60 --pairs 16 --eval-runs 32 --seed 0",
            "infomarket check attack_search"} <= found  # the collector sees plain blocks and console blocks
    missing = found - set(SMALL) - set(SMALL_NOT_RUN)
    assert not missing, f"give these a small form in SMALL (or a reason in SMALL_NOT_RUN): {sorted(missing)}"
    stale = (set(SMALL) | set(SMALL_NOT_RUN)) - found
    assert not stale, f"no longer in {SMALL_DOCS}: {sorted(stale)}"


@pytest.mark.parametrize("documented", sorted(SMALL))
def test_a_small_form_changes_only_the_size(documented):
    parser = build_parser()
    big = vars(parser.parse_args(shlex.split(documented)[1:]))
    small = vars(parser.parse_args(shlex.split(SMALL[documented])[1:]))
    changed = {k for k in big.keys() | small.keys() if big.get(k) != small.get(k)}
    assert changed <= SIZE_OPTIONS, f"the small form changes more than the size: {sorted(changed - SIZE_OPTIONS)}"


def _chain_store(folder: Path) -> None:
    """A results store holding a chain table: one short run of the chain study's partition setup."""
    assert main(["run", "chain_partition", "--steps", "200", "--runs", "1", "--out", str(folder), "--quiet"]) == 0


@pytest.mark.parametrize("documented", sorted(SMALL))
def test_documented_command_runs_at_a_small_size(documented, tmp_path, monkeypatch, capsys):
    pytest.importorskip("gymnasium") if " rl-train" in documented or "--env" in documented else None
    monkeypatch.chdir(tmp_path)
    words = shlex.split(SMALL[documented])
    if "chainstore" in words:  # the store the page's `STORE` stands for
        _chain_store(tmp_path / "chainstore")
        capsys.readouterr()
    if "--questions" in words:  # a path of the repository, relative to its root as the page shows it
        rel = Path(words[words.index("--questions") + 1])
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_text((ROOT / rel).read_text())
    assert main(words[1:]) == 0, capsys.readouterr().err
    out = capsys.readouterr().out
    assert out.strip()
    if words[1] == "attack-search" and "--validate" in words:
        assert "Recovery rate per searcher: search " in out
    elif words[1] == "attack-search":
        report = json.loads((tmp_path / "as" / "report.json").read_text())
        assert report["steps"] == 60 and report["transitory"] == 20 and report["reduced"]
    if words[1] == "check":
        assert "\nchain: " in out
    if words[1:3] == ["store", "sql"]:
        assert "chain_id" in out or "blocks" in out
    if words[1:3] == ["store", "verify"]:
        assert "1 committed part(s), 0 damaged" in out


#: The Python examples of these pages, run with their sizes made small (each pattern must match).
PY_SMALL = {"num_envs=64": "num_envs=2", "steps=10000": "steps=60", "transitory=5000": "transitory=20",
            "steps=4000": "steps=60", "transitory=1000": "transitory=20"}


def test_the_python_examples_of_the_small_run_pages_run_at_a_small_size(tmp_path, monkeypatch):
    pytest.importorskip("gymnasium")
    monkeypatch.chdir(tmp_path)
    blocks = [b for name in SMALL_DOCS
              for b in re.findall(r"```python\n(.*?)```", (ROOT / "docs" / name).read_text(), re.S)]
    assert blocks
    for code in blocks:
        for big, small in PY_SMALL.items():
            code = code.replace(big, small)
        names: dict = {}
        exec(compile(code, "<docs example>", "exec"), names)  # the docs' own example, run as a reader would
        for name in ("env", "venv"):  # whatever vector env an example built runs at the small size
            if hasattr(names.get(name), "num_envs") and hasattr(names[name], "runs"):
                assert names[name].num_envs == 2 and names[name].runs.steps == 60


# ------------------------------------------------------------------ the other pages' commands at a reduced size
#: Console commands of the other pages, each run with only its size changed (SIZE_OPTIONS) and its
#: placeholders filled (PLACEHOLDERS), in a scratch folder holding README's minimal experiment as my.toml with
#: 300 steps (sweep has no --steps: the file's length is its size) and, where a page names a store, a
#: reduced run of fig2B there.  What stays in NOT_RUN has no option that makes it small (full-length sweeps,
#: reproduce), needs a server, a scheduler or ROS, or is a declared study.
REDUCED = {
    "infomarket run fig2B --runs 16 --out results/2b": "infomarket run fig2B --runs 2 --steps 300 --out results/2b",
    "infomarket run my.toml --history 100": "infomarket run my.toml --runs 2 --steps 300 --history 100",
    "infomarket sweep my.toml --out store --workers 8": "infomarket sweep my.toml --out store --workers 2 --runs 4",
    "infomarket sweep EXP --out STORE": "infomarket sweep my.toml --out results/paper --runs 2",
    "infomarket figures results/paper --out results/figures": "infomarket figures results/paper --out results/figures",
    "infomarket figures results/paper --out results/paper-report":
        "infomarket figures results/paper --out results/paper-report",
    "infomarket figures results/paper --out report --vector pdf":
        "infomarket figures results/paper --out report --vector pdf",
    "infomarket store verify STORE": "infomarket store verify results/paper",
    "infomarket store repair STORE": "infomarket store repair results/paper",
    "infomarket bench --json": "infomarket bench --json --steps 40 --repeats 1",
    "infomarket bench --robots 25,100,1000,10000 --json":
        "infomarket bench --robots 25,30 --json --steps 40 --repeats 1",
    "infomarket run examples/age_liar.toml": "infomarket run examples/age_liar.toml --runs 1 --steps 300",
    "infomarket replay crowd --movie crowd.gif": "infomarket replay crowd --steps 20 --movie crowd.gif",
}
#: What a page's placeholder stands for in its reduced form.
PLACEHOLDERS = {"EXP": "my.toml", "STORE": "results/paper"}


@pytest.mark.parametrize("documented", sorted(REDUCED))
def test_a_reduced_form_changes_only_the_size(documented):
    parser = build_parser()
    words = [PLACEHOLDERS.get(w, w) for w in shlex.split(documented)]
    big = vars(parser.parse_args(words[1:]))
    small = vars(parser.parse_args(shlex.split(REDUCED[documented])[1:]))
    changed = {k for k in big.keys() | small.keys() if big.get(k) != small.get(k)}
    assert changed <= SIZE_OPTIONS, f"the reduced form changes more than the size: {sorted(changed - SIZE_OPTIONS)}"


@pytest.mark.parametrize("documented", sorted(REDUCED))
def test_documented_command_runs_at_a_reduced_size(documented, tmp_path, monkeypatch, capsys, procs):
    (tmp_path / "my.toml").write_text(re.sub(r"(?m)^steps = \d+$", "steps = 300", readme_minimal_experiment()))
    monkeypatch.chdir(tmp_path)
    words = shlex.split(REDUCED[documented])
    if "results/paper" in words and words[1] != "sweep":  # the store the page names, made small
        assert main(["run", "fig2B", "--runs", "2", "--steps", "300", "--out", "results/paper", "--quiet"]) == 0
        capsys.readouterr()
    if "examples/age_liar.toml" in words:
        # the repository's example, run from a copy as the page runs it from the root; in a process of its own,
        # since its plugin registers "age_liar" in the process that loads it (tests/test_extending.py's, here)
        shutil.copytree(ROOT / "examples", tmp_path / "examples")
        done = procs.run([sys.executable, "-m", "infomarket.cli", *words[1:]], cwd=tmp_path)
        assert done.returncode == 0 and done.stdout.strip(), done.stderr
        return
    assert main(words[1:]) == 0, capsys.readouterr().err
    out = capsys.readouterr().out
    assert out.strip() or words[1] == "replay"  # replay reports on stderr and writes its file
    if words[1] == "replay":
        assert Path("crowd.gif").read_bytes()[:3] == b"GIF"
    if words[1] == "figures":
        folder = Path(words[words.index("--out") + 1])
        vector = "pdf" if "pdf" in words else "svg"
        assert {"fig2.png", f"fig2.{vector}", "report.md", "report.html"} <= {p.name for p in folder.iterdir()}
    if words[1] in ("run", "sweep") and "--out" in words:
        from infomarket.store import Store

        runs = Store(words[words.index("--out") + 1]).runs()
        assert len(runs) == int(words[words.index("--runs") + 1]) and set(runs["steps"]) == {300}

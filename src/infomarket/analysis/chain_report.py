"""The chain study's report: its stores read (``load``), its questions answered (``chain_study``) and
written as ``chain-study.md``, ``chain-study.csv`` and ``chain-study.png`` (``ChainStudy``)."""
from __future__ import annotations

import pandas as pd

from ..cliargs import UsageError
from ..store import Store
from . import study
from .chain_figure import figure
from .chain_study import DECLARATION, answer, markdown, per_run
from .frames import Frames
from .study import NO_DATA, NOT_RUN, PENDING


def load(stores: list[str]) -> tuple[pd.DataFrame, pd.DataFrame | None, str]:
    """Per-run values of every store given, their chain measures (when a store keeps them) and a line on
    whether the questions were declared before each store's first run."""
    frames, chains, locks = [], [], []
    for path in stores:
        store = Store(path)
        f = Frames.from_store(store)  # StoreError (exit 2) for a missing or foreign folder
        if not f.robots.empty:
            frames.append(f.robots)
        if callable(getattr(store, "chain", None)):  # a store that keeps the chain measures per run
            c = store.chain()
            if len(c):
                chains.append(c)
        status = DECLARATION.question_status(store.declarations())
        locks.append(f"{path}: {', '.join(sorted(status))}")
    robots = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()
    chain = pd.concat(chains, ignore_index=True) if chains else None
    note = ("Declaration record (store.json) for chain_questions.toml: " + "; ".join(locks) +
            " ('not recorded': the store's record does not list this file; its commit precedes the runs)")
    return per_run(robots), chain, note


class ChainStudy(study.Study):
    """The chain study: its questions (``chain_questions.toml``) answered from its stores, as
    ``chain-study.md``, ``chain-study.csv`` and ``chain-study.png``; ``wall``: a line on how long the runs
    took, copied into the markdown."""

    declaration = DECLARATION

    def __init__(self, wall: str = "") -> None:
        self.wall = wall

    def answer(self, store) -> study.Report:
        """The answers from the stores ``store`` (a list of store folders).

        Raises:
            UsageError: the stores hold no completed run, or none of the chain study's experiments.
        """
        runs, chain, locks = load(store)
        if runs.empty:
            raise UsageError(f"{', '.join(store)}: no completed runs of the chain study")
        a = answer(runs, chain)
        # stores of other experiments: nothing to answer
        if all(str(v).startswith((NOT_RUN, PENDING, NO_DATA)) for v in a.table["answer"]):
            raise UsageError(f"{', '.join(store)}: no runs of the chain study's experiments (chain_paper, "
                             f"chain_fig7, chain_sweep, chain_fig7_sweep, chain_partition), so no question can be "
                             f"answered; run `infomarket sweep chain_paper --out STORE` first (docs/research.md)")
        a.locks = locks
        self.answers = a  # the command prints its table
        return study.Report.of("chain-study", markdown(a, self.wall), table=a.table, figure=lambda p: figure(a, p))

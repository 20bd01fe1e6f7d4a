"""The open questions' answers from several stores read together (docs/research.md, the 2026-11-24 statistics review).

``infomarket figures STORE`` answers them from one ``sweep future`` store; this does the same from the
per-experiment stores of ``infomarket sweep future_honest --out A``, ``... future_liar --out B`` and so
on (each experiment keeps its own seeds, so they hold the same runs as one ``sweep future`` store):

    PYTHONPATH=src python docs/research/future_answers.py A B C D
"""
import sys

import pandas as pd

from infomarket.analysis import future
from infomarket.analysis.frames import Frames
from infomarket.store import Store

stores = [Store(p) for p in sys.argv[1:]]
robots = pd.concat([s.robots() for s in stores], ignore_index=True)
table = future.question_table(Frames(robots=robots, meta=stores[0].meta()))
for row in table.itertuples():
    print(f"== {row.id} | {future.st.shown(row.answer, row.note)}\n   {row.statistics}")

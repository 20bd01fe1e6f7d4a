"""``tools/floor_ablation.py`` cuts the market out of the step loop by anchors in its source; these checks
keep the tool true to the template (docs/performance.md quotes what it measures)."""
from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
spec = importlib.util.spec_from_file_location("floor_ablation", ROOT / "tools" / "floor_ablation.py")
tool = importlib.util.module_from_spec(spec)
spec.loader.exec_module(tool)


def test_the_cut_loop_keeps_the_robots_and_loses_the_market():
    whole = (ROOT / tool.TEMPLATE).read_text()
    cut_whole = tool.without_market(whole)
    source, cut = (text[text.index("def step_all("):] for text in (whole, cut_whole))  # the loop itself
    for market in ("sell_dispatch(", "buy_dispatch(", "deposit(w, i, rng)", "install_table(", "begin_communication("):
        assert market in source and market not in cut, market
    for robot in ("find_neighbours(w)", "forage(w, i, bits)", "behaviour_step(w, i, bits)", "move(w, i, dx, dy, bits)",
                  "end_of_step(w, rng)", "record_history(w)"):
        assert robot in cut, robot
    compile(cut_whole, "loop_template.py", "exec")  # still Python


def test_a_template_without_the_anchors_is_refused():
    with pytest.raises(SystemExit, match="no longer has the passes"):
        tool.without_market("def step_all():\n    pass\n")

"""The chain model's blocks replayed on the EVM one by one (chain.block_replay, ``chain demo
--chain-period``): a modelled run matches at every block, and a wrong ledger is caught at its block.

Expected balances in the hand-made chains are computed by hand from docs/model.md §5 (reward 1,
information share 0.5, stake 0.04) and docs/chain-model.md's gas rule, not by the code under test."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from infomarket import load_experiment
from infomarket.evm.block_replay import match_purchases, replay_blocks
from infomarket.ledger.gas import table_gas
from infomarket.evm.cli import chain_config, demo_config, main
from infomarket.engine.simulation import Simulation
from infomarket.ledger.blocklog import Block, BlockLog, ChainTx

STAKE_UNITS = 40_000_000  # 0.04 token in units of 1e-9


@pytest.fixture(scope="module")
def modelled():
    """A small modelled run: 25 robots of fig4C with staking, 3 000 steps, a block every 5 steps, gossip
    over the robots' links only (forks and reorganisations happen)."""
    config = chain_config(demo_config(load_experiment("fig4C"), 25, 3000, "staking"), 5, None)
    sim = Simulation(config, 0, record_events=True)
    log = BlockLog(sim)
    log.run()
    return config, log, sim.result()


def test_a_modelled_run_replays_and_matches_at_every_block(modelled):
    config, log, result = modelled
    blocks = log.canonical()
    assert result.totals["chain"]["forks"] > 0 and result.totals["chain"]["reorgs"] > 0  # not a trivial chain
    kinds = {tx.kind for b in blocks for tx in b.txs}
    assert kinds == {"reveal", "deposit"}
    report = replay_blocks(blocks, match_purchases(log.txs, result.events), config)
    assert report.first_mismatch is None and report.conserved
    assert report.blocks_checked == len(blocks)
    assert report.deposits == sum(tx.kind == "deposit" for b in blocks for tx in b.txs)


def test_a_wrong_modelled_balance_is_caught_at_its_block(modelled):
    config, log, result = modelled
    blocks = log.canonical()
    k = len(blocks) // 2
    bad = blocks[k].balances.copy()
    bad[3] += 1e-6  # 1 000 units: far above any rounding bound
    wrong = [*blocks[:k], replace(blocks[k], balances=bad), *blocks[k + 1:]]
    report = replay_blocks(wrong, match_purchases(log.txs, result.events), config)
    m = report.first_mismatch
    assert (m.block, m.height, m.robot, report.blocks_checked) == (blocks[k].id, k, 3, k)
    assert m.diff_units == pytest.approx(-1000, abs=1)


def test_a_dropped_reveal_is_caught_at_its_block(modelled):
    config, log, result = modelled
    blocks = log.canonical()
    # a block with a reveal whose buyer does not deposit in the same block, its seller the only one
    # selling in that block, and no deposit paying the seller in it
    for k, blk in enumerate(blocks):  # noqa: B007 - the block's index, read after the loop
        if len(blk.txs) == 1 and blk.txs[0].kind == "reveal":
            break
    else:
        pytest.fail("no block holds a single reveal")
    seller = blk.txs[0].seller
    wrong = [*blocks[:k], replace(blk, txs=()), *blocks[k + 1:]]
    report = replay_blocks(wrong, match_purchases(log.txs, result.events), config)
    m = report.first_mismatch
    # the EVM's seller kept the stake the modelled one locked
    assert (m.height, m.robot) == (k, seller) and m.diff_units == pytest.approx(STAKE_UNITS, abs=1)


def _tiny(gas_price=None, wealth=1.0):
    """Two robots (0 sells to 1), staking, a given initial wealth; no simulation."""
    config = demo_config(load_experiment("fig4C"), 2, 10, "staking")
    config = chain_config(config, 1, gas_price)
    payment = config.payment.model_dump()
    payment["initial_wealth"] = wealth
    return config.with_overrides(payment=payment)


def _event(seq, step):
    return {"kind": "purchase", "step": step, "buyer": 1, "seller": 0, "site": 0, "x": 3.0, "y": 4.0, "age": 0,
            "seller_x": 0.0, "seller_y": 0.0}


def _reveal(seq, step, gas=0.0):
    return ChainTx(seq, "reveal", 0, 1, 0, 0, 53.13, 0.04, gas, step)


def _deposit(seq, step):
    return ChainTx(seq, "deposit", 1, 1, -1, -1, 0.0, 0.0, 0.0, step)


def _block(i, txs, balances):
    return Block(i, i - 1, i, i, 0, i, tuple(txs), np.array(balances, float))


def test_a_reveal_the_branch_cannot_pay_fails_on_the_evm_too():
    # wealth 0.05: the first reveal locks 0.04 (0.01 left), the second cannot: it fails, moving nothing
    config = _tiny(wealth=0.05)
    blocks = [_block(0, [], [0.05, 0.05]), _block(1, [_reveal(0, 1), _reveal(1, 1)], [0.01, 0.05])]
    report = replay_blocks(blocks, {0: _event(0, 1), 1: _event(1, 1)}, config)
    assert report.ok and report.reveals == 1
    assert [(h, seq, name) for h, seq, name in report.refused] == [(1, 1, "InfoMarketInsufficientStake")]
    # a modelled ledger in which the second reveal had been paid is caught
    paid = [blocks[0], _block(1, blocks[1].txs, [-0.03, 0.05])]
    report = replay_blocks(paid, {0: _event(0, 1), 1: _event(1, 1)}, config)
    assert (report.first_mismatch.height, report.first_mismatch.robot) == (1, 0)


def test_gas_is_billed_by_the_models_rule():
    # gas price 1e-7: a reveal 1e-7 x 128 645 = 0.0128645 (docs/gas.md, reveal with staking; its sender's view
    # set it aside), a deposit settling one record 1e-7 x 167 885 (outlier with staking, n = 1) = 0.0167885
    config = _tiny(gas_price=1e-7)
    assert table_gas(np.array([1.0, 4.0]), np.array([167_885.0, 217_803.0]), 1.0) == 167_885
    blocks = [_block(0, [], [1.0, 1.0]),
              _block(1, [_reveal(0, 1, gas=0.0128645)], [1.0 - 0.04 - 0.0128645, 1.0]),
              # buyer: +1 reward +0.04 pot -(0.5 + 0.04) to the seller, then the deposit's gas
              _block(2, [_deposit(1, 2)], [0.9471355 + 0.54, 1.5 - 0.0167885])]
    report = replay_blocks(blocks, {0: _event(0, 1)}, config)
    assert report.ok, report.first_mismatch
    assert report.model_deposit_gas == [167_885] and report.model_reveal_gas == [pytest.approx(128_645)]
    # without the deposit's gas in the modelled ledger the buyer differs at block 2
    free = [*blocks[:2], _block(2, blocks[2].txs, [0.9471355 + 0.54, 1.5])]
    m = replay_blocks(free, {0: _event(0, 1)}, config).first_mismatch
    assert (m.height, m.robot) == (2, 1) and m.diff_units == pytest.approx(-16_788_500, abs=1)


def test_a_reveal_the_models_gas_check_refuses_is_not_sent():
    # wealth 0.045 covers the stake (0.04) but not stake + gas (0.0528645): the model fails the reveal
    config = _tiny(gas_price=1e-7, wealth=0.045)
    blocks = [_block(0, [], [0.045, 0.045]), _block(1, [_reveal(0, 1, gas=0.0128645)], [0.045, 0.045])]
    report = replay_blocks(blocks, {0: _event(0, 1)}, config)
    assert report.ok and report.gas_refused == 1 and report.reveals == 0


def test_the_chain_demo_replays_a_modelled_run(capsys):
    assert main(["chain", "demo", "--chain-period", "5"]) == 0  # as docs/chain.md shows it (3 000 steps)
    out = capsys.readouterr().out
    assert "every robot's balance matches the modelled ledger at all" in out


@pytest.mark.parametrize("argv, message", [
    (["--chain-period", "0"], "argument --chain-period: must be >= 1, got 0"),
    (["--gas-price", "-1"], "argument --gas-price: must be a finite number >= 0, got -1"),
])
def test_bad_chain_arguments_exit_2(capsys, argv, message):
    with pytest.raises(SystemExit) as stopped:
        main(["chain", "demo", *argv])
    assert stopped.value.code == 2 and message in capsys.readouterr().err


@pytest.mark.parametrize("argv, message", [
    (["--chain-period", "5", "--backend", "py-evm"], "needs the revm backend"),
    (["--gas-price", "1e-7"], "--gas-price needs the chain model"),
])
def test_chain_demo_refuses_what_it_cannot_do(capsys, argv, message):
    assert main(["chain", "demo", *argv]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err


def test_an_experiment_with_a_chain_section_is_replayed_block_by_block(tmp_path, capsys):
    (tmp_path / "poa.toml").write_text("""
name = "poa"
steps = 3000

[swarm]
robots = 25

[[swarm.groups]]
behaviour = "sceptical"
count = 20

[[swarm.groups]]
behaviour = "scaboteur"
count = 5

[payment]
scheme = "outlier"
stake = 0.04

[chain]
consensus = "poa"
period = 4
""")
    assert main(["chain", "demo", "--experiment", str(tmp_path / "poa.toml")]) == 0
    out = capsys.readouterr().out
    assert "a block every 4 steps" in out and "matches the modelled ledger at all" in out

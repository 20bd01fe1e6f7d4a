"""``infomarket chain demo`` (infomarket.evm.cli): argument errors, and the on-chain replay of a
simulated swarm agreeing with the simulation's ledger."""
from __future__ import annotations

import pytest

from infomarket.evm.cli import demo_config, main


@pytest.mark.parametrize("argv, message", [
    (["--robots", "0"], "argument --robots: must be >= 1, got 0"),
    (["--steps", "many"], "argument --steps: expected an integer, got 'many'"),
    (["--scheme", "barter"], "invalid choice: 'barter'"),
    (["--rpc", "localhost:8545"], "argument --rpc: must be an http(s):// JSON-RPC URL"),
    (["--seed", "-1"], "argument --seed: must be >= 0, got -1"),
])
def test_bad_arguments_give_one_message_and_exit_status_2(capsys, argv, message):
    with pytest.raises(SystemExit) as stopped:
        main(["chain", "demo", *argv])
    assert stopped.value.code == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    assert len([line for line in err.splitlines() if "error:" in line]) == 1


def test_chain_needs_a_subcommand(capsys):
    with pytest.raises(SystemExit) as stopped:
        main(["chain"])
    assert stopped.value.code == 2


def _simulator():
    try:
        from infomarket import load_experiment, simulate
    except ImportError as exc:
        pytest.skip(f"the simulator (infomarket.simulate) is not importable yet: {exc}")
    return load_experiment, simulate


def test_unknown_experiment_is_a_usage_error(capsys):
    _simulator()
    assert main(["chain", "demo", "--experiment", "no-such-experiment"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("infomarket: error:") and "Traceback" not in err


def test_an_unreachable_node_is_reported_before_simulating(capsys):
    _simulator()
    assert main(["chain", "demo", "--rpc", "http://127.0.0.1:9"]) == 2
    captured = capsys.readouterr()
    assert captured.err == "infomarket: error: no JSON-RPC node answers at http://127.0.0.1:9\n"
    assert "simulated" not in captured.out


def test_demo_config_scales_the_swarm_and_sets_the_scheme():
    load_experiment, _ = _simulator()
    config = demo_config(load_experiment("fig4C"), 7, 123, "delayed")
    assert config.swarm.robots == 7 and config.steps == 123
    assert [g.count for g in config.swarm.groups] == [6, 1]
    assert (config.payment.scheme, config.payment.stake) == ("delayed", 0.0)
    staking = demo_config(load_experiment("fig2A"), 3, 10, "staking")
    assert (staking.payment.scheme, staking.payment.stake) == ("outlier", 0.04)


def test_on_chain_balances_equal_the_simulated_ledger(capsys):
    """The issue's acceptance check, in short: a staking swarm with deposits, purchases and refusals,
    every one through the contract; every balance within its rounding bound of the simulation's."""
    load_experiment, simulate = _simulator()
    from infomarket.evm.evm_replay import replay_result

    result = simulate(demo_config(load_experiment("fig4C"), 5, 4000, "staking"), seed=2, record_events=True)
    kinds = result.events["kind"].value_counts()
    assert kinds["deposit"] >= 3 and kinds["purchase"] >= 50 and kinds["refused"] >= 1
    report, rows = replay_result(result)
    assert not report.disagreements
    assert report.conserved()
    assert report.items == kinds["deposit"] and len(report.reveal_gas) == kinds["purchase"]
    # the simulator's stake check tolerates float rounding, so every refusal is one the contract makes too
    assert report.refusals_confirmed == kinds["refused"]
    assert all(r.ok for r in rows), [r for r in rows if not r.ok]


def test_demo_command_prints_the_costs_and_the_verdict(capsys):
    _simulator()
    assert main(["chain", "demo", "--robots", "5", "--steps", "4000", "--seed", "2", "--scheme", "delayed"]) == 0
    out = capsys.readouterr().out
    for label in ("gas per reveal", "gas per deposit", "gas per item delivered", "blocks used"):
        assert label in out
    # revm charges cold storage per transaction (test_revm_gas), so its gas is a chain's and carries no warm label
    assert "  gas measured on         revm\n" in out and "warm storage" not in out
    assert out.rstrip().endswith("on-chain balances match the simulated ledger (within the fixed-point rounding bound)")


def test_a_run_without_deposits_is_refused_not_compared(capsys):
    """Finding (low): `--robots 6 --steps 2000` made purchases and no deposit, so "balances match" held
    whatever the contract's weights; such a run is now refused before the replay."""
    _simulator()
    assert main(["chain", "demo", "--robots", "6", "--steps", "2000"]) == 2
    captured = capsys.readouterr()
    assert "0 deposits" in captured.err and "would prove nothing" in captured.err
    assert "replayed" not in captured.out and "match" not in captured.out


def test_the_demo_defaults_make_deposits():
    load_experiment, simulate = _simulator()
    from infomarket.evm.cli import add_subcommand
    import argparse

    parser = argparse.ArgumentParser()
    add_subcommand(parser.add_subparsers(dest="command"))
    args = parser.parse_args(["chain", "demo"])
    config = demo_config(load_experiment(args.experiment), args.robots, args.steps, args.scheme)
    kinds = simulate(config, seed=args.seed, record_events=True).events["kind"].value_counts()
    assert kinds.get("deposit", 0) >= 10 and kinds.get("purchase", 0) >= 100


def _experiment_file(tmp_path, scheme: str, params: str) -> str:
    """fig4C paying by ``scheme`` with ``params`` (a TOML inline table), as a file the demo can load."""
    path = tmp_path / f"{scheme}.toml"
    path.write_text('name = "demo"\nsteps = 4000\n[swarm]\nrobots = 25\n'
                    '[[swarm.groups]]\nbehaviour = "sceptical"\ncount = 20\n'
                    '[[swarm.groups]]\nbehaviour = "scaboteur"\ncount = 5\nparams = { rotation_angle = 90.0 }\n'
                    f'[payment]\nscheme = "{scheme}"\nstake = 0.04\nparams = {params}\n')
    return str(path)


@pytest.mark.parametrize("chain_model, verdict", [
    ([], "on-chain balances match the simulated ledger (within the fixed-point rounding bound)"),
    (["--chain-period", "3"], "every robot's balance matches the modelled ledger at all"),
])
def test_a_capped_outlier_experiment_is_replayed_on_chain_and_agrees(tmp_path, capsys, chain_model, verdict):
    """``--scheme experiment`` keeps the experiment's payment: capped_outlier with cap 1 runs on the
    contract's OutlierCapped scheme, and every balance is within its rounding bound of the simulation's
    (the instant ledger's at the end, or the chain model's after every block). Five robots meet often:
    about half of the instant run's purchases are a seller's second or later record in its buyer's round
    trip, void under the cap."""
    _simulator()
    path = _experiment_file(tmp_path, "capped_outlier", "{ cap = 1 }")
    assert main(["chain", "demo", "--experiment", path, "--scheme", "experiment", "--robots", "5", "--steps",
                 "4000", "--seed", "2", *chain_model]) == 0
    out = capsys.readouterr().out
    assert "scheme capped_outlier (stake 0.04)" in out
    assert verdict in out.rstrip().splitlines()[-1]


def test_a_consensus_slash_experiment_is_refused_before_simulating(tmp_path, capsys):
    _simulator()
    path = _experiment_file(tmp_path, "consensus_slash", "{ slash_angle = 60.0 }")
    assert main(["chain", "demo", "--experiment", path, "--scheme", "experiment"]) == 2
    captured = capsys.readouterr()
    assert captured.err.startswith("infomarket: error: consensus_slash is not on chain: it slashes by the angle")
    assert len(captured.err.strip().splitlines()) == 1 and "Traceback" not in captured.err
    assert "simulated" not in captured.out


@pytest.mark.parametrize("scheme", ["outcome_slash", "trip_slash"])
def test_an_outcome_slashing_experiment_is_refused_with_its_reason(tmp_path, capsys, scheme):
    _simulator()
    path = _experiment_file(tmp_path, scheme, "{ theta = 30.0 }")
    assert main(["chain", "demo", "--experiment", path, "--scheme", "experiment"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"infomarket: error: {scheme} is not on chain: it slashes by the depositing buyer's "
                          "own outcome records") and len(err.strip().splitlines()) == 1


def test_an_adaptive_outlier_experiment_is_refused_with_its_reason(tmp_path, capsys):
    _simulator()
    path = _experiment_file(tmp_path, "adaptive_outlier", "{ theta = 30.0 }")
    assert main(["chain", "demo", "--experiment", path, "--scheme", "experiment"]) == 2
    err = capsys.readouterr().err
    assert err == ("infomarket: error: adaptive_outlier is not on chain: each seller's Theta follows its "
                   "reputation, which the simulated ledger keeps and the contract does not\n")

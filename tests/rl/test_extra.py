"""Without the `rl` extra, the environments and the commands that need them say what to install."""
import sys

import pytest

from infomarket.cli import main
from infomarket.errors import UsageError


@pytest.fixture
def no_gymnasium(monkeypatch):
    for name in [m for m in sys.modules if m == "gymnasium" or m.startswith(("gymnasium.", "infomarket.rl.envs",
                                                                                "infomarket.rl.parallel",
                                                                                "infomarket.bench.env"))]:
        monkeypatch.delitem(sys.modules, name)
    monkeypatch.setitem(sys.modules, "gymnasium", None)  # `import gymnasium` now fails


def test_the_envs_name_the_extra(no_gymnasium):
    import infomarket.rl as rl

    with pytest.raises(UsageError, match=r"pip install 'infomarket\[rl\]'"):
        rl.AttackVectorEnv  # noqa: B018 - the attribute's lookup is what is tested


@pytest.mark.parametrize("argv", [["bench", "--env"], ["rl-train", "--iterations", "1"]])
def test_the_commands_exit_2_naming_the_extra(no_gymnasium, argv, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "infomarket[rl]" in err and "Traceback" not in err


def test_importing_rl_without_gymnasium_registers_nothing_and_does_not_fail(no_gymnasium):
    import importlib

    import infomarket.rl as rl

    rl = importlib.reload(rl)  # the import-time registration runs again, with `import gymnasium` failing
    assert rl.ENV_ID == "infomarket/Attack-v0"

"""Experiment files as editors write them (issue 21, more of the same)."""
from infomarket.cli import main

BODY = 'name = "bom"\nsteps = 10\n[swarm]\nrobots = 2\n[[swarm.groups]]\nbehaviour = "naive"\ncount = 2\n'


def test_a_byte_order_mark_is_not_an_invalid_statement(tmp_path, capsys):
    """Windows editors may start a UTF-8 file with a byte-order mark: it was "not valid TOML: Invalid
    statement (at line 1, column 1)"."""
    for name, body in (("bom.toml", BODY), ("bom.json", '{"name": "bom", "steps": 10, "swarm": {"robots": 2, '
                                                       '"groups": [{"behaviour": "naive", "count": 2}]}}')):
        (tmp_path / name).write_bytes(b"\xef\xbb\xbf" + body.encode())
        assert main(["check", str(tmp_path / name)]) == 0, capsys.readouterr().err
        assert capsys.readouterr().out.startswith("bom: valid.")

"""The terrain keys leave the paper's setups as they were: same configuration hashes (stored results
stay valid) and the plane's kernel."""
import pytest

from infomarket.config.load import load_experiment, validate

#: config_hash() of every paper setup as computed by the code before the terrain keys existed
#: (main at 3c51a7c), so stores written then still match their configurations.
BEFORE = {'fig2A': '93b0d0974ae24300', 'fig2B': '80115f17e17eb8ef', 'fig2C': 'd4a85fb7a4fc4886',
          'fig2D': 'cda3b3c6037b375d', 'fig3A': '9709b408f7df9ce5', 'fig3B': '48e037d4145b4abf',
          'fig3C': '0d72ec6fa0c02e64', 'fig4A': 'ae596dc5a357e671', 'fig4B': '9d823ce97f54aeef',
          'fig4C': '6d59b4a883247a60', 'fig5': '3deee30a27aed509', 'fig6A': '55c2336283b995d4',
          'fig6B': '07dd8e1adef439fe', 'fig7': '92c89f3f2bd2f4a2'}


@pytest.mark.parametrize("name", BEFORE)
def test_paper_setups_keep_their_hashes_and_the_plane(name):
    cfg = load_experiment(name)
    assert cfg.config_hash() == BEFORE[name]
    assert not cfg.terrain


BASE = {"swarm": {"robots": 2, "groups": [{"behaviour": "naive", "count": 2}]}}


@pytest.mark.parametrize("extra", [
    {"obstacles": [{"shape": "circle", "x": 600.0, "y": 300.0, "radius": 10.0}]},
    {"robot": {"collisions": True}}, {"robot": {"line_of_sight": True}}, {"robot": {"sense_robots": True}},
    {"nest": [{"x": 1000.0, "y": 300.0}, {"x": 1000.0, "y": 100.0}]},
])
def test_each_terrain_key_selects_the_terrain_step_and_changes_the_hash(extra):
    cfg = validate({**BASE, **extra})
    assert cfg.terrain
    assert cfg.config_hash() != validate(BASE).config_hash()


def test_a_list_of_one_site_is_still_the_plane():
    cfg = validate({**BASE, "food": [{"x": 200.0, "y": 300.0}]})
    assert not cfg.terrain and cfg.sites("food")[0].x == 200.0

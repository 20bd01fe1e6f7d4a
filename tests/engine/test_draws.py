"""The engine's draws from the bit generator are the Generator's own draws, in the same order: compared
with numpy's Generator in Python (its C code, an independent reference) and with numba's methods."""
import numpy as np
from numba import njit

from infomarket.engine.draws import normal, uniform


@njit
def _mixed(source, k, loc, scale):
    out = np.empty(2 * k)
    for j in range(k):
        out[2 * j] = uniform(source)
        out[2 * j + 1] = normal(source, loc, scale)
    return out


def _numpy(seed, k, loc, scale):
    g = np.random.default_rng(seed)
    out = np.empty(2 * k)
    for j in range(k):
        out[2 * j] = g.random()
        out[2 * j + 1] = g.normal(loc, scale)
    return out


def test_compiled_draws_from_the_bit_generator_are_numpys():
    expect = _numpy(11, 500, 0.3, 2.5)
    np.testing.assert_array_equal(_mixed(np.random.default_rng(11).bit_generator, 500, 0.3, 2.5), expect)
    np.testing.assert_array_equal(_mixed(np.random.default_rng(11), 500, 0.3, 2.5), expect)


def test_a_shared_stream_stays_in_step():
    """Draws through the bit generator advance the Generator's own stream (rules draw from it too)."""
    g, twin = np.random.default_rng(5), np.random.default_rng(5)
    _mixed(g.bit_generator, 3, 0.0, 1.0)
    for _ in range(3):
        twin.random()
        twin.normal(0.0, 1.0)
    assert g.random() == twin.random()


def test_plain_python_draws_are_the_same():
    g, h = np.random.default_rng(2), np.random.default_rng(2)
    assert uniform(g.bit_generator) == h.random() and uniform(g) == h.random()
    assert normal(g.bit_generator, 1.0, 3.0) == h.normal(1.0, 3.0) and normal(g, 0.0, 1.0) == h.normal(0.0, 1.0)

"""Market-side rules (``payments.consensus``): balances after a round trip, computed by hand, and the
public checker every scheme must pass.  Reward 1, information share 0.5, initial wealth 1."""
import numpy as np
import pytest

from infomarket import checks
from infomarket.ledger import LedgerEvent, replay_events
from infomarket.payments.consensus import consensus_directions


def _trip(sales, robots):
    """Robot 0 buys ``sales`` = [(seller, direction)] for food, then deposits."""
    return [LedgerEvent("purchase", 0, s, 0, d) for s, d in sales] + [LedgerEvent("deposit", 0)]


def test_the_consensus_is_the_record_nearest_to_all_others_of_its_site():
    # food 10, 20, 100: sums of distances 100, 90, 170 -> 20; nest 350 and 5 (across 0): a tie, the first
    sites = np.array([0, 0, 0, 1, 1], dtype=np.int64)
    out = consensus_directions(sites, np.array([10.0, 20.0, 100.0, 350.0, 5.0]))
    assert list(out) == [20.0, 20.0, 20.0, 350.0, 350.0]


def test_stake_is_slashed_in_proportion_to_the_distance_from_consensus():
    # Sellers 1, 2, 3 at 10, 20, 100 degrees; consensus 20; distances 10, 0, 80 of slash_angle 90:
    # each keeps 8/9, 1, 1/9 of its stake (0.04) and shares the rest by the same fractions.
    # Amount 0.5 + 3 * 0.04 = 0.62; stakes back 0.04 * (8/9 + 1 + 1/9) = 0.08; rest 0.54 over 2:
    # seller 1: 0.04 * 8/9 + 0.54 * 4/9, seller 2: 0.04 + 0.54 / 2, seller 3: 0.04 / 9 + 0.54 / 18.
    out = replay_events(_trip([(1, 10.0), (2, 20.0), (3, 100.0)], 4), 4, scheme="consensus_slash",
                        stake=0.04, params={"slash_angle": 90.0})
    paid = [0.04 * 8 / 9 + 0.54 * 4 / 9, 0.04 + 0.27, 0.04 / 9 + 0.03]
    assert list(out.balances) == pytest.approx([1.5, *(1 - 0.04 + p for p in paid)], abs=1e-12)
    assert out.balances.sum() == pytest.approx(5.0, abs=1e-12)


def test_without_stake_the_share_follows_the_distance_and_a_record_past_the_angle_gets_nothing():
    # slash_angle 45: distances 10, 0, 80 keep 35/45, 1, 0; the 0.5 is shared 7/9 : 1 : 0 of 16/9
    out = replay_events(_trip([(1, 10.0), (2, 20.0), (3, 100.0)], 4), 4, scheme="consensus_slash",
                        params={"slash_angle": 45.0})
    assert list(out.balances[1:]) == pytest.approx([1 + 0.5 * 7 / 16, 1 + 0.5 * 9 / 16, 1.0], abs=1e-12)


def test_a_seller_past_its_cap_gets_its_stake_back_and_nothing_more():
    # Honest sellers 1, 2, 3 at 10, 15, 20 once each; seller 4 sells a 100-degree lie 5 times; cap 1.
    # Counted: 10, 15, 20 (3 agreeing each) and seller 4's first (alone: 1); its 4 later records are void.
    # Amount 0.5 + 8 * 0.04 = 0.82; void stakes back 4 * 0.04 = 0.16; rest 0.66 shared 3 : 3 : 3 : 1.
    sales = [(1, 10.0), (2, 15.0), (3, 20.0)] + [(4, 100.0)] * 5
    out = replay_events(_trip(sales, 5), 5, scheme="capped_outlier", stake=0.04, params={"theta": 30.0, "cap": 1})
    honest = 1 - 0.04 + 0.66 * 0.3
    assert list(out.balances) == pytest.approx([1 + 1 + 0.32 - 0.82, honest, honest, honest,
                                                1 - 0.2 + 0.16 + 0.066], abs=1e-12)
    # the paper's scheme pays the five lies 25 of 34 agreement counts
    paper = replay_events(_trip(sales, 5), 5, scheme="outlier", stake=0.04, params={"theta": 30.0})
    assert paper.balances[4] == pytest.approx(1 - 0.2 + 0.82 * 25 / 34, abs=1e-12)


def test_a_cap_above_every_sellers_count_is_the_papers_outlier_scheme():
    sales = [(1, 10.0), (2, 15.0), (1, 200.0), (3, 20.0), (2, 12.0)]
    for stake in (0.0, 0.04):
        capped = replay_events(_trip(sales, 4), 4, scheme="capped_outlier", stake=stake, params={"cap": 2})
        paper = replay_events(_trip(sales, 4), 4, scheme="outlier", stake=stake)
        np.testing.assert_allclose(capped.balances, paper.balances, rtol=0, atol=1e-12)


@pytest.mark.parametrize("name", ["consensus_slash", "capped_outlier"])
def test_the_rules_pass_the_public_checker(name):
    checks.check_payment(name)


def test_an_expired_round_trip_is_slashed_as_a_deposit_would_slash_it():
    # Stake expiry 5: seller 1's record (step 1) expires the round trip at the start of step 6, before the
    # deposit: all four records, 1 and 2 at 10 degrees, 3 at 20, 4 at 100 (step 3), are settled as at a
    # deposit, the buyer paying the share 0.5 from its balance. Sums of angular distances 100, 100, 100,
    # 260: the consensus is the earliest, 10 degrees; the records keep 1, 1, 8/9 and 0 of their 0.04 stakes.
    # The rule's weights add up to 0.5 + 4 * 0.04 = 0.66: stakes back 0.08 + 0.32/9, the rest 4.9/9 shared
    # 1 : 1 : 8/9 : 0 (of 26/9). The deposit then finds an empty round trip: the buyer keeps the reward.
    events = [LedgerEvent("purchase", 0, 1, 0, 10.0, 1)] + [
        LedgerEvent("purchase", 0, s, 0, d, 3) for s, d in ((2, 10.0), (3, 20.0), (4, 100.0))] + [
        LedgerEvent("deposit", 0, step=6)]
    out = replay_events(events, 5, scheme="consensus_slash", stake=0.04, params={"slash_angle": 90.0},
                        stake_expiry=5)
    rest = 4.9 / 9
    weights = [0.04 + rest * 9 / 26, 0.04 + rest * 9 / 26, 0.04 * 8 / 9 + rest * 8 / 26, 0.0]
    assert list(out.balances) == pytest.approx([1.5, *(0.96 + w for w in weights)], abs=1e-12)

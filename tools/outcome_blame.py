"""How much blame outcome-based trust puts on honest sellers, with and without liars in the swarm.

    .venv/bin/python tools/outcome_blame.py --seeds 4 --steps 15000
    .venv/bin/python tools/outcome_blame.py --honest vote_k --params '{"k": 2, "horizon": 1000}'
    .venv/bin/python tools/outcome_blame.py --honest outcome_trust --params '{"provenance": 1}'
    .venv/bin/python tools/outcome_blame.py --honest outcome_trust --scheme outcome_slash --stake 0.04

The ``outcome_trust`` buyer blames every seller whose vector it used when a trip fails.  An honest robot
that bought a lie, averaged it in and sold the result is blamed for it, as are honest sellers whose old
vectors drifted too far.  The script runs 25 robots (``outcome_trust`` and 0 or ``--liars`` saboteurs
rotating by ``--rotation`` degrees, which buy as naive robots and so resell too) and, from every buyer's
records at the end, reports for honest sellers and for liars: the share of their judged trips that failed
(bad / (good + bad), pooled over buyers), the share of (buyer, seller) records whose Beta mean is below
``distrust`` (sellers that buyer no longer buys from) and items per honest robot; the naive swarm's items
beside it.  Under outlier penalisation without stake, as docs/defences.md's other tables, unless
``--scheme`` / ``--stake`` say otherwise; with a stake it also reports the stake each honest robot and each
liar lost (locked in sales and not paid back), on average.  With ``"provenance": 1`` the records are of the
vectors' origins, so "honest sellers" reads "honest origins".
"""
from __future__ import annotations

import argparse
import json

import numpy as np

import infomarket as im
from infomarket.engine.simulation import Simulation


def run(honest: str, liars: int, seed: int, steps: int, rotation: float, params: dict, scheme: str = "outlier",
        stake: float = 0.0, pparams: dict | None = None) -> dict:
    """One run: items per honest robot (and, with a stake, the stake lost per honest robot and per liar)
    and, for ``outcome_trust`` buyers, the pooled records."""
    groups = [{"behaviour": honest, "count": 25 - liars, "params": params}]
    if liars:
        groups.append({"behaviour": "saboteur", "count": liars, "params": {"rotation_angle": rotation}})
    cfg = im.Experiment.model_validate({"steps": steps, "swarm": {"robots": 25, "groups": groups},
                                        "payment": {"scheme": scheme, "stake": stake,
                                                    "params": pparams or {}}})
    sim = Simulation(cfg, seed)
    result = sim.run()
    out = {"items": float(result.robots.items_collected[:25 - liars].mean())}
    if stake > 0:
        lost = sim.world.rep_stake_lost
        out["honest_stake_lost"] = float(lost[:25 - liars].mean())
        out["liar_stake_lost"] = float(lost[25 - liars:].mean()) if liars else float("nan")
    if honest != "outcome_trust":
        return out
    w = sim.world
    prior, distrust = params.get("prior", 1.0), params.get("distrust", 0.3)
    tally = {"honest": [0.0, 0.0, 0, 0], "liar": [0.0, 0.0, 0, 0]}  # good, bad, records, distrusted
    for buyer in range(25 - liars):
        for j in range(w.trust_seller.shape[1]):
            s = int(w.trust_seller[buyer, j])
            if s < 0:
                continue
            good, bad = float(w.trust_good[buyer, j]), float(w.trust_bad[buyer, j])
            t = tally["liar" if s >= 25 - liars else "honest"]
            t[0] += good
            t[1] += bad
            t[2] += 1
            t[3] += (good + prior) / (good + bad + 2 * prior) < distrust
    for who, (good, bad, records, low) in tally.items():
        out[f"{who}_failed"] = bad / (good + bad) if good + bad else float("nan")
        out[f"{who}_distrusted"] = low / records if records else float("nan")
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--steps", type=int, default=15000)
    ap.add_argument("--liars", type=int, default=3)
    ap.add_argument("--rotation", type=float, default=90.0)
    ap.add_argument("--honest", default="naive,outcome_trust", help="the honest behaviours, comma-separated")
    ap.add_argument("--params", default="{}", help="the honest behaviours' parameters, as JSON")
    ap.add_argument("--scheme", default="outlier", help="the payment scheme")
    ap.add_argument("--stake", type=float, default=0.0, help="the stake per sale")
    ap.add_argument("--payment-params", default="{}", help="the scheme's parameters, as JSON")
    args = ap.parse_args()
    params = json.loads(args.params)
    for honest in args.honest.split(","):
        for liars in (0, args.liars):
            rows = [run(honest, liars, s, args.steps, args.rotation, params, args.scheme, args.stake,
                        json.loads(args.payment_params))
                    for s in range(args.seeds)]
            cells = []
            for key in rows[0]:
                v = np.array([r[key] for r in rows])
                if np.isnan(v).all():
                    continue  # no liars: nothing to say about them
                cells.append(f"{key} {np.nanmean(v):.3f} ± {np.nanstd(v):.3f}")
            print(f"{honest:14s} liars {liars}: " + ", ".join(cells), flush=True)


if __name__ == "__main__":
    main()

"""A seller that lies about the age of its information: it claims its vector is brand new."""
import infomarket as im
from infomarket.behaviours.api import own_entry


@im.behaviour("age_liar", buy="naive", honest=False,
              description="sells its true vector but claims it is claimed_age steps old")
def age_liar_sell(w, me, site, claimed_age=0.0):
    valid, x, y, age = own_entry(w, me, site)
    return valid, x, y, int(claimed_age)

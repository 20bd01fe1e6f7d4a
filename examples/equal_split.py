"""A payment scheme that pays every seller of a round trip the same, however often it sold."""
import infomarket as im


@im.payment("equal_split", description="each seller of the round trip gets an equal share")
def equal_split(buyer, sellers, sites, directions, weights):
    for x in range(len(sellers)):
        sales = 0
        for y in range(len(sellers)):
            if sellers[y] == sellers[x]:
                sales += 1
        weights[x] = 1.0 / sales  # a seller's transactions add up to one share

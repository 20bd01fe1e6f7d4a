"""List nodes: each buyer's open transactions on a branch, as a node of a shared store (``ls_*``) whose
predecessors are the rest of the list; the same reveal appended to the same list is the same node on
every branch, so a settled list's weights are kept by its node.  The ledger arrays' pool gets a list
only when it is read (``materialise``)."""
import math

from ...jit import njit

from ...state.view import unlock
from ..pool import reserve


@njit(cache=True)
def append_node(w, buyer, prev, seq, seller, site, direction, step, stake):
    """The list node after ``prev`` (-1: a first one) of buyer's list recording reveal ``seq``: an
    existing one with the same content, else a new one (``ls_top``; the host keeps room).  A list is
    then one node whatever branch made it, and a settled list's cached weights serve every branch."""
    x = w.ls_first_child[prev] if prev >= 0 else w.ls_roots[buyer]
    first = x
    while x >= 0:
        if (w.ls_seq[x] == seq and w.ls_stake[x] == stake
                and math.copysign(1.0, w.ls_stake[x]) == math.copysign(1.0, stake)):
            return x
        x = w.ls_next_sibling[x]
    top = w.ls_top[0]
    unlock(w.ls_seller)[top] = seller
    unlock(w.ls_site)[top] = site
    unlock(w.ls_dir)[top] = direction
    unlock(w.ls_step)[top] = step
    unlock(w.ls_stake)[top] = stake
    unlock(w.ls_prev)[top] = prev
    unlock(w.ls_len)[top] = (w.ls_len[prev] if prev >= 0 else 0) + 1
    unlock(w.ls_seq)[top] = seq
    unlock(w.ls_buyer)[top] = buyer
    unlock(w.ls_first_child)[top] = -1
    unlock(w.ls_next_sibling)[top] = first
    unlock(w.ls_weights_at)[top] = -1
    if prev >= 0:
        unlock(w.ls_first_child)[prev] = top
    else:
        unlock(w.ls_roots)[buyer] = top
    unlock(w.ls_top)[0] = top + 1
    return top


@njit(cache=True)
def cached_weights(w, v, k):
    """The k weights cached for list node v (``cache_weights``), as the same array type a fresh weighing
    gives (the settlement reads them; only ledger operations may unlock ledger arrays)."""
    return unlock(w.weight_store)[w.ls_weights_at[v]:w.ls_weights_at[v] + k]


@njit(cache=True)
def cache_weights(w, v, weights):
    """Keep the weights of list v (its ls_len[v] transactions) for the next settlement of the same list, if
    the cache has room (the host packs it with the lists)."""
    top = w.weight_top[0]
    k = weights.shape[0]
    if top + k > w.weight_store.shape[0]:
        return
    wt = unlock(w.weight_store)
    for x in range(k):
        wt[top + x] = weights[x]
    unlock(w.ls_weights_at)[v] = top
    unlock(w.weight_top)[0] = top + k


@njit(cache=True)
def weighed_before(w, buyer):
    """Has the buyer's list in the state being applied (``state_list``) been weighed on some branch, with a
    scheme that reads nothing but the list (``chn_cache``)?"""
    v = w.state_list[buyer]
    return w.chn_cache and v >= 0 and w.ls_weights_at[v] >= 0


@njit(cache=True)
def weights_of(w, buyer):
    """The weights kept for the buyer's list (``weighed_before``)."""
    return cached_weights(w, w.state_list[buyer], w.tx_count[buyer])


@njit(cache=True)
def keep_weights(w, buyer, weights):
    """Keep the weights the scheme gave the buyer's list, when it reads nothing but the list."""
    v = w.state_list[buyer]
    if w.chn_cache and v >= 0:
        cache_weights(w, v, weights)


@njit(cache=True)
def materialise(w, i):
    """Buyer i's open transactions in the ledger arrays' pool are its list in the current state
    (``state_list``): nothing to do if the pool holds that list; only the nodes after it if the pool holds a
    list it extends; else the whole list."""
    v = w.state_list[i]
    held = w.pool_list[i]
    if held == v:
        return
    k = w.ls_len[v] if v >= 0 else 0
    h = w.ls_len[held] if held >= 0 else 0
    x = v  # is the held list a beginning of v's?  (a node is the list that ends with it)
    while x >= 0 and w.ls_len[x] > h:
        x = w.ls_prev[x]
    if x != held:
        h = 0
    unlock(w.tx_count)[i] = h  # what reserve moves if the block must move
    reserve(w, i, k)  # the host keeps room (chain_needs)
    a = w.tx_off[i]
    seller, site, dirs = unlock(w.tx_seller), unlock(w.tx_site), unlock(w.tx_dir)
    step, stake = unlock(w.tx_step), unlock(w.tx_stake)
    x = v
    while x >= 0 and w.ls_len[x] > h:  # the nodes after the held beginning, last first
        p = a + w.ls_len[x] - 1
        seller[p] = w.ls_seller[x]
        site[p] = w.ls_site[x]
        dirs[p] = w.ls_dir[x]
        step[p] = w.ls_step[x]
        stake[p] = w.ls_stake[x]
        x = w.ls_prev[x]
    unlock(w.tx_count)[i] = k
    unlock(w.pool_list)[i] = v


@njit(cache=True)
def materialise_all(w):
    """Every buyer's list of the current state in the pool (nothing to do unless a list changed since the
    last call: ``pool_stale``)."""
    if not w.pool_stale[0]:
        return
    for i in range(w.balance.shape[0]):
        materialise(w, i)
    unlock(w.pool_stale)[0] = False

"""Chains of beams: beams joined end to end, which exact stick treats as one beam (``contact.system``)."""
import numpy as np

__all__ = ["beam_chains"]


def beam_chains(model):
    """``(root, count)`` ``(n_beams,)``: for each beam of ``model`` the first beam (smallest id) and the element count
    of its chain, the beams joined end to end (``model.join`` of an end node of one beam to an end node of another, or
    an end node shared; a join through a node outside beams, such as a plate's, does not chain).  A wire made of
    pieces is one chain: exact stick keys its mortar groups by the master's chain (``CHAIN_GROUPS``) and takes the
    slave's length for ``c`` from its chain (``CHAIN_C``; docs/theory_mortar.md 3b, 3d)."""
    beams = model.beams
    end = {}
    for k, b in enumerate(beams):
        end.setdefault(int(b.first), []).append(k)
        end.setdefault(int(b.last), []).append(k)
    parent = list(range(len(beams)))

    def find(k):
        while parent[k] != k:
            parent[k] = parent[parent[k]]
            k = parent[k]
        return k

    def union(i, j):
        i, j = find(i), find(j)
        parent[max(i, j)] = min(i, j)

    for a, b in model.joins:
        for i in end.get(int(a), ()):
            for j in end.get(int(b), ()):
                union(i, j)
    for ks in end.values():              # beams sharing an end node
        for i in ks[1:]:
            union(i, ks[0])
    root = np.array([find(k) for k in range(len(beams))], dtype=np.int64)
    count = np.bincount(root, weights=[b.n_elements for b in beams], minlength=len(beams))
    return root, count[root].astype(np.int64)

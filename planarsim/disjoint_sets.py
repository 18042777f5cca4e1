"""Disjoint sets of bodies (union-find with path halving): which bodies joints tie together."""
from __future__ import annotations


class DisjointSets:
    """n nodes, each its own set until joined."""

    def __init__(self, n: int):
        self.parent = list(range(n))

    def root(self, i: int) -> int:
        """The representative of node i's set."""
        parent = self.parent
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    def join(self, a: int, b: int) -> bool:
        """Join the sets of a and b; False if they were one set already (a loop)."""
        ra, rb = self.root(a), self.root(b)
        if ra == rb:
            return False
        self.parent[ra] = rb
        return True

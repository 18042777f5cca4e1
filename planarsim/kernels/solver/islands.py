"""Islands: the rows of a step grouped by the bodies they link, each group solved on its own.

Bodies linked by a row (a joint, a joint limit, a contact between two bodies) belong to one
island; the ground and the world's shapes link nothing (they cannot move). The rows of two
islands share no body, so their matrix J W J^T is block diagonal and its complementarity
problem falls apart into one problem per island: ten separate piles are ten small dense
problems (work ~ sum of n_k^3), not one large one (~ (sum n_k)^3). The grouping is a
union-find over the rows' bodies, O(rows + bodies) per grouping; a step with one island solves
exactly as it did without islands (the same rows in the same order).
"""
from ...compile import kernel


@kernel
def _root(parent, i):
    """The representative of body i's island (path halving)."""
    while parent[i] != i:
        parent[i] = parent[parent[i]]
        i = parent[i]
    return i


@kernel
def group_rows(ws, n):
    """Rows 0..n-1 grouped by island into ws.island_rows (each island's rows in their order;
    island k holds ws.island_rows[ws.island_start[k]:ws.island_start[k + 1]], islands in the
    order of their first row); ws.row_island[r] is row r's island. Returns the number of
    islands."""
    parent = ws.island_parent
    for i in range(parent.shape[0]):
        parent[i] = i
        ws.island_label[i] = -1
    for r in range(n):
        a = ws.row_body[r, 0]
        b = ws.row_body[r, 1]
        if a >= 0 and b >= 0:
            ra = _root(parent, a)
            rb = _root(parent, b)
            if ra != rb:
                parent[max(ra, rb)] = min(ra, rb)
    count = 0
    for r in range(n):
        body = ws.row_body[r, 1]
        if body < 0:
            body = ws.row_body[r, 0]     # a world shape's point on a body's face
        root = _root(parent, body)
        if ws.island_label[root] < 0:
            ws.island_label[root] = count
            count += 1
        ws.row_island[r] = ws.island_label[root]
    for k in range(count + 1):
        ws.island_start[k] = 0
    for r in range(n):
        ws.island_start[ws.row_island[r] + 1] += 1
    for k in range(count):
        ws.island_start[k + 1] += ws.island_start[k]
        ws.island_fill[k] = ws.island_start[k]
    for r in range(n):
        k = ws.row_island[r]
        ws.island_rows[ws.island_fill[k]] = r
        ws.island_fill[k] += 1
    return count

"""Islands: rows grouped by the bodies they link (union-find), and separate piles solved as
separate problems give the answers each pile gets alone."""
import numpy as np
from hypothesis import given, settings, strategies as st
from numba import njit

import planarsim as ps
from planarsim.compiled import audit_counts
from planarsim.compile import options as compile_options
from planarsim.kernels.solver.islands import group_rows
from planarsim.state import make_workspace

jit = njit(**dict(compile_options(), cache=False))


@jit
def _group(ws, n):
    return group_rows(ws, n)


def _components(n_body, links):
    """Reference: connected components of the bodies by breadth-first search."""
    adj = [[] for _ in range(n_body)]
    for a, b in links:
        if a >= 0 and b >= 0:
            adj[a].append(b)
            adj[b].append(a)
    comp = [-1] * n_body
    for s in range(n_body):
        if comp[s] >= 0:
            continue
        comp[s], todo = s, [s]
        while todo:
            for w in adj[todo.pop()]:
                if comp[w] < 0:
                    comp[w] = s
                    todo.append(w)
    return comp


def _bodies(n):
    b = ps.ModelBuilder()
    for k in range(n):
        b.add_point_mass(f"p{k}", 1.0, pos=(float(k), 1.0))
        b.add_point_contact(f"c{k}", f"p{k}")
    return b.compile()


@settings(max_examples=200, deadline=None)
@given(data=st.data(), n_body=st.integers(1, 12))
def test_rows_are_grouped_by_the_bodies_they_link(data, n_body):
    body = st.integers(-1, n_body - 1)
    links = data.draw(st.lists(st.tuples(body, st.integers(0, n_body - 1)), min_size=0, max_size=30))
    ws = make_workspace(_bodies(n_body))
    ws = ws._replace(row_body=np.zeros((max(len(links), 1), 2), np.int64),
                     island_rows=np.zeros(max(len(links), 1), np.int64),
                     row_island=np.zeros(max(len(links), 1), np.int64))
    for r, (a, b) in enumerate(links):
        ws.row_body[r] = (a, b)
    count = _group(ws, len(links))
    comp = _components(n_body, links)
    grouped = ws.island_rows[:len(links)]
    assert sorted(grouped) == list(range(len(links))), "every row once"
    for k in range(count):
        rows = grouped[ws.island_start[k]:ws.island_start[k + 1]]
        assert len(rows) > 0 and np.all(np.diff(rows) > 0), "an island's rows in their order"
        assert len({comp[links[r][1]] for r in rows}) == 1, "one component per island"
    islands_of = {}
    for r, (a, b) in enumerate(links):
        islands_of.setdefault(comp[b], set()).add(ws.row_island[r])
    assert all(len(v) == 1 for v in islands_of.values()), "one island per component"
    assert count == len(islands_of)


def _pile(b, x0, tag):
    """Three boxes of 1, 2 and 3 kg on flat ground: the middle one resting on the first, the
    third sliding at 2 m/s into them."""
    w, h = 0.4, 0.2
    for j, (x, y, vx) in enumerate(((0.0, 0.1, 0.0), (0.05, 0.3, 0.0), (-0.8, 0.1, 2.0))):
        mass = 1.0 + j
        b.add_body(f"{tag}{j}", mass, mass * (w * w + h * h) / 12, pos=(x0 + x, y),
                   vel=(vx, 0.0), shapes=[("box", (0.0, 0.0), w, h, {"mu": 0.3})])


def test_separate_piles_move_as_each_alone():
    """Two such piles 5 m apart in one model end where each ends alone, to 1e-9 m (the
    islands' problems are solved apart; the mode check they share may send both to the
    complementarity solve where one alone keeps its linear answer: rounding), with a clean
    audit and the third box stopped by the others."""
    ends = []
    for tags in (("a",), ("b",), ("a", "b")):
        b = ps.ModelBuilder(dt=1e-3)
        for tag in tags:
            _pile(b, 0.0 if tag == "a" else 5.0, tag)
        sim = ps.Simulator(b.compile())
        sim.steps(1500)
        assert all(v == 0 for v in audit_counts(sim.ws).values())
        ends.append(sim.state.q.copy())
    assert ends[0][2, 0] < ends[0][0, 0] - 0.39, "the sliding box ends against the pile"
    together = ends[2]
    assert np.allclose(together[:3], ends[0], rtol=0, atol=1e-9)
    assert np.allclose(together[3:], ends[1], rtol=0, atol=1e-9)

"""Stage 2's broad phase: which pairs of shapes may touch, and the contacts a step visits.

Sweep and prune. Each shape's bounding circle is placed at the configuration
(pair.place_shapes: centre (x, y), radius R, a bound v on its points' speed) and widened by
its share of a pair's margin, e = margin / 2 + SPECULATIVE_FACTOR h v (plus rounding), to the
box [x - R - e, x + R + e] x [y - R - e, y + R + e]. Two shapes whose boxes do not overlap are
farther apart than the exact test of pair.find_pair asks (R_a + R_b + margin +
SPECULATIVE_FACTOR h (v_a + v_b) between the centres), so the pairs this sweep skips are the
pairs that test would find apart: the same answers, without visiting every pair of the model.
The shapes stay sorted by their boxes' left ends (insertion sort from the last step's order:
nearly sorted from step to step, O(n) then); the sweep visits only boxes that overlap on x.
Cost: O(shapes + pairs overlapping on x) a step, where testing every pair is O(shapes^2).

The contacts a step visits (ws.live, ascending): every ground contact, and both slots of each
pair the sweep found. A pair that leaves the list is cleared as find_pair clears a pair with
no manifold point (free, no features, no impulse), so a contact outside the list is always
free, far and without impulse, and every stage may loop over the list alone. A model without
shapes has every contact in the list, once (make_workspace), and never calls this module.
"""
from ...compile import kernel
from .pair import SPECULATIVE_FACTOR, _speed_bound, clear_slot, place_shapes
from ..prev_copy import add_synced

# relative widening of a shape's box [-] and its absolute floor [m]: the rounding of the box's
# ends, so that the sweep never skips a pair the exact test would keep
SWEEP_ROUNDING = 1e-12
SWEEP_FLOOR = 1e-15
# ws.pair_flag bits of a pair's slot 0
FLAG_LIVE = 1          # in this step's list (ws.live_pairs)
FLAG_WAS_LIVE = 2      # in the last step's list, not yet seen in this one's


@kernel
def _place_boxes(ws, margin, h):
    """ws.sweep_box[k] = (left, right, bottom, top) [m] of shape k's widened bounding circle."""
    for k in range(ws.shape_reach.shape[0]):
        x = ws.shape_reach[k, 0]
        y = ws.shape_reach[k, 1]
        e = ws.shape_reach[k, 2] + 0.5 * margin + SPECULATIVE_FACTOR * h * ws.shape_reach[k, 3]
        e += SWEEP_ROUNDING * (abs(x) + abs(y) + e) + SWEEP_FLOOR
        ws.sweep_box[k, 0] = x - e
        ws.sweep_box[k, 1] = x + e
        ws.sweep_box[k, 2] = y - e
        ws.sweep_box[k, 3] = y + e


@kernel
def _sort_by_left(ws):
    """ws.sweep_order: the shapes by their boxes' left ends (insertion sort of the last order)."""
    order = ws.sweep_order
    for i in range(1, order.shape[0]):
        k = order[i]
        left = ws.sweep_box[k, 0]
        j = i - 1
        while j >= 0 and ws.sweep_box[order[j], 0] > left:
            order[j + 1] = order[j]
            j -= 1
        order[j + 1] = k


@kernel
def _sift_down(a, root, end):
    """Restore the max-heap a[:end] below root (heap_sort)."""
    while True:
        child = 2 * root + 1
        if child >= end:
            return
        if child + 1 < end and a[child + 1] > a[child]:
            child += 1
        if a[root] >= a[child]:
            return
        a[root], a[child] = a[child], a[root]
        root = child


@kernel
def _sort_ints(a, n):
    """a[:n] ascending, in place (heap sort: O(n log n) whatever the order; the sweep emits
    the pairs of a pile or a wall in the order of its boxes' left ends, far from their slots'
    order, where an insertion sort took O(n^2))."""
    for root in range(n // 2 - 1, -1, -1):
        _sift_down(a, root, n)
    for end in range(n - 1, 0, -1):
        a[0], a[end] = a[end], a[0]
        _sift_down(a, 0, end)


@kernel
def sweep_pairs(ws, margin, h, out):
    """The pairs of the model (as their slot-0 contact) whose shapes' boxes, widened for a
    pair margin [m] and a step of h [s], overlap: into out, ascending; returns how many.
    The shapes must be placed (pair.place_shapes)."""
    _place_boxes(ws, margin, h)
    _sort_by_left(ws)
    order = ws.sweep_order
    n_shape = order.shape[0]
    count = 0
    for i in range(n_shape):
        a = order[i]
        right = ws.sweep_box[a, 1]
        for j in range(i + 1, n_shape):
            b = order[j]
            if ws.sweep_box[b, 0] > right:
                break
            if ws.sweep_box[b, 2] > ws.sweep_box[a, 3] or ws.sweep_box[a, 2] > ws.sweep_box[b, 3]:
                continue
            p = ws.shape_pair_slot[a, b]
            if p >= 0:
                out[count] = p
                count += 1
    _sort_ints(out, count)
    return count


@kernel
def merge_contacts(ground, pairs, n_pairs, out):
    """out <- the ground contacts (ascending) and both slots of pairs[:n_pairs] (slot-0
    contacts, ascending), merged in ascending order; returns how many."""
    n = 0
    g = 0
    p = 0
    while g < ground.shape[0] or p < n_pairs:
        if p >= n_pairs or (g < ground.shape[0] and ground[g] < pairs[p]):
            out[n] = ground[g]
            n += 1
            g += 1
        else:
            out[n] = pairs[p]
            out[n + 1] = pairs[p] + 1
            n += 2
            p += 1
    return n


@kernel(inline="never")
def update_live(m, s, ws, margin, h):
    """The step's pairs (sweep_pairs for the pair margin [m] and step h [s]) and contacts
    (ws.live); a pair that left since the last call is cleared (both slots: free, no features,
    no impulse, not new, gap inf). Returns the number of pairs listed."""
    for k in range(ws.n_live_pairs[0]):
        ws.pair_flag[ws.last_pairs[k]] = FLAG_WAS_LIVE
    n = sweep_pairs(ws, margin, h, ws.live_pairs)
    for k in range(n):
        ws.pair_flag[ws.live_pairs[k]] = FLAG_LIVE
        add_synced(s, ws, ws.live_pairs[k])     # (its slots may change: prev_copy.py)
    for k in range(ws.n_live_pairs[0]):
        p = ws.last_pairs[k]
        if ws.pair_flag[p] == FLAG_WAS_LIVE:
            ws.pair_flag[p] = 0
            for c in range(p, p + 2):
                clear_slot(s, ws, c)
                ws.contact_impulse[c, 0] = 0.0
                ws.contact_impulse[c, 1] = 0.0
                ws.contact_new[c] = 0
                ws.contact_candidate[c] = 0
                ws.contact_held[c] = 0
    for k in range(n):
        ws.last_pairs[k] = ws.live_pairs[k]
    ws.n_live_pairs[0] = n
    ws.n_live[0] = merge_contacts(ws.ground_contacts, ws.live_pairs, n, ws.live)
    return n


@kernel
def widen_for_answer(m, s, ws, h, margin):
    """After a part's solve: a body the solve set moving faster than the sweep of its start
    assumed (a ball struck at rest within a step, then at 30 m/s) may meet shapes no listed
    pair holds. Where a shape's speed bound under the answer (ws.v_new) exceeds the one its
    box was widened for, the pairs are listed again (update_live) with boxes that also cover
    the answer; the pairs that join (apart: their slots free) are left to the sweep after the
    solve (pair_toi.pair_impact_time), which splits the step where they touch. The boxes
    only grow, so no listed pair leaves; ws.shape_reach is placed again as it was (its speed
    bounds are the ones stage 2 judged the pairs by). Returns the pairs added."""
    grow = False
    for k in range(m.shape_body.shape[0]):
        if _speed_bound(m, ws.v_new, m.shape_body[k], k) > ws.shape_reach[k, 3]:
            grow = True
            break
    if not grow:
        return 0
    for k in range(m.shape_body.shape[0]):
        ws.shape_reach[k, 3] = max(ws.shape_reach[k, 3], _speed_bound(m, ws.v_new, m.shape_body[k], k))
    listed = ws.n_live_pairs[0]
    added = update_live(m, s, ws, margin, h) - listed
    place_shapes(m, s.q, ws.body_cs, s.v, ws.v_pred, ws)
    return added

"""The State kept at a step's start (Workspace.prev), copied at the cost of what is listed.

A step begins by keeping its State in ws.prev: to be taken again from there (sub-steps, a
guard, more storage) and to name it in an error. The bodies', joints' and ground contacts'
arrays are a model's size; the shape pairs' contact slots are two per pair of shapes that may
touch (a 1,035-box pyramid has 1.07 million, about 60 MB), of which a step visits only the
pairs the broad phase lists. So the slots are copied only where the State can differ from
ws.prev:

- after a copy into prev, the two agree on every slot;
- a step changes the State's contact slots only through the listed contacts (ws.live: the
  ground contacts and both slots of each listed pair) and by clearing the pairs that leave the
  list (broad_phase.update_live);
- so they can differ only at the ground contacts and at the pairs listed at the last copy or
  since (ws.sync_pairs: update_live adds each pair it lists that is not there yet).

Whatever changes the State otherwise sets ws.prev_whole, and the next copy takes every slot:
each call from Python (link/step.py: run_steps and run_recorded set it as they begin and
as they return, step_entry as it returns: the State may be put in or changed in place
between calls), a step begun again from ws.start, the step's
impulses forgotten (step.forget_impulses). So within one call of Simulator.steps(n) the steps
after the first copy only the listed slots; Simulator.step() copies them all. A pair that
joins the list has its slots copied into ws.prev as they are then (add_synced): a compiled
loop of one's own that changes the State between its calls of `step` thus still begins a
step again from what it put in; only ws.prev's pairs never listed since (an error's
last_state) may miss such a change, unless the loop sets ws.prev_whole[0] = 1.
"""
from ..compile import kernel


@kernel
def _copy1(src, dst):
    for i in range(src.shape[0]):
        dst[i] = src[i]


@kernel
def _copy2(src, dst):
    for i in range(src.shape[0]):
        for k in range(src.shape[1]):
            dst[i, k] = src[i, k]


@kernel
def _copy_all_but_slots(src, dst):
    """dst <- src on every array but the contact slots' (bodies, time, joints, forces)."""
    _copy2(src.q, dst.q)
    _copy2(src.v, dst.v)
    _copy1(src.time, dst.time)
    _copy1(src.step, dst.step)
    _copy2(src.limit_active, dst.limit_active)
    _copy1(src.mode_cursor, dst.mode_cursor)
    _copy2(src.ext_force, dst.ext_force)
    _copy2(src.last_pin_impulse, dst.last_pin_impulse)
    _copy1(src.last_rod_impulse, dst.last_rod_impulse)


@kernel(inline="always")
def copy_state(src, dst):
    """dst <- src, array by array (dst is a State of the same shapes; no allocation)."""
    _copy_all_but_slots(src, dst)
    _copy1(src.contact_mode, dst.contact_mode)
    _copy1(src.contact_slip, dst.contact_slip)
    _copy1(src.contact_enabled, dst.contact_enabled)
    _copy2(src.last_contact_impulse, dst.last_contact_impulse)
    _copy1(src.contact_feature, dst.contact_feature)
    _copy1(src.contact_dependent, dst.contact_dependent)


@kernel
def _copy_slot(src, dst, c):
    """dst's contact slot c <- src's."""
    dst.contact_mode[c] = src.contact_mode[c]
    dst.contact_slip[c] = src.contact_slip[c]
    dst.contact_enabled[c] = src.contact_enabled[c]
    dst.last_contact_impulse[c, 0] = src.last_contact_impulse[c, 0]
    dst.last_contact_impulse[c, 1] = src.last_contact_impulse[c, 1]
    dst.contact_feature[c] = src.contact_feature[c]
    dst.contact_dependent[c] = src.contact_dependent[c]


@kernel
def _copy_listed(src, dst, ws):
    """dst <- src where they can differ (the module's docstring): every array but the
    contact slots, which are copied at the ground contacts and the slots of ws.sync_pairs."""
    _copy_all_but_slots(src, dst)
    for k in range(ws.ground_contacts.shape[0]):
        _copy_slot(src, dst, ws.ground_contacts[k])
    for k in range(ws.n_sync_pairs[0]):
        p = ws.sync_pairs[k]
        _copy_slot(src, dst, p)
        _copy_slot(src, dst, p + 1)


@kernel
def list_synced(ws):
    """ws.sync_pairs <- the pairs listed now (ws.last_pairs), each marked in ws.pair_synced;
    the marks of those it held cleared first."""
    for k in range(ws.n_sync_pairs[0]):
        ws.pair_synced[ws.sync_pairs[k]] = 0
    n = ws.n_live_pairs[0]
    for k in range(n):
        p = ws.last_pairs[k]
        ws.sync_pairs[k] = p
        ws.pair_synced[p] = 1
    ws.n_sync_pairs[0] = n


@kernel
def add_synced(s, ws, p):
    """Pair p (its slot-0 contact) listed: into ws.sync_pairs unless there already, its slots
    copied into ws.prev as they are (the step has not changed them since its start: a change
    put in from outside between steps is then kept if the step begins again)."""
    if ws.pair_synced[p] == 0:
        ws.pair_synced[p] = 1
        ws.sync_pairs[ws.n_sync_pairs[0]] = p
        ws.n_sync_pairs[0] += 1
        _copy_slot(s, ws.prev, p)
        _copy_slot(s, ws.prev, p + 1)


@kernel
def keep_prev(s, ws):
    """ws.prev <- s (a step's start): every slot where ws.prev_whole says so,
    else the listed ones (the module's docstring); then the pairs listed now are the ones
    whose slots may change."""
    if ws.prev_whole[0] == 1:
        copy_state(s, ws.prev)
        ws.prev_whole[0] = 0
    else:
        _copy_listed(s, ws.prev, ws)
    list_synced(ws)


@kernel
def back_to_prev(s, ws):
    """s <- ws.prev (the step begun again from its start): every slot where ws.prev_whole
    says so, else the listed ones; they agree on every slot after."""
    if ws.prev_whole[0] == 1:
        copy_state(ws.prev, s)
        ws.prev_whole[0] = 0
    else:
        _copy_listed(ws.prev, s, ws)


@kernel
def keep_prev_bodies(s, ws):
    """keep_prev for a step that changes only the bodies' positions and velocities, the clock
    and the pins' impulses (the pin-chain path: a model of pins alone, without contacts,
    limits or rods, whose every step, by either path, changes nothing else): those arrays
    alone, unless ws.prev_whole asks for every one (the State was put in or changed from
    outside since the last copy)."""
    if ws.prev_whole[0] == 1:
        keep_prev(s, ws)
        return
    _copy2(s.q, ws.prev.q)
    _copy2(s.v, ws.prev.v)
    _copy1(s.time, ws.prev.time)
    _copy1(s.step, ws.prev.step)
    _copy2(s.last_pin_impulse, ws.prev.last_pin_impulse)

"""The audit of a step's contact impulses (kernels/checks/audit.audit_impulses) on impulses put in by
hand: its pull and cone rules allow rounding, and agree on what is rounding."""
import pytest
from numba import njit

import planarsim as ps
from planarsim.compile import options as compile_options
from planarsim.kernels.checks.audit import AUDIT_NAMES, IMPULSE_FLOOR, audit_impulses
from planarsim.kernels.codes import MODE_PINNED, MODE_SLIDING

jit = njit(**dict(compile_options(), cache=False))


@jit
def _audit(m, s, ws, opt, h):
    return audit_impulses(m, s, ws, opt, h)


def _box_on_two_corners(mu):
    b = ps.ModelBuilder(dt=1e-3)
    box = b.add_body("box", 1.0, 0.01, pos=(0.0, 0.1))
    b.add_point_contact("left", box, (-0.1, -0.1), mu=mu)
    b.add_point_contact("right", box, (0.1, -0.1), mu=mu)
    return ps.Simulator(b.compile())


@pytest.mark.parametrize("mu", [0.2, 1.0, 3.0])
def test_a_sliding_contact_whose_push_rounds_below_zero_is_on_its_cone(mu):
    """One corner carries the load (0.1 N s); the other slides with a push that rounds below
    zero, within the pull rule (0.8 of the floor IMPULSE_FLOOR of the largest impulse), and
    its friction is -mu s lambda_n, on the cone by construction: nothing is counted (the
    cone rule once counted it, by 2 mu times the push, for mu above 0.6). A push three times
    the floor below zero is counted as a pull."""
    sim = _box_on_two_corners(mu)
    m, s, ws = sim.model.arrays, sim.state, sim.ws
    floor = IMPULSE_FLOOR * 0.1
    s.contact_mode[0] = MODE_PINNED
    s.contact_mode[1] = MODE_SLIDING
    s.contact_slip[1] = 1.0
    ws.contact_impulse[0] = (0.1, 0.0)
    ws.v_new[:] = 0.0
    ws.v_pred[:] = 0.0
    pull = AUDIT_NAMES.index("pull")
    for push, pulls in ((-0.8 * floor, False), (-3.0 * floor, True)):
        ws.contact_impulse[1] = (push, -mu * push)       # friction -mu s lambda_n, s = 1
        ws.audit[:] = 0
        found = _audit(m, s, ws, sim.options, 1e-3)
        counts = dict(zip(AUDIT_NAMES, ws.audit.tolist()))
        if pulls:
            assert ws.audit[pull] == 1, (push, counts)
        else:
            assert found == 0, (push, counts)

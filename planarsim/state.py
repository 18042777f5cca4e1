"""State (what a run needs to resume bit for bit) and Workspace (what a step recomputes).

Both are NamedTuples of numpy arrays so that compiled kernels take them directly.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from . import memory
from .capacity import workspace_capacity, workspace_contacts  # noqa: F401  (public here too)
from .errors import WorkspaceTooLarge
from .kernels.checks.audit import N_AUDIT
from .kernels.info import N_INFO
from .kernels.codes import CONTACT_PAIR, DENSE_MAX_ROWS, N_BROKEN, SPARSE_MAX_DEPTH
from .model import Model
from .pin_chains import joints_form_no_loop, pin_chain_order


class State(NamedTuple):
    """Complete simulation state. Arrays are mutated in place by the kernels.

    q : (n_body, 3) [m, m, rad]          positions and angles of the body COMs
    v : (n_body, 3) [m/s, m/s, rad/s]    velocities
    time : (1,) [s]                       simulated time
    step : (1,) int                       steps taken
    contact_mode : (n_contact,) int       0 free, 1 pinned, 2 sliding
    contact_slip : (n_contact,) [-]       slip direction (+-1 along the ground tangent) when sliding
    contact_enabled : (n_contact,) int    0 disables a contact (it passes through the ground)
    limit_active : (n_pin, 2) int         lower / upper joint limit rows in use
    mode_cursor : (1,) int                the contact checked next by the alternating scheme
    ext_force : (n_body, 3) [N, N, N m]   external force and torque held until changed (pushes)
    last_contact_impulse : (n_contact, 2) [N s]   normal, tangential impulse of the last step
    last_pin_impulse : (n_pin, 4) [N s, N s, N m s, N m s]   x, y, lower, upper limit impulse
    last_rod_impulse : (n_rod,) [N s]     of the last step (the velocity solve's plus the share of
                                          the position correction's that became velocity, so that
                                          over a run they add up to the momentum the joint moved;
                                          a complementarity projection's are not included, and a
                                          step taken in turn sub-steps keeps its last one's); the
                                          next step's solve starts from
                                          them (kernels/solver/warm_start.py): a closed loop whose
                                          load split is not unique keeps the last one
    contact_feature : (n_contact,) int    the features a shape pair's slot touched with in the
                                          last step (-1: none; kernels/geometry/pair.py): a slot keeps its
                                          mode and impulse while they stay the same
    contact_dependent : (n_contact,) int  the contact's rows that the last sparse velocity solve
                                          (of this step or an earlier one) dropped as dependent
                                          on the others, or left out and found held (bit 1: the
                                          normal row, bit 2: the friction row; a pile at rest):
                                          the next sparse solve factors the others only and
                                          checks these rows' equations (kernels/solver/sparse_factor.py;
                                          a contact without rows keeps its bits)
    """
    q: np.ndarray
    v: np.ndarray
    time: np.ndarray
    step: np.ndarray
    contact_mode: np.ndarray
    contact_slip: np.ndarray
    contact_enabled: np.ndarray
    limit_active: np.ndarray
    mode_cursor: np.ndarray
    ext_force: np.ndarray
    last_contact_impulse: np.ndarray
    last_pin_impulse: np.ndarray
    last_rod_impulse: np.ndarray
    contact_feature: np.ndarray
    contact_dependent: np.ndarray

    @property
    def t(self) -> float:
        return float(self.time[0])

    def copy(self) -> "State":
        return State(*(a.copy() for a in self))

    def restore(self, other: "State") -> None:
        """Overwrite this state's arrays with `other`'s (bit for bit)."""
        for a, b in zip(self, other):
            a[...] = b

    def as_dict(self) -> dict:
        return {name: getattr(self, name).copy() for name in self._fields}

    @classmethod
    def from_dict(cls, d) -> "State":
        """The State of a dict of its arrays (as_dict); one saved before contact_dependent
        existed starts with none known dependent."""
        d = with_defaults(d)
        return cls(*(np.array(d[name]) for name in cls._fields))


def with_defaults(d) -> dict:
    """d (name -> array) with contact_dependent filled in where missing: zeros (no row known
    dependent; the first sparse solve factors every row, as a step always did before the
    field existed)."""
    d = dict(d)
    if "contact_dependent" not in d and "contact_mode" in d:
        d["contact_dependent"] = np.zeros(np.shape(d["contact_mode"]), np.int64)
    return d


STATE_DIMS = dict(  # shape of each State array; strings are the model's sizes
    q=("n_body", 3), v=("n_body", 3), time=(1,), step=(1,), contact_mode=("n_contact",),
    contact_slip=("n_contact",), contact_enabled=("n_contact",), limit_active=("n_pin", 2),
    mode_cursor=(1,), ext_force=("n_body", 3), last_contact_impulse=("n_contact", 2),
    last_pin_impulse=("n_pin", 4), last_rod_impulse=("n_rod",), contact_feature=("n_contact",),
    contact_dependent=("n_contact",))

# fields holding codes, not quantities: the values each may take and the rule's words
_STATE_CODES = dict(
    contact_mode=((0, 1, 2), "must be 0 (free), 1 (pinned) or 2 (sliding)"),
    contact_enabled=((0, 1), "must be 0 or 1"),
    limit_active=((0, 1), "must be 0 or 1"),
    contact_dependent=((0, 1, 2, 3), "must be 0..3 (bit 1: normal row, bit 2: friction row)"),
    contact_slip=((-1, 0, 1), "must be -1 or +1 (0: sliding solved without friction)"))

# the element that index 0 of a field counts (named in errors when the model is known)
_STATE_ELEMENT = dict(q="body", v="body", ext_force="body", contact_mode="contact",
                      contact_slip="contact", contact_enabled="contact",
                      last_contact_impulse="contact", limit_active="pin", last_pin_impulse="pin",
                      last_rod_impulse="rod", contact_feature="contact",
                      contact_dependent="contact")


def check_shapes(arrays, dims, what, sizes=None) -> dict:
    """Raise ValueError unless each arrays[name] has the shape dims[name] (ints: fixed sizes,
    strings: sizes shared by the arrays, taken from `sizes`, else from the first array that
    has them). The message names `what`.name, its shape and the one wanted. Returns the sizes."""
    sizes = dict(sizes or {})
    for name, want in dims.items():
        shape = np.shape(arrays[name])
        known = dict(sizes)
        if len(shape) == len(want):
            for d, n in zip(want, shape):
                if isinstance(d, str):
                    sizes.setdefault(d, n)
        if len(shape) != len(want) or any(sizes.get(d, d) != n for d, n in zip(want, shape)):
            spec = ", ".join(f"{d}={known[d]}" if d in known else str(d) for d in want)
            spec += "," if len(want) == 1 else ""
            raise ValueError(f"{what}.{name} has shape {shape}; it must be ({spec})")
    return sizes


def check_state(state, model: Model | None = None, what: str = "state") -> None:
    """Raise ValueError naming the field, index and value (and the body, contact, pin or rod
    when `model` is given) unless `state` is one the step can take: shapes as STATE_DIMS (the
    model's sizes, or sizes the arrays agree on), finite numbers [SI units], codes as
    _STATE_CODES, step an integer >= 0, mode_cursor in 0..n_contact-1 (0 without contacts),
    and, with a model, no active limit on a side where the pin has none."""
    arrays = dict(zip(State._fields, state))
    sizes = None if model is None else dict(n_body=model.n_body, n_contact=model.n_contact,
                                            n_pin=model.n_pin, n_rod=model.n_rod)
    sizes = check_shapes(arrays, STATE_DIMS, what, sizes)
    nc = sizes["n_contact"]
    rules = {name: (lambda a, v=values: np.isin(a, v), words)
             for name, (values, words) in _STATE_CODES.items()}
    rules["step"] = (lambda a: (a >= 0) & (a == np.floor(a)), "must be an integer >= 0")
    rules["contact_feature"] = (lambda a: (a >= -1) & (a == np.floor(a)),
                                "must be an integer >= -1")
    rules["mode_cursor"] = (lambda a: (a >= 0) & (a < max(nc, 1)) & (a == np.floor(a)),
                            f"must be in 0..{nc - 1}" if nc else "must be 0 (no contacts)")
    for name, a in arrays.items():
        a = np.asarray(a)
        if a.dtype.kind not in "biuf":
            raise ValueError(f"{what}.{name} has dtype {a.dtype}; it must hold numbers")
        test, words = rules.get(name, (np.isfinite, "must be finite"))
        ok = test(a)
        if name == "limit_active" and model is not None and np.all(ok):
            ok = (a == 0) | np.isfinite(model.arrays.pin_limit)
            words = "must be 0: the pin has no limit on that side"
        if not np.all(ok):
            i = tuple(int(k) for k in np.argwhere(~ok)[0])
            who = ""
            if model is not None and name in _STATE_ELEMENT:
                kind = _STATE_ELEMENT[name]
                who = f" ({kind} {getattr(model, kind + '_names')[i[0]]!r})"
            raise ValueError(f"{what}.{name}[{', '.join(map(str, i))}]={a[i].item()}{who} {words}")


def _body_rows(name, a, n_body):
    """a as a fresh (n_body, 3) float array: one row per body, exactly that shape (a transposed
    or flattened array would be read as other bodies' numbers)."""
    try:
        arr = np.array(a, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name}={a!r} must be numbers: one row (x, y, theta) per body of the "
                         f"model, shape ({n_body}, 3)") from None
    if arr.shape != (n_body, 3):
        raise ValueError(f"{name} has shape {arr.shape}; it must be ({n_body}, 3): one row "
                         f"(x, y, theta) per body of the model, in the model's body order")
    return arr.copy()


def make_state(model: Model, q=None, v=None) -> State:
    """Initial State of `model` (build pose and velocities unless q, v are given)."""
    nb, nc, npin = model.n_body, model.n_contact, model.n_pin
    q = _body_rows("q", model.q0 if q is None else q, nb)
    v = _body_rows("v", model.v0 if v is None else v, nb)
    return State(q=q, v=v, time=np.zeros(1), step=np.zeros(1, np.int64),
                 contact_mode=np.zeros(nc, np.int64), contact_slip=np.ones(nc),
                 contact_enabled=np.ones(nc, np.int64), limit_active=np.zeros((npin, 2), np.int64),
                 mode_cursor=np.zeros(1, np.int64), ext_force=np.zeros((nb, 3)),
                 last_contact_impulse=np.zeros((nc, 2)), last_pin_impulse=np.zeros((npin, 4)),
                 last_rod_impulse=np.zeros(model.n_rod),
                 contact_feature=np.full(nc, -1, np.int64),
                 contact_dependent=np.zeros(nc, np.int64))


class Workspace(NamedTuple):
    """Scratch arrays of one step (allocated once by make_workspace; a step never allocates).

    Rows are constraint equations; row r acts on bodies row_body[r] (a, b; -1 = world) with
    Jacobian blocks row_J[r, 0|1, :] and impulse directions row_F[r, 0|1, :] (they differ only
    for sliding contacts, whose impulse is lambda_n (n - mu s t)).
    A workspace belongs to one model: its contacts' last ground queries (contact_found) are of
    that model's terrain and contact points (forget_ground_queries when either changes).
    """
    force: np.ndarray            # (n_body, 3) applied forces [N, N, N m]
    body_cs: np.ndarray          # (n_body, 3) cos, sin of the body angles at the current q, and
                                 #   the angles they belong to (NaN: not computed yet)
    body_first_row: np.ndarray   # (n_body,) int first row touching each body (-1: none)
    row_first: np.ndarray        # (R,) int first row sharing a body with row r (envelope)
    row_reach: np.ndarray        # (R,) int last row r' whose envelope starts at or before r
    row_list: np.ndarray         # (R,) int scratch: the rows a column's elimination updates
    v_pred: np.ndarray           # (n_body, 3) unconstrained velocity v + h M^-1 f
    v_new: np.ndarray            # (n_body, 3) constrained velocity of the current solve
    v_lin: np.ndarray            # (n_body, 3) velocity the joints' second-order target is
                                 #   linearized at: v_pred and the soft rows' own answer
                                 #   (soft.soft_prediction)
    soft_joint: np.ndarray       # (n_pin,) int the joints with a soft row, in order
    soft_body: np.ndarray        # (n_pin, 2) int their bodies (-1: the world)
    soft_J: np.ndarray           # (n_pin, 2, 3) their rate rows g at the step's start
    soft_first: np.ndarray       # (n_pin,) int first soft row sharing a body with each (envelope)
    soft_start: np.ndarray       # (n_pin,) int where each row's envelope begins in soft_env
    soft_env: np.ndarray         # (soft_envelope_size,) L D L^T of G W G^T + Gamma, row by row
    soft_rhs: np.ndarray         # (n_pin,) its right-hand side, then the soft rows' impulses
    friction_slip: np.ndarray    # (n_pin,) a frictional joint's mode this step: 0 stuck (its
                                 #   row in the solve), +-1 slipping that way (its friction
                                 #   -F h slip in v_pred) (kernels/constraints/joint_friction.py)
    friction_bound: np.ndarray   # (n_pin,) F h [N m s or N s]: its impulse's bound this step
    friction_J: np.ndarray       # (n_pin, 2, 3) its rate row g at the step's start
    soft_mark: np.ndarray        # (n_body,) int first soft row touching each body (scratch)
    q_pred: np.ndarray           # (n_body, 3) predicted end-of-step configuration q + h v_pred
    cs_pred: np.ndarray          # (n_body, 3) cos, sin, angle of q_pred (as body_cs)
    q_keep: np.ndarray           # (n_body, 3) q and v before a Newton step of the position
    v_keep: np.ndarray           #   correction (put back if the step diverges)
    dq_correction: np.ndarray    # (n_body, 3) a position correction's move [m, rad] (Newton, projection)
    dv_correction: np.ndarray    # (n_body, 3) its change of velocity [m/s, rad/s] (joints: move / h)
    pin_impulse_moved: np.ndarray  # (n_pin, 4) [N s or N m s] the Newton correction's velocity
    rod_impulse_moved: np.ndarray  # (n_rod,) [N s]   impulses of this step, per joint row as in
                                 #   State.last_pin_impulse (integrate.record_moved_impulses)
    correction_kept: np.ndarray  # (1,) share of the correction's velocity change that
                                 #   bound_correction_work kept (1: all)
    q_solved: np.ndarray         # (n_body, 3) q integrated with v_solved, before the position
                                 #   correction (its work is measured from here)
    v_solved: np.ndarray         # (n_body, 3) velocity the contact solve ended at, before the
                                 #   position correction changed it (bound_correction_work)
    contact_point: np.ndarray    # (n_contact, 2) world contact point [m]
    contact_ground: np.ndarray   # (n_contact, 2) ground point below it [m]
    contact_normal: np.ndarray   # (n_contact, 2) unit ground normal
    contact_gap: np.ndarray      # (n_contact,) signed gap at step start [m]; of a contact
                                 #   left unqueried (contact_stale) a lower bound of it
    contact_stale: np.ndarray    # (n_contact,) int 1: a free point contact surely clear of the
                                 #   ground, not queried this step (its ground point and normal
                                 #   are an earlier step's; kernels/geometry/contacts.py)
    contact_found: np.ndarray    # (n_contact, 4) its body's pose (x, y, theta) and its gap
                                 #   where it was last queried (gap -inf: never)
    contact_anchor: np.ndarray   # (n_contact, 2) material contact point in the body frame [m]
    contact_impulse: np.ndarray  # (n_contact, 2) normal, tangential impulse of the step [N s]
    contact_held: np.ndarray     # (n_contact,) int 1 if the position correction held its normal row
    contact_on_arc: np.ndarray   # (n_contact,) int 1: the contact lies on a circular sole
    contact_new: np.ndarray      # (n_contact,) int 1: engaged during this step
    contact_bodies: np.ndarray   # (n_contact, 2) int the contact's reference body (-1: the
                                 #   ground or the world) and the body carrying its material
                                 #   point (a shape pair's roles change with its features)
    contact_dist: np.ndarray     # (n_contact,) int 1: a shape pair's gap is a distance between
                                 #   two core points (vertex on vertex), 0: from a face
    contact_face: np.ndarray     # (n_contact, 4) a pair's reference face in its body's frame:
                                 #   unit normal, and a point on the face's core line (or the
                                 #   core vertex where contact_dist) [m]
    contact_refpt: np.ndarray    # (n_contact, 5) the reference body's and the other body's
                                 #   material points where the contact touched at the step's
                                 #   start (each in its body's frame) [m], and r_inc times
                                 #   their angles' difference then [m] (a round side's roll)
    contact_radii: np.ndarray    # (n_contact, 2) radius of the reference and the other shape [m]
    contact_curve: np.ndarray    # (n_contact,) the second-order part of a held contact's normal
                                 #   velocity target (solve.held_contact_curve) [m/s]
    contact_bounce: np.ndarray   # (n_contact,) normal velocity restitution asks for [m/s]
    manifold: np.ndarray         # (2, 10) the narrow phase's points (kernels/geometry/collide.py)
    shape_reach: np.ndarray      # (n_shape, 4) each shape's bounding circle in the world (x, y,
                                 #   radius [m]) and a bound on its points' speed [m/s]
    sweep_box: np.ndarray        # (n_shape, 4) each shape's widened bounding box [m]
                                 #   (left, right, bottom, top; kernels/geometry/broad_phase.py)
    sweep_order: np.ndarray      # (n_shape,) int the shapes by their boxes' left ends
    shape_pair_slot: np.ndarray  # (n_shape, n_shape) int slot-0 contact of the pair of two
                                 #   shapes (-1: they never collide); (0, 0) without pairs
    live_pairs: np.ndarray       # (n_pair,) int this step's pairs (slot-0 contacts), ascending
    last_pairs: np.ndarray       # (n_pair,) int the list before the last update
    n_live_pairs: np.ndarray     # (1,) int pairs listed
    sweep_pairs: np.ndarray      # (n_pair,) int scratch list of a sweep (projection, audit)
    pair_flag: np.ndarray        # (n_contact,) int a pair's slot 0: broad_phase.FLAG_* bits
    ground_contacts: np.ndarray  # (n_ground,) int every contact that is not a shape pair's
    live: np.ndarray             # (n_contact,) int the contacts a step visits, ascending:
                                 #   the ground contacts and both slots of each listed pair
    n_live: np.ndarray           # (1,) int contacts listed
    near_contacts: np.ndarray    # (n_contact,) int scratch list of contacts (the projection's)
    row_body: np.ndarray         # (R, 2) int
    row_J: np.ndarray            # (R, 2, 3)
    row_F: np.ndarray            # (R, 2, 3)
    row_Jp: np.ndarray           # (R, 2, 3) Jacobian at the end-of-step configuration
    row_c: np.ndarray            # (R,) position error [m or rad]
    row_c_pred: np.ndarray       # (R,) position error at q_pred [m or rad]
    row_kind: np.ndarray         # (R,) int ROW_*
    row_owner: np.ndarray        # (R,) int pin / rod / contact index
    n_row: np.ndarray            # (1,) int rows in use (the row arrays are the general
                                 #   stages'; a step of the pin-chain path writes none of them:
                                 #   its rows are ws.chain_lever, its impulses State.last_pin_impulse)
    A_low: np.ndarray            # (P,) the effective-mass matrix J M^-1 F^T, its lower
                                 #   triangle and diagonal inside the rows' envelope: entry
                                 #   (i, j), row_first[i] <= j <= i, at row_start[i] + j -
                                 #   row_first[i] (kernels/solver/solve.py); P: profile capacity
    A_up: np.ndarray             # (P,) its upper triangle the same way: entry (j, i), j < i,
                                 #   at row_start[i] + j - row_first[i] (column i)
    row_start: np.ndarray        # (R + 1,) int where each row's envelope begins in A_low / A_up
    A_dense: np.ndarray          # (D, D) the same matrix as a dense square where the rows are
                                 #   few (D = min(R, DENSE_MAX_ROWS); kernels/solver/dense.py)
    factor_kind: np.ndarray      # (1,) int which factorisation holds the rows (kernels/solver/matrix.py:
                                 #   0 the envelope, 1 sparse, 2 dense; sparse: A_low / A_up hold
                                 #   the factors' columns L and U, at L_index's rows; dense: A_dense)
    L_index: np.ndarray          # (P,) int the sparse factors' row of each entry
    sp_perm: np.ndarray          # (R,) int sparse order: place -> row (kernels/solver/sparse_factor.py)
    sp_iperm: np.ndarray         # (R,) int row -> place
    sp_row_key: np.ndarray       # (R,) int each row's part in the nested dissection
    sp_parent: np.ndarray        # (R,) int elimination tree (-1: a root)
    sp_flag: np.ndarray          # (R,) int scratch marks
    sp_pattern: np.ndarray       # (R,) int scratch: a row's pattern in the factor
    sp_lcount: np.ndarray        # (R,) int entries of each factor column
    sp_lstart: np.ndarray        # (R + 1,) int where each factor column begins
    sp_pivot: np.ndarray         # (R,) pivots by place (0: dropped)
    sp_diag: np.ndarray          # (R,) the matrix's diagonal by place
    sp_x: np.ndarray             # (R,) scratch
    sp_y: np.ndarray             # (R,) scratch
    sp_start: np.ndarray         # (R + 1,) int where each place's lower neighbours begin
    sp_index: np.ndarray         # (P,) int the lower neighbours' places
    sp_low: np.ndarray           # (P,) A[k, i] of each (i < k)
    sp_up: np.ndarray            # (P,) A[i, k] of each
    sp_body_rows: np.ndarray     # (2 R,) int each body's rows by place (sp_body_start)
    sp_body_start: np.ndarray    # (n_body + 1,) int
    sp_body_fill: np.ndarray     # (n_body,) int scratch cursor
    sp_bodies: np.ndarray        # (n_body,) int the bodies in nested-dissection order
    sp_body_place: np.ndarray    # (n_body,) int each body's place in it
    sp_key: np.ndarray           # (n_body,) scratch: the coordinate a part is split along [m]
    sp_stack: np.ndarray         # (n_body + 2, 2) int the parts still to split
    sp_count: np.ndarray         # ((n_body + 1) MAX_DEPTH + 1,) int counting sort of the rows
    sp_kept_rows: np.ndarray     # (R, 4) int the rows whose factors the sparse storage holds:
                                 #   kind, owner, bodies (solve.same_rows_factored)
    sp_kept: np.ndarray          # (3,) int [0] 1: the sparse storage holds the velocity solve's
                                 #   factors of the rows in sp_kept_rows (0: none kept), [1] how
                                 #   many rows, [2] how many it dropped as dependent
    sp_kept_pivot: np.ndarray    # (1,) their joint rows' smallest pivot share (ws.joint_pivot)
    sp_factored: np.ndarray      # (1,) int the places the sparse factors hold; later ones are
                                 #   rows left out as dependent (sparse_factor.order_rows)
    rhs: np.ndarray              # (R,)
    lam_start: np.ndarray        # (R,) impulses the solve starts from (the last step's);
                                 #   scratch of the refinement on kept factors
    lam: np.ndarray              # (R,) impulses [N s or N m s]
    act_u: np.ndarray            # (n_act,) applied (saturated) commands
    act_power: np.ndarray        # (n_act,) mechanical power [W] (forces.end_power: the
                                 #   command times its move over the step / h once a step
                                 #   stands)
    act_work: np.ndarray         # (n_act,) the commands' work [J] in the steps since the
                                 #   last recorded frame (record_frame divides it by
                                 #   act_work_time and starts both again)
    act_work_time: np.ndarray    # (1,) [s] those steps' time
    info: np.ndarray             # (N_INFO,) int: what the last step did, slots named in
                                 #   kernels/info.py (INFO_*; step_info(ws) by name)
    broken_rules: np.ndarray     # (N_BROKEN + 1,) int: the rules the last checked answer
                                 #   broke, by rule (kernels/codes.py BROKE_*;
                                 #   modes.rule_breaks), then GUESS_PENDING
    guard_value: np.ndarray      # (3,) offending value when a guard fired; the speed bound
                                 #   [m/s] when it was a speed (GUARD_SPEED); a torque's turn,
                                 #   inverse inertia and limit (GUARD_STIFF_ACTUATOR)
    row_b: np.ndarray            # (R,) residual of each row without impulses: w = A lam + b
                                 #   [m/s] (velocity stage) or [m, rad] (position projection)
    row_soft: np.ndarray         # (R, 6) a soft row's armature, stiffness, damping, joint rate
                                 #   at the step's start, compliance, g W g^T (kernels/constraints/soft.py)
    contact_candidate: np.ndarray  # (n_contact,) int 1: in the complementarity problem
    limit_candidate: np.ndarray  # (n_pin, 2) int 1: in the complementarity problem
    lcp_rows: np.ndarray         # (R,) int rows: joints first, then the others
    lcp_var: np.ndarray          # (R,) int row -> first LCP variable (tangent rows: 3)
    lcp_pos: np.ndarray          # (R,) int non-joint row k -> its first LCP variable
    row_local: np.ndarray        # (R,) int a row's place in its island's dense matrix lcp_A
    lcp_A: np.ndarray            # (C, C) an island's J M^-1 J^T in full (C: the island rows
                                 #   the dense complementarity storage holds)
    lcp_B: np.ndarray            # (C, C) joint block A_bb, factored
    lcp_G: np.ndarray            # (C, C + 1) A_bb^-1 [A_bx, b_b]
    lcp_S: np.ndarray            # (C, C + 1) Schur complement [S, s]
    lcp_M: np.ndarray            # (L, L) the LCP matrix (L = 2 C: unilateral + 3 per friction
                                 #   row, which follows its normal row)
    lcp_q: np.ndarray            # (L,)
    lcp_z: np.ndarray            # (L,) its solution
    lcp_scale: np.ndarray        # (L,) diagonal scaling of the variables
    lcp_T: np.ndarray            # (L, 2L + 2) Lemke's tableau
    lcp_basis: np.ndarray        # (L,) int
    row_slip: np.ndarray         # (R,) slip speed gamma of a tangent row in the last
                                 #   complementarity solve [m/s] (mixed_lcp.solve_mixed_lcp)
    lcp_nz: np.ndarray           # (L,) int scratch: a column's non-zero rows (lcp.lemke_revised)
    island_parent: np.ndarray    # (n_body,) int union-find of the bodies (kernels/solver/islands.py)
    island_label: np.ndarray     # (n_body,) int island of a representative body (-1: none)
    island_start: np.ndarray     # (n_body + 2,) int first entry of each island in island_rows
    island_fill: np.ndarray      # (n_body + 1,) int scratch cursor of the grouping
    island_rows: np.ndarray      # (R,) int the rows grouped by island
    row_island: np.ndarray       # (R,) int each row's island
    island_failed: np.ndarray    # (n_body + 1,) int 1: the island's problem had no answer
    island_fallback: np.ndarray  # (n_body + 1,) int 1: solved by the frictionless rule
    island_scale: np.ndarray     # (n_body + 1,) its problem's largest approach (scaled units)
    audit: np.ndarray            # (N_AUDIT,) int violations counted since the workspace was
                                 #   made (kernels/checks/audit.py: AUDIT_NAMES)
    audit_last: np.ndarray       # (4,) int the last violation: step, kind, contact or pin, body
    audit_value: np.ndarray      # (1,) its size (impulse [N s], work [J], gap or depth [m])
    audit_worst: np.ndarray      # (4,) int the step's largest pin gap or depth violation: step,
                                 #   kind, pin or contact, body (StepOptions.gross_limit)
    audit_worst_value: np.ndarray  # (1,) its size [m] (0: none this step)
    bounce_scale: np.ndarray     # (1,) the factor of the step's rebound targets (1; less where
                                 #   the energetic bound scales them: kernels/solver/rebound.py)
    energy_stop: np.ndarray      # (1,) int 1: this step gained energy from nowhere beyond
                                 #   StepOptions.energy_limit (kernels/checks/work.judge_energy)
    first_order: np.ndarray      # (1,) int 1: this step's joint rows aim at J v = 0 (a
                                 #   projection) after the second-order target added energy
    joint_gain: np.ndarray       # (3,) the joints' energy gain of the step's answer beyond
                                 #   their allowance [J], its row, 1 where measured for the
                                 #   answer standing (work.joints_add_energy, computed once)
    joint_pivot: np.ndarray      # (1,) the smallest share of its diagonal a joint row's pivot
                                 #   kept in the factorisation of the step's answer (1: no
                                 #   joint row; 0: one dropped as dependent): a loop at or
                                 #   near a dependent configuration (work.joints_add_energy)
    lcp_eps: np.ndarray          # (1,) largest diagonal term the complementarity solves of
                                 #   this step added (mixed_lcp.REGULARISATION; scaled units)
    impact_time: np.ndarray      # (1,) time [s] of the last CCD impact (time-of-impact split)
    audit_keep: np.ndarray       # (N_AUDIT,) int the audit's counts before a step that may be
                                 #   taken again in sub-steps (step._step)
    path_explained: np.ndarray   # (n_body, 3) the path [m] each body's velocities explain over
                                 #   the step's finished parts (time-of-impact splits), its speed
                                 #   [m/s] at the current part's start, its largest overlap [m]
                                 #   at the step's start (guards.check_displacements)
    step_path: np.ndarray        # (n_body,) the path [m] each body's velocities explain over the
                                 #   last whole step: per part (time-of-impact splits, turn
                                 #   sub-steps) its length times the body's largest speed in it
    room: np.ndarray             # (5,) int [0] 1: a row, the rows' envelope or an island's
                                 #   complementarity problem did not fit this step (its answer
                                 #   is discarded: the step returns GUARD_ROOM from its start,
                                 #   and Simulator grows the solve's storage, grow_workspace);
                                 #   [1] 1: the solve's storage holds fewer contacts than the
                                 #   model has (so a step keeps its pair list's start in
                                 #   start_pairs, to begin again from it); [2] the envelope
                                 #   entries and [3] the island rows the step needed beyond
                                 #   the storage (0: none); [4] the island rows the dense
                                 #   complementarity storage may grow to (LCP_GROWTH_BUDGET:
                                 #   a larger island's problem is not solved that way)
    least_change: np.ndarray     # (3,) int [0] 1: this step's solves take the least change of
                                 #   impulses where rows are dependent (solve.least_change_impulses;
                                 #   set once an answer broke a rule: step.solve_and_check);
                                 #   [1] rows the last solve dropped as dependent; [2] least-change
                                 #   answers tried in this solve of the modes
    start_pairs: np.ndarray      # (n_pair,) int the listed pairs at the step's start (room[1])
    n_start_pairs: np.ndarray    # (1,) int how many
    prev_whole: np.ndarray       # (1,) int 1: the next copy of the State into prev copies every
                                 #   contact slot (each call from Python begins and ends with
                                 #   it set; a state put in; a step begun again from ws.start);
                                 #   0: the ground contacts' and sync_pairs' slots (prev_copy.py)
    sync_pairs: np.ndarray       # (n_pair,) int the pairs (slot-0 contacts) listed at the last
                                 #   copy into prev and those listed since: the only pairs whose
                                 #   slots the State can have changed since (each once)
    n_sync_pairs: np.ndarray     # (1,) int how many
    pair_synced: np.ndarray      # (n_contact,) int a pair's slot 0: 1 while in sync_pairs
    chain_on: np.ndarray         # (1,) int 1: the model's pins form open chains and are its only
                                 #   rows: the step tries its pin-chain path (kernels/solver/pin_chain.py;
                                 #   planarsim/pin_chains.py)
    joints_open: np.ndarray      # (1,) int 1: the model's joints close no loop of bodies
                                 #   (pin_chains.joints_form_no_loop; position.joints_alone)
    frame_free: np.ndarray       # (1,) int 1: the model touches the world nowhere (no joint to
                                 #   it, no shape on it, no ground contact): its checks measure
                                 #   motion about its centre of mass (kernels/checks/frame.py)
    chain_pin: np.ndarray        # (n_pin,) int the pins chain by chain (pin_chain_order)
    chain_end: np.ndarray        # (n_pin, 2) int the ends of pins k and k - 1 at the body they
                                 #   share (-1: a chain starts at k)
    chain_factor: np.ndarray     # (n_pin, 12) the block elimination of the pins' matrix at
                                 #   place k: its pivot's inverse, A[k, k - 1] P_{k-1}^-1, A[k - 1, k]
                                 #   (2 x 2 each, row-major)
    chain_y: np.ndarray          # (n_pin, 2) scratch of the block substitution
    chain_cs: np.ndarray         # (n_body, 3) cos, sin, angle carried through the path's step
                                 #   (pin_chain.carry_trig; read within a step only)
    chain_lever: np.ndarray      # (n_pin, 2, 4) [m] each pin's anchors from their bodies' centres
                                 #   of mass (end a, end b): (x, y) at the step's start, at the
                                 #   iterate (pin_chain.lever_gaps; read within a step only)
    start: State                 # the step's start while it is taken in sub-steps (GUARD_ROOM
                                 #   puts it back; kernels/step.py)
    prev: State                  # the state at the start of the last step (for guard errors)


def array_pairs(dst, src) -> list:
    """[(a, b)]: the arrays of two NamedTuples of the same shapes (nested ones too), paired."""
    pairs = []
    for a, b in zip(dst, src):
        if isinstance(a, tuple):
            pairs.extend(array_pairs(a, b))
        else:
            pairs.append((a, b))
    return pairs


@njit(cache=True)
def _copy_flat(dst, src):
    for k in range(len(dst)):
        d = dst[k]
        s = src[k]
        for i in range(d.shape[0]):
            d[i] = s[i]


class ArrayCopier:
    """Copies the second array of each (dst, src) pair into the first, in place, in one
    compiled call per dtype (float64, int64; any other array in Python): a Simulator's reset
    copies a fresh workspace's few hundred arrays, whose copy one by one from Python cost
    more than the environment's step."""

    def __init__(self, pairs):
        from numba.typed import List
        self.lists = {}
        self.others = []
        for dst, src in pairs:
            if (dst.dtype in (np.float64, np.int64) and dst.dtype == src.dtype
                    and dst.shape == src.shape and dst.flags.c_contiguous and src.flags.c_contiguous):
                lists = self.lists.setdefault(dst.dtype.str, (List(), List()))
                lists[0].append(dst.reshape(-1))
                lists[1].append(src.reshape(-1))
            else:
                self.others.append((dst, src))

    def copy(self) -> None:
        for dst, src in self.lists.values():
            _copy_flat(dst, src)
        for dst, src in self.others:
            dst[...] = src


def forget_ground_queries(ws: Workspace) -> None:
    """Drop the contacts' last ground queries (the next step queries every contact): for a
    workspace kept across a change of terrain or contact points."""
    ws.contact_found[:] = -np.inf
    ws.contact_stale[:] = 0


def forget_pairs(ws: Workspace) -> None:
    """Take every shape pair as listed in the last step, so that the next sweep clears each
    one it does not find (kernels/geometry/broad_phase.py): for a state put in from outside, whose
    pairs' contacts its positions may no longer have."""
    slot0 = np.unique(ws.shape_pair_slot[ws.shape_pair_slot >= 0])
    ws.last_pairs[:] = slot0
    ws.n_live_pairs[0] = slot0.size
    ws.prev_whole[0] = 1        # (the next sweep may clear any pair's slots)


def forget_kept_factors(ws: Workspace) -> None:
    """The velocity solve's kept factors (StepOptions.keep_factors) not to be reused: a state,
    model or options put in from outside."""
    ws.sp_kept[0] = 0


def refresh_chains(model: Model, ws: Workspace) -> None:
    """ws's pin-chain arrays for `model` (a model swapped in: its pins' limits, springs or
    armature decide whether the pin-chain path may take its steps)."""
    for name, value in _chain_arrays(model).items():
        getattr(ws, name)[...] = value


def max_rows(model: Model, contacts: int | None = None) -> int:
    """Rows of the step's solve with room for `contacts` contacts in rows (default: every
    contact slot the model has): a joint's two equalities, two limit sides and its soft row;
    a rod's; a contact's normal and tangent."""
    nc = model.n_contact if contacts is None else contacts
    return max(1, 5 * model.n_pin + model.n_rod + 2 * nc)


# [bytes] the solve's storage a new workspace is given (solve_bytes): room in rows for every
# contact slot of its model, the envelope of all those rows and a dense complementarity
# problem over all of them where that fits (every walker, every model of tens of shapes);
# beyond it, room for the contacts a step is likely to hold (contact_capacity), an envelope
# of ENVELOPE_PER_ROW entries a row and complementarity problems of LCP_ROWS rows, each grown
# by the Simulator when a step needs more
SOLVE_BUDGET = 64 * 2 ** 20

# contacts per shape a first workspace holds when not every slot fits SOLVE_BUDGET: a box
# on two others with one beside it touches with 2-3 pairs of two slots each
CONTACTS_PER_SHAPE = 6
# envelope entries per row a first workspace holds when the full envelope does not fit
ENVELOPE_PER_ROW = 64
# island rows a first workspace's dense complementarity storage holds when not all rows fit
LCP_ROWS = 256
# [bytes] the largest dense complementarity storage a workspace may grow to: an island with
# more rows than fit is not solved as one complementarity problem (its contacts' modes are
# found by the linear solves alone; where those fail the audit says so)
LCP_GROWTH_BUDGET = 2 ** 30


def profile_full(rows: int) -> int:
    """Envelope entries of rows rows that all share a body: rows (rows + 1) / 2."""
    return rows * (rows + 1) // 2


def lcp_bytes(lcp_rows: int) -> int:
    """Memory [bytes] of the dense complementarity storage for islands of lcp_rows rows:
    four C x C (or C x (C + 1)) matrices and Lemke's L x L and L x (2L + 2), L = 2 C."""
    C, L = lcp_rows, 2 * lcp_rows
    return 8 * (2 * C * C + 2 * C * (C + 1) + L * L + L * (2 * L + 2))


def lcp_rows_limit() -> int:
    """The most island rows whose dense complementarity storage fits LCP_GROWTH_BUDGET
    (lcp_bytes(C) = 128 C^2 + 48 C, solved for C)."""
    C = int((-48.0 + math.sqrt(48.0 ** 2 + 512.0 * LCP_GROWTH_BUDGET)) / 256.0)
    return C - 1 if lcp_bytes(C) > LCP_GROWTH_BUDGET else C


def solve_bytes(model: Model, contacts: int, profile: int, lcp_rows: int) -> int:
    """Memory [bytes] of the solve's storage with room for `contacts` contacts in rows,
    `profile` envelope entries and islands of `lcp_rows` rows in the dense complementarity
    storage (the arrays of _solve_arrays)."""
    return sum(int(np.prod(shape)) * 8 for shape, _ in _solve_shapes(model, contacts, profile,
                                                                     lcp_rows).values())


def contact_capacity(model: Model) -> int:
    """Contacts the solve's storage of a new workspace holds: every contact slot of the model
    where that, with their full envelope and complementarity storage, fits SOLVE_BUDGET, else
    the ground contacts and CONTACTS_PER_SHAPE per shape; a step that needs more returns
    GUARD_ROOM and the Simulator grows it (grow_workspace)."""
    nc = model.n_contact
    R = max_rows(model, nc)
    if solve_bytes(model, nc, profile_full(R), R) <= SOLVE_BUDGET:
        return nc
    n_ground = int(np.sum(model.arrays.contact_kind != CONTACT_PAIR))
    return min(nc, n_ground + CONTACTS_PER_SHAPE * model.n_shape)


def first_capacity(model: Model, contacts: int) -> tuple[int, int]:
    """(envelope entries, island rows of the dense complementarity storage) of a new
    workspace holding `contacts` contacts: all its rows' where that fits SOLVE_BUDGET, else
    ENVELOPE_PER_ROW a row and LCP_ROWS (grown when a step needs more)."""
    R = max_rows(model, contacts)
    if solve_bytes(model, contacts, profile_full(R), R) <= SOLVE_BUDGET:
        return profile_full(R), R
    return min(profile_full(R), ENVELOPE_PER_ROW * R), min(R, LCP_ROWS)


def _broad_phase_lists(model: Model) -> dict:
    """The broad phase's tables and lists (kernels/geometry/broad_phase.py): the pair table of the
    shapes, every ground contact, and the live list, which holds every contact until the
    first sweep (a model without shapes keeps it so)."""
    arr = model.arrays
    nc, ns = model.n_contact, model.n_shape
    pair_slot0 = [i for i in range(nc) if arr.contact_kind[i] == CONTACT_PAIR
                  and arr.contact_pair[i, 2] == 0]
    n_pair = len(pair_slot0)
    table = np.full((ns, ns) if n_pair else (0, 0), -1, np.int64)
    for i in pair_slot0:
        a, b = arr.contact_pair[i, 0], arr.contact_pair[i, 1]
        table[a, b] = table[b, a] = i
    ground = np.array([i for i in range(nc) if arr.contact_kind[i] != CONTACT_PAIR], np.int64)
    live = np.arange(nc, dtype=np.int64)
    return dict(sweep_box=np.zeros((ns, 4)), sweep_order=np.arange(ns, dtype=np.int64),
                shape_pair_slot=table, live_pairs=np.zeros(n_pair, np.int64),
                last_pairs=np.array(pair_slot0, np.int64).reshape(n_pair),
                n_live_pairs=np.array([n_pair], np.int64),
                sweep_pairs=np.zeros(n_pair, np.int64), pair_flag=np.zeros(nc, np.int64),
                ground_contacts=ground, live=live, n_live=np.array([nc], np.int64),
                near_contacts=np.zeros(nc, np.int64))


def check_workspace(model: Model, contacts: int, profile: int, lcp_rows: int) -> None:
    """Raise WorkspaceTooLarge, before anything is allocated, when the solve's storage with
    room for `contacts` contacts, `profile` envelope entries and islands of `lcp_rows` rows
    (solve_bytes) needs more memory than the machine has."""
    need = solve_bytes(model, contacts, profile, lcp_rows)
    have = memory.machine_memory()
    if have and need > have:
        n_pair = int(np.sum(model.arrays.contact_kind == CONTACT_PAIR)) // 2
        raise WorkspaceTooLarge(
            f"this model's step needs {memory.gib(need)} of memory, more than this machine's "
            f"{memory.gib(have)}: its solve holds {contacts:,} contacts in rows "
            f"({max_rows(model, contacts):,} rows, {profile:,} entries of their matrix, "
            f"complementarity problems of {lcp_rows:,} rows; the model has "
            f"{model.n_contact:,} contact slots: {n_pair:,} pairs of shapes that may touch, "
            f"two each, of {model.n_shape:,} shapes on {model.n_body:,} bodies). Fewer "
            f"contacts fit: collide=False on shapes that never touch, or category= / mask= "
            f"filter bits that keep apart the shapes that cannot meet "
            f"(ModelBuilder.add_shape), or fewer bodies touching at once", need, have)


def _solve_shapes(model: Model, contacts: int, profile: int, lcp_rows: int) -> dict:
    """name -> (shape, dtype) of the workspace's arrays sized by the solve's rows R
    (max_rows with room for `contacts` contacts), the envelope's entries P (`profile`) and
    the dense complementarity storage's island rows C (`lcp_rows`; L = 2 C variables)."""
    R, P, C = max_rows(model, contacts), max(1, profile), max(1, lcp_rows)
    L = 2 * C
    D = min(R, DENSE_MAX_ROWS)
    f, i = np.float64, np.int64
    return dict(row_first=((R,), i), row_reach=((R,), i), row_list=((R,), i),
                row_body=((R, 2), i), row_J=((R, 2, 3), f), row_F=((R, 2, 3), f),
                row_Jp=((R, 2, 3), f), row_c=((R,), f), row_c_pred=((R,), f),
                row_kind=((R,), i), row_owner=((R,), i), A_low=((P,), f), A_up=((P,), f),
                row_start=((R + 1,), i), A_dense=((D, D), f), L_index=((P,), i), sp_perm=((R,), i),
                sp_iperm=((R,), i), sp_row_key=((R,), i), sp_parent=((R,), i),
                sp_flag=((R,), i), sp_pattern=((R,), i), sp_lcount=((R,), i),
                sp_lstart=((R + 1,), i), sp_pivot=((R,), f), sp_diag=((R,), f),
                sp_x=((R,), f), sp_y=((R,), f), sp_start=((R + 1,), i), sp_index=((P,), i),
                sp_low=((P,), f), sp_up=((P,), f), sp_body_rows=((2 * R,), i),
                sp_kept_rows=((R, 4), i), rhs=((R,), f), lam_start=((R,), f), lam=((R,), f),
                row_b=((R,), f), row_soft=((R, 6), f), lcp_rows=((R,), i),
                lcp_var=((R,), i), lcp_pos=((R,), i), row_local=((R,), i),
                lcp_A=((C, C), f), lcp_B=((C, C), f), lcp_G=((C, C + 1), f),
                lcp_S=((C, C + 1), f), lcp_M=((L, L), f), lcp_q=((L,), f), lcp_z=((L,), f),
                lcp_scale=((L,), f), lcp_T=((L, 2 * L + 2), f), lcp_basis=((L,), i),
                row_slip=((R,), f), lcp_nz=((L,), i), island_rows=((R,), i),
                row_island=((R,), i))


def _solve_arrays(model: Model, contacts: int, profile: int, lcp_rows: int) -> dict:
    """The workspace's arrays of _solve_shapes, zeroed."""
    return {name: np.zeros(shape, dtype)
            for name, (shape, dtype) in _solve_shapes(model, contacts, profile, lcp_rows).items()}


def grow_workspace(model: Model, ws: Workspace) -> Workspace:
    """ws with more room in its solve's storage after a step returned GUARD_ROOM: twice the
    envelope entries or the complementarity storage's island rows the step ran out of (at
    least what it needed), else twice its contacts (at most every slot of the model); its
    other arrays are ws's own (the same objects). WorkspaceTooLarge if that does not fit
    the machine."""
    contacts, profile, lcp_rows = workspace_capacity(model, ws)
    need_profile, need_lcp = int(ws.room[2]), int(ws.room[3])
    if need_profile > profile or need_lcp > lcp_rows:
        if need_profile > profile:
            profile = max(2 * profile, need_profile)
        if need_lcp > lcp_rows:
            lcp_rows = min(max(2 * lcp_rows, need_lcp), max(int(ws.room[4]), need_lcp))
    else:
        contacts = min(model.n_contact, max(2 * contacts, contacts + 16))
    check_workspace(model, contacts, profile, lcp_rows)
    grown = {}
    for name, (shape, dtype) in _solve_shapes(model, contacts, profile, lcp_rows).items():
        old = getattr(ws, name)
        if old.shape != shape:
            array = np.zeros(shape, dtype)
            kept = tuple(slice(0, min(k, g)) for k, g in zip(old.shape, shape))
            array[kept] = old[kept]
            grown[name] = array
    ws.sp_kept[0] = 0           # (factors of the old storage's rows: not kept)
    room = ws.room.copy()
    room[0] = 0
    room[1] = int(contacts < model.n_contact)
    room[2] = 0
    room[3] = 0
    return ws._replace(room=room, **grown)


def soft_envelope_size(model: Model) -> int:
    """Entries of the soft prediction's envelope (kernels/constraints/soft.soft_prediction): its rows are
    the joints with a soft row (armature, stiffness or damping; soft.has_soft_row), in order,
    and row t holds columns from the first of them sharing a body with t."""
    a = model.arrays
    soft = (np.asarray(a.pin_armature) > 0) | (np.asarray(a.pin_stiffness) > 0) | (
        np.asarray(a.pin_damping) > 0)
    first_at = {}
    size = 0
    for t, bodies in enumerate(np.asarray(a.pin_body).reshape(-1, 2)[soft]):
        first = t
        for b in bodies:
            if b >= 0:
                first = min(first, first_at.setdefault(int(b), t))
        size += t - first + 1
    return size


def make_workspace(model: Model, contacts: int | None = None, profile: int | None = None,
                   lcp_rows: int | None = None) -> Workspace:
    """A model's workspace with room for `contacts` contacts in its solve's storage
    (default: contact_capacity), `profile` entries of their matrix's envelope and islands of
    `lcp_rows` rows in its dense complementarity storage (defaults: first_capacity)."""
    contacts = contact_capacity(model) if contacts is None else min(int(contacts), model.n_contact)
    first_profile, first_lcp = first_capacity(model, contacts)
    profile = first_profile if profile is None else int(profile)
    lcp_rows = first_lcp if lcp_rows is None else int(lcp_rows)
    check_workspace(model, contacts, profile, lcp_rows)
    nb, nc, na = model.n_body, model.n_contact, model.n_act
    npin = model.n_pin
    z = np.zeros
    lists = _broad_phase_lists(model)
    n_pair = lists["live_pairs"].shape[0]
    return Workspace(force=z((nb, 3)), body_cs=np.full((nb, 3), np.nan),
                     body_first_row=z(nb, np.int64),
                     v_pred=z((nb, 3)), v_new=z((nb, 3)), v_lin=z((nb, 3)),
                     soft_joint=z(npin, np.int64), soft_body=z((npin, 2), np.int64),
                     soft_J=z((npin, 2, 3)), soft_first=z(npin, np.int64),
                     soft_start=z(npin, np.int64), soft_env=z(soft_envelope_size(model)),
                     soft_rhs=z(npin), soft_mark=z(nb, np.int64),
                     friction_slip=z(npin), friction_bound=z(npin), friction_J=z((npin, 2, 3)),
                     q_pred=z((nb, 3)), cs_pred=np.full((nb, 3), np.nan), q_keep=z((nb, 3)),
                     v_keep=z((nb, 3)), dq_correction=z((nb, 3)), dv_correction=z((nb, 3)),
                     pin_impulse_moved=z((npin, 4)), rod_impulse_moved=z(model.n_rod),
                     correction_kept=np.ones(1),
                     q_solved=z((nb, 3)), v_solved=z((nb, 3)),
                     contact_point=z((nc, 2)), contact_ground=z((nc, 2)),
                     contact_normal=z((nc, 2)), contact_gap=z(nc), contact_stale=z(nc, np.int64),
                     contact_found=np.full((nc, 4), -np.inf), contact_anchor=z((nc, 2)),
                     contact_impulse=z((nc, 2)), contact_held=z(nc, np.int64), contact_on_arc=z(nc, np.int64),
                     contact_new=z(nc, np.int64),
                     contact_bodies=np.stack([np.full(nc, -1, np.int64),
                                              np.asarray(model.arrays.contact_body, np.int64)],
                                             axis=1).reshape(nc, 2).copy(),
                     contact_dist=z(nc, np.int64), contact_face=z((nc, 4)),
                     contact_refpt=z((nc, 5)), contact_radii=z((nc, 2)), contact_bounce=z(nc),
                     contact_curve=z(nc),
                     manifold=z((2, 10)), shape_reach=z((model.n_shape, 4)),
                     **lists, **_solve_arrays(model, contacts, profile, lcp_rows),
                     n_row=z(1, np.int64), act_u=z(na), act_power=z(na), act_work=z(na),
                     act_work_time=z(1),
                     info=z(N_INFO, np.int64), broken_rules=z(N_BROKEN + 1, np.int64),
                     guard_value=z(3),
                     contact_candidate=z(nc, np.int64), limit_candidate=z((model.n_pin, 2), np.int64),
                     island_parent=z(nb, np.int64), factor_kind=z(1, np.int64),
                     sp_body_start=z(nb + 1, np.int64), sp_body_fill=z(nb, np.int64),
                     sp_bodies=z(nb, np.int64), sp_body_place=z(nb, np.int64), sp_key=z(nb),
                     sp_stack=z((nb + 2, 2), np.int64),
                     sp_count=z((nb + 1) * SPARSE_MAX_DEPTH + 1, np.int64),
                     sp_kept=z(3, np.int64), sp_kept_pivot=np.ones(1),
                     sp_factored=z(1, np.int64),
                     island_label=z(nb, np.int64), island_start=z(nb + 2, np.int64),
                     island_fill=z(nb + 1, np.int64), island_failed=z(nb + 1, np.int64),
                     island_fallback=z(nb + 1, np.int64), island_scale=z(nb + 1),
                     audit=z(N_AUDIT, np.int64),
                     audit_last=z(4, np.int64), audit_value=z(1),
                     audit_worst=z(4, np.int64), audit_worst_value=z(1), first_order=z(1, np.int64),
                     bounce_scale=np.ones(1), energy_stop=z(1, np.int64),
                     joint_gain=z(3), joint_pivot=np.ones(1), lcp_eps=z(1),
                     impact_time=z(1), audit_keep=z(N_AUDIT, np.int64), path_explained=z((nb, 3)),
                     step_path=z(nb),
                     room=np.array([0, int(contacts < nc), 0, 0, lcp_rows_limit()], np.int64), least_change=z(3, np.int64),
                     start_pairs=z(n_pair, np.int64), n_start_pairs=z(1, np.int64),
                     prev_whole=np.ones(1, np.int64), sync_pairs=z(n_pair, np.int64),
                     n_sync_pairs=z(1, np.int64), pair_synced=z(nc, np.int64),
                     **_chain_arrays(model), start=make_state(model), prev=make_state(model))


def touches_no_world(model: Model) -> bool:
    """The model touches the world nowhere: no pin, slider or rod to the world, no shape on
    it, no contact with the ground (every contact a pair of two bodies' shapes). Its motion
    as a whole is then free, and its step's checks measure motion about its centre of mass
    (kernels/checks/frame.py)."""
    a = model.arrays
    joints = np.concatenate([np.asarray(a.pin_body).reshape(-1),
                             np.asarray(a.rod_body).reshape(-1)])
    return bool(model.n_body > 0 and np.all(joints >= 0) and np.all(np.asarray(a.shape_body) >= 0)
                and np.all(np.asarray(a.contact_kind) == CONTACT_PAIR))


def _chain_arrays(model: Model) -> dict:
    """The pin-chain path's arrays (Workspace.chain_*; planarsim/pin_chains.py)."""
    npin = model.n_pin
    found = pin_chain_order(model)
    order, ends = found if found is not None else (np.zeros(npin, np.int64),
                                                    np.full((npin, 2), -1, np.int64))
    return dict(chain_on=np.array([int(found is not None)], np.int64),
                joints_open=np.array([int(joints_form_no_loop(model))], np.int64),
                frame_free=np.array([int(touches_no_world(model))], np.int64), chain_pin=order,
                chain_end=ends, chain_factor=np.zeros((npin, 12)), chain_y=np.zeros((npin, 2)),
                chain_cs=np.full((model.n_body, 3), np.nan),
                chain_lever=np.zeros((npin, 2, 4)))

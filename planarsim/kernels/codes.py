"""Integer codes shared by the kernels and the Python side, defined once."""
# contact kinds (model.contact_kind)
CONTACT_POINT = 0      # a material point (a point mass, a box corner)
CONTACT_ARC = 1        # a circular-arc sole that rolls
CONTACT_PAIR = 2       # one of two slots of a pair of colliding shapes (kernels/geometry/pair.py)
CONTACT_EDGE = 3       # a shape's straight edge over curved ground: its deepest point (hills)
# contact modes (state.contact_mode)
MODE_FREE = 0
MODE_PINNED = 1        # no slip along the ground
MODE_SLIDING = 2       # slipping, Coulomb friction at the cone's edge
# how the modes carried over from the last step are checked (StepOptions.mode_strategy)
MODES_ALTERNATING = 0  # one contact re-examined per step, in turn, before the guaranteed solve
MODES_ALL = 1          # straight to the guaranteed (complementarity) solve when the guess fails
# joint kinds (model.pin_kind): an entry of the pin table is a hinge or a slider (prismatic),
# whose coordinate is an angle or a slide (bit JOINT_SLIDE_BIT); a free body's coordinate
# (bit JOINT_FREE_BIT: an MJCF free root's slide or hinge) has that coordinate's limits,
# spring-damper, armature and motor but no constraint rows
JOINT_SLIDE_BIT = 1
JOINT_FREE_BIT = 2
JOINT_HINGE = 0
JOINT_SLIDER = JOINT_SLIDE_BIT
JOINT_FREE_HINGE = JOINT_FREE_BIT
JOINT_FREE_SLIDE = JOINT_FREE_BIT | JOINT_SLIDE_BIT
# row kinds (workspace.row_kind): each kind's rows are evaluated in its own module (pin.py,
# slider.py, rod.py, limit.py, soft.py, contacts.py for the ground, pair.py for shapes) and
# dispatched in one place (rows.py); a kind's class is asked through rows.py's named predicates, never by number order
ROW_PIN_X = 0
ROW_PIN_Y = 1
ROW_ROD = 2
ROW_LIMIT_LO = 3
ROW_LIMIT_HI = 4
ROW_CONTACT_N = 5
ROW_CONTACT_T = 6
ROW_SLIDE_PERP = 7     # a slider's anchor b held on its axis line (slider.py)
ROW_SLIDE_ANGLE = 8    # a slider's relative angle held (slider.py)
ROW_JOINT_SOFT = 9     # a joint coordinate's armature and implicit spring-damper (soft.py)
ROW_JOINT_FRICTION = 10  # a stuck joint's dry friction: its rate held, |impulse| <= F h (joint_friction.py)

INTEGRATOR_EULER = 0      # StepOptions.integrator: the default step, symplectic Euler with SHAKE
# 1: RATTLE, second order (kernels/dynamics/rattle.py)
INTEGRATOR_RATTLE4 = 2    # RATTLE composed in five stages (Suzuki), fourth order
INTEGRATOR_RATTLE6 = 3    # RATTLE composed in seven stages (Yoshida), sixth order
INTEGRATOR_NAMES = ("euler", "rattle", "rattle4", "rattle6")
# nesting depth of the sparse factorisation's parts (kernels/solver/sparse_factor.py; the workspace's
# counting sort holds this many keys per body): parts deeper than this share a place
SPARSE_MAX_DEPTH = 40
# systems of at most this many rows may be eliminated in a dense square (kernels/solver/dense.py,
# matrix.arrange), whose storage (Workspace.A_dense) is this squared at most
DENSE_MAX_ROWS = 48

# the rules an answer can break, as solver/modes.rule_breaks counts them into ws.broken_rules
BROKE_EQUATION = 0  # a row's equation missed (a dependent row dropped, its target unmet)
BROKE_PULL = 1      # a contact's normal impulse pulls
BROKE_REVERSAL = 2  # a sliding contact's slip reversed
BROKE_CONE = 3      # a pinned contact's friction outside its cone
BROKE_LIMIT = 4     # a joint limit's impulse pulls
N_BROKEN = 5
# ws.broken_rules[GUESS_PENDING] = 1: the next check is of the step's guess (step.solve_modes),
# whose counts go to the step's INFO_GUESS_* (kernels/info.py) too
GUESS_PENDING = N_BROKEN

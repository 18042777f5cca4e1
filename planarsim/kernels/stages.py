"""The step's stages, written once: their numbers, names, modules and functions, in the order
step.step_of_length runs them. step.py's numbered comments, the kernel modules' docstrings
("Stage N: ...") and the documentation's table of the stages (stage_table) are checked
against this list (tests/planarsim/test_stages.py). Plain data: no numba here."""

#: (name, what it does, its modules (the first owns it; "folder.module" is
#: planarsim/kernels/folder/module.py), the functions that run it)
STAGES = (
    ("forces", "applied forces and the free velocity v* = v + h M^-1 f",
     ("dynamics.forces", "dynamics.fluid"),
     ("apply_forces", "apply_fluid", "predict_velocity")),
    ("contacts", "the contact points: ground queries, the broad phase, shape pairs",
     ("geometry.contacts", "geometry.broad_phase", "geometry.pair", "geometry.collide"),
     ("find_contacts", "find_contact", "find_edge", "update_live", "find_pair")),
    ("rows", "the active constraint rows J and their errors c, one module per kind",
     ("constraints.rows", "constraints.pin", "constraints.slider", "constraints.rod",
      "constraints.limit", "constraints.soft", "constraints.joint_friction",
      "constraints.joints"),
     ("build_rows", "eval_row", "pin_row", "slider_perp_row", "slider_angle_row", "rod_row",
      "limit_row", "soft_row", "friction_row", "ground_row", "pair_row")),
    ("impulses", "the rows' impulses: one linear solve",
     ("solver.solve", "solver.matrix", "solver.envelope", "solver.dense",
      "solver.sparse_factor"),
     ("solve_impulses",)),
    ("modes", "the contacts' and limits' rules checked, then the guaranteed solve",
     ("solver.modes", "solver.complementarity", "solver.islands", "solver.mixed_lcp", "solver.lcp"),
     ("rule_breaks", "seed_rule", "check_contact", "solve_contacts")),
    ("impact", "continuous collision: a step split at the time of impact",
     ("geometry.ccd", "geometry.pair_toi"),
     ("split_at_impact", "pair_impact_time", "hold_off_fast_pairs")),
    ("audit", "the step audits its own answer (of the impulses; of the positions at the end "
     "of stage 8)", ("checks.audit", "checks.work"),
     ("audit_impulses", "audit_joints")),
    ("positions", "integrate, correct, settle",
     ("dynamics.position", "dynamics.integrate"),
     ("position_stage", "integrate_positions", "correct_positions", "settle_positions",
      "bound_correction_work")),
    ("guards", "every coordinate finite and within its bound", ("checks.guards",),
     ("check_guards", "check_speeds")),
)


def stage_number(name: str) -> int:
    """The number (from 1) of the stage called `name`."""
    for k, stage in enumerate(STAGES):
        if stage[0] == name:
            return k + 1
    raise KeyError(f"no stage {name!r}; the stages: {[s[0] for s in STAGES]}")


def stage_table() -> str:
    """The stages as a Markdown table (number and name, what it does, modules, functions)."""
    lines = ["| stage | what it does | modules (`planarsim/kernels/`) | functions |",
             "|---|---|---|---|"]
    for k, (name, what, modules, functions) in enumerate(STAGES):
        lines.append(f"| {k + 1}. {name} | {what} | "
                     + ", ".join(f"`{m.replace('.', '/')}.py`" for m in modules) + " | "
                     + ", ".join(f"`{f}`" for f in functions) + " |")
    return "\n".join(lines)

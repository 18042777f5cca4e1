"""Checks: the step judges its own answer (stages 7 and 9, stages.py).

The audit of the impulses and of the end positions against the contacts' rules (no pulling
contact, friction within its cone, no penetration, the joints held), the work each cause does
on the bodies (the energy audit's measures: no constraint may add energy), and the guards:
every coordinate finite and within its bound, the displacements explained by the
velocities."""

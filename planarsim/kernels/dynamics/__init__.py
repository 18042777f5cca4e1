"""Dynamics: forces and motion (stages 1 and 8, stages.py).

The applied forces (gravity, actuators, pushes, springs taken explicitly, a fluid's drag)
and the free velocity v* = v + h M^-1 f; the positions at the step's end: symplectic Euler's
q + h v, the Newton-SHAKE correction back onto the constraints and the settling of what is
left; and the energy-accurate integrators (RATTLE and its compositions) built around the
step."""

"""Which models the accurate integrators (StepOptions.integrator 'rattle', 'rattle4', 'rattle6';
kernels/dynamics/rattle.py) can step, checked from Python before the first step.

The compiled step makes the same test (kernels/dynamics/rattle.py unsupported) and stops with
GUARD_UNSUPPORTED for a caller that did not check; this one names the culprit at once.
"""
from __future__ import annotations

import numpy as np

from .errors import accurate_unsupported
from .kernels.codes import INTEGRATOR_EULER
from .kernels.dynamics.rattle import (UNSUPPORTED_CONTACT, UNSUPPORTED_FLUID, UNSUPPORTED_FRICTION,
                                      UNSUPPORTED_LIMIT, UNSUPPORTED_SOFT)


def unsupported_feature(model):
    """(what, index) of the first element an accurate integrator cannot step (a contact, a
    joint limit, a joint's spring, damper, armature or friction, a fluid drag), or None."""
    a = model.arrays
    if len(a.contact_body):
        return UNSUPPORTED_CONTACT, 0
    for j in range(len(a.pin_body)):
        if np.isfinite(a.pin_limit[j]).any():
            return UNSUPPORTED_LIMIT, j
        if a.pin_armature[j] > 0.0 or a.pin_stiffness[j] > 0.0 or a.pin_damping[j] > 0.0:
            return UNSUPPORTED_SOFT, j
        if a.pin_frictionloss[j] > 0.0:
            return UNSUPPORTED_FRICTION, j
    if len(a.fluid_body):
        return UNSUPPORTED_FLUID, 0
    return None


def check_integrator(model, options, who="Simulator") -> None:
    """Raise the ModelError naming the culprit if options.integrator is an accurate one and
    the model has an element it cannot step; nothing for the default integrator."""
    if options.integrator == INTEGRATOR_EULER:
        return
    found = unsupported_feature(model)
    if found is not None:
        raise accurate_unsupported(model, found[0], found[1], int(options.integrator), who)

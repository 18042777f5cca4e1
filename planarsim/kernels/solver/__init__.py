"""Solver: the impulses that make every row hold at the step's end (stages 4 and 5, stages.py).

The linear solve (J W F^T) lambda = -(c / h + J v*) by elimination inside the rows' envelope
or by a sparse factorisation in nested-dissection order, started from the last step's
impulses; the pin chains' block elimination; the contacts' and limits' rules (pinned,
sliding, free; Coulomb's cone) checked on an answer, and the guaranteed solve where they
break: one mixed complementarity problem per island of bodies, by Lemke's pivoting; and the
energetic bound on restitution's rebounds."""

"""Constraints: the rows J and position errors c that joints impose (stage 3, stages.py).

One module per kind of constraint: a pin's two equalities (p_b - p_a = 0), a slider's two
(its axis and its angle), a rod's length, a joint limit's inequality, a joint's soft row
(armature and an implicit spring-damper) and its dry friction; a joint's coordinate (hinge
angle or slide) whatever its kind; the workspace's list of active rows; and the one dispatch
on a row's kind. (The contacts' rows are written with their geometry: ../geometry.)"""

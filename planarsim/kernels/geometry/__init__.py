"""Geometry: where the bodies are and what touches what (stages 2 and 6, stages.py).

The ground, an analytic height h(x); the colliding shapes, convex cores grown by a radius,
their closest features and contact manifolds (narrow phase) and which pairs may touch within
a step (a sweep and prune over bounding circles: broad phase); the contact point, normal and
gap of every foot on the ground and of every pair of shapes, with the contacts' rows; and
continuous collision: the time of impact of a point's or a shape pair's swept motion within
the step, where the step is split."""

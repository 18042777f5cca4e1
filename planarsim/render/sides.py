"""Which side of the walker an element belongs to, read from its name.

Walkers name their parts after the leg they belong to: ``left_thigh`` / ``right_shin``,
``FL_calf`` / ``RR_thigh`` (front/rear left/right), ``outer_leg`` / ``inner_foot``,
``foot0`` / ``leg1``, ``leg_a`` / ``foot_b``. ``side_of(name)`` turns such a name into a side
label (``"left"``, ``"right"``, ``"outer"``, ``"inner"``, ``"leg 0"``, ...) and ``model_sides``
tags every body, rod and actuator of a model, so a picture can colour the two legs apart
without knowing the walker. Trunk parts (``hip``, ``torso``, ``base``) get no side.
"""
from __future__ import annotations

import re

# (pattern on one lower-case token, side label); the first match wins
_TOKEN_RULES = (
    (re.compile(r"left|l"), "left"),
    (re.compile(r"right|r"), "right"),
    (re.compile(r"[fhrb]l"), "left"),        # FL, RL, HL, BL: front/rear/hind/back left
    (re.compile(r"[fhrb]r"), "right"),
    (re.compile(r"outer"), "outer"),
    (re.compile(r"inner"), "inner"),
)
_LIMB = r"(?:foot|feet|leg|thigh|shin|calf|knee|ankle|sole|toe|heel|spring)"
_NUMBERED = re.compile(rf"{_LIMB}_?([0-1ab])")
# the order in which sides are listed (and coloured: first colour, second colour)
SIDE_ORDER = ("left", "right", "outer", "inner", "leg 0", "leg 1", "leg a", "leg b")


def side_of(name: str) -> str | None:
    """Side label of an element named `name`, or None (trunk, or no side in the name)."""
    tokens = [t for t in re.split(r"[^0-9a-z]+", str(name).lower()) if t]
    for tok in tokens:
        for pattern, side in _TOKEN_RULES:
            if pattern.fullmatch(tok):
                return side
    found = _NUMBERED.fullmatch("_".join(tokens)) or _NUMBERED.fullmatch("".join(tokens))
    return f"leg {found.group(1)}" if found else None


def side_index(side: str | None) -> int | None:
    """0 for the first side of a pair (left, outer, leg 0, leg a), 1 for the second, None."""
    return None if side is None else SIDE_ORDER.index(side) % 2


def model_sides(model, overrides: dict | None = None) -> dict:
    """{"body": [side per body], "rod": [...], "act": [...]} (None: no side).

    overrides maps element names to a side label (or None), for names the rules misread.
    A rod or actuator without a side in its own name takes the side of the bodies it joins
    when they have one side between them.
    """
    overrides = dict(overrides or {})
    bad = {k: v for k, v in overrides.items() if v is not None and v not in SIDE_ORDER}
    if bad:
        raise ValueError(f"sides={bad}: a side must be one of {', '.join(SIDE_ORDER)} or None")

    def tag(name):
        return overrides[name] if name in overrides else side_of(name)

    a = model.arrays
    body = [tag(n) for n in model.body_names]

    def joined(names, pairs):
        out = []
        for name, pair in zip(names, pairs):
            own = tag(name)
            if own is None and name not in overrides:
                found = {body[b] for b in pair if b >= 0} - {None}
                own = found.pop() if len(found) == 1 else None
            out.append(own)
        return out

    return {"body": body, "rod": joined(model.rod_names, a.rod_body),
            "act": joined(model.act_names, [row[:2] for row in a.act_body])}

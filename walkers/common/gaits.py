"""A gait given by name or number, checked against a walker's gait enum."""
from __future__ import annotations


def gait_number(gaits, gait, who: str) -> int:
    """The number of `gait` in the IntEnum `gaits`: a name ('walk', any case), a member, or
    its number; anything else (None, an unknown name or number) is a ValueError naming the
    gait and `who`'s gaits."""
    names = [g.name.lower() for g in gaits]
    if isinstance(gait, str):
        if gait.upper() in gaits.__members__:
            return int(gaits[gait.upper()])
    elif not isinstance(gait, bool):
        try:
            return int(gaits(gait))
        except (TypeError, ValueError):
            pass
    raise ValueError(f"unknown {who} gait {gait!r}; use one of {names}")

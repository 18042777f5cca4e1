"""A body's geoms and inertials read: world pose, size, mass and contact parameters (mass
properties as MuJoCo's compiler computes them: planarsim.mjcf_frames)."""
from __future__ import annotations

import numpy as np

from .. import mjcf_frames as F
from .attributes import ElementReader
from .plane import vec
from .schema import DEFAULT_DENSITY, DEFAULT_FRICTION, SUPPORTED_GEOMS


class BodyPartsReader(ElementReader):
    """The <geom> and <inertial> elements of a body (Body3D at the file's pose)."""

    def geom(self, g, eff, body):
        """World pose, size and mass of one geom (see planarsim.mjcf_frames)."""
        kind = eff.get("type", "sphere")
        if kind not in SUPPORTED_GEOMS:
            self.fail(g, f"type={kind!r} is not supported ({', '.join(SUPPORTED_GEOMS)})")
        if kind == "plane":
            pos, R = self.frame(g, eff, body.pos, body.R)
            return dict(node=g, eff=eff, kind=kind, pos=pos, R=R, mass=0.0, name=eff.get("name", ""),
                        **self.contact_params(g, eff))
        size = self.floats(g, eff, "size", (1, 2, 3))
        if np.any(size <= 0):
            self.fail(g, f"size={vec(size)} must be > 0")
        need = {"sphere": 1, "capsule": 1 if "fromto" in eff else 2,
                "cylinder": 1 if "fromto" in eff else 2, "box": 2 if "fromto" in eff else 3,
                "ellipsoid": 2 if "fromto" in eff else 3}[kind]
        if size.size < need:
            self.fail(g, f"{kind} size={vec(size)} needs {need} number(s)")
        if "fromto" in eff and kind != "sphere":
            ft = self.floats(g, eff, "fromto", 6)
            p0, p1 = ft[:3], ft[3:]
            if not self.global_coords:
                p0, p1 = body.pos + body.R @ p0, body.pos + body.R @ p1
            half = 0.5 * float(np.linalg.norm(p1 - p0))
            if not half > 0:
                self.fail(g, "fromto end points must differ")
            pos, R, ends = 0.5 * (p0 + p1), F.zaxis_matrix(p1 - p0), (p0, p1)
            dims = (size[0], half) if kind in ("capsule", "cylinder") else (size[0], size[1], half)
        else:
            pos, R = self.frame(g, eff, body.pos, body.R)
            dims = tuple(size[:need])
            ends = (pos - dims[-1] * R[:, 2], pos + dims[-1] * R[:, 2])
        vol, unit = F.unit_inertia(kind, dims)
        if "mass" in eff:
            mass = self.scalar(g, eff, "mass", 0.0)
            if mass < 0:
                self.fail(g, f"mass={mass} must be > 0 (or 0 for a massless geom)")
        else:
            density = self.scalar(g, eff, "density", DEFAULT_DENSITY)
            if density < 0:
                self.fail(g, f"density={density} must be >= 0")
            mass = density * vol
        return dict(node=g, eff=eff, kind=kind, pos=pos, R=R, dims=dims, unit=unit, mass=mass, ends=ends,
                    name=eff.get("name", ""), **self.contact_params(g, eff))

    def contact_params(self, g, eff):
        """contype, conaffinity (bits), condim and sliding friction of a geom."""
        out = {}
        for key in ("contype", "conaffinity"):
            v = eff.get(key, "1")
            if not v.strip().isdigit():
                self.fail(g, f"{key}={v!r} must be a non-negative integer (bits)")
            out[key] = int(v)
        out["condim"] = int(self.scalar(g, eff, "condim", 3))
        if out["condim"] not in (1, 3, 4, 6):
            self.fail(g, f"condim={out['condim']} must be 1, 3, 4 or 6")
        fr = self.floats(g, eff, "friction", (1, 2, 3), default=DEFAULT_FRICTION)
        if fr[0] < 0:
            self.fail(g, f"friction={vec(fr)} must be >= 0")
        out["mu"] = float(fr[0])
        return out

    def inertial(self, node, body):
        eff = dict(node.attrib)
        self.vet(node, eff)
        pos, R = self.frame(node, eff, body.pos, body.R)
        mass = float(self.floats(node, eff, "mass", 1)[0])   # required, as MuJoCo's
        if not mass > 0:
            self.fail(node, f"mass={mass} must be > 0")
        if "fullinertia" in eff and "diaginertia" in eff:
            self.fail(node, "give diaginertia or fullinertia, not both (MuJoCo refuses both)")
        if "fullinertia" in eff:
            f6 = self.floats(node, eff, "fullinertia", 6)
            tensor = np.array([[f6[0], f6[3], f6[4]], [f6[3], f6[1], f6[5]], [f6[4], f6[5], f6[2]]])
            what = f"fullinertia=({', '.join(f'{float(x):g}' for x in f6)})"
        else:
            d = self.floats(node, eff, "diaginertia", 3)
            tensor = np.diag(d)
            what = f"diaginertia=({', '.join(f'{float(x):g}' for x in d)})"
        # as MuJoCo's compiler: the whole tensor positive definite, out-of-plane moments too
        moments = np.linalg.eigvalsh(tensor) if np.all(np.isfinite(tensor)) else np.array([np.nan])
        if not np.all(moments > 0):
            self.fail(node, f"{what} is not positive definite: a body's inertia must be")
        tensor = R @ tensor @ R.T
        return dict(node=node, mass=mass, pos=pos, tensor=tensor)

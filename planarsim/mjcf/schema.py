"""What the MJCF loader reads: MuJoCo's defaults, every element and attribute with what
becomes of it (read, ignored and reported, or only its default value supported), and the
options of the shapes it adds."""

DEFAULT_DENSITY = 1000.0  # [kg/m^3] MuJoCo's default geom density
DEFAULT_TIMESTEP = 0.002  # [s] MuJoCo's default option timestep
DEFAULT_GRAVITY = (0.0, 0.0, -9.81)  # [m/s^2] MuJoCo's default option gravity
DEFAULT_FRICTION = (1.0, 0.005, 0.0001)  # MuJoCo's default geom friction (slide, spin, roll)
DRAWN = {"collide": False}  # add_shape's options for a geom that is only drawn
COLLIDES = {"collide": True}
AXIS_TOL = 1e-9  # how far a unit joint axis may lean from the plane's normal (or into it)
DROPPABLE = ("armature", "fluid")  # physics the caller may choose to load without

# Per element: attributes it reads ("use"), ignores and reports ("ignore"), and accepts only
# at MuJoCo's default value ("default": value; any other value changes physics this loader
# does not model, a ModelError). Any attribute not listed is a ModelError.
ORIENT = {"quat", "axisangle", "euler", "zaxis", "xyaxes"}
ATTRIBUTES = {
    "mujoco": dict(use={"model"}),
    "compiler": dict(
        use={"angle", "coordinate", "inertiafromgeom", "settotalmass", "eulerseq", "autolimits"},
        ignore={"meshdir", "texturedir", "assetdir", "discardvisual", "strippath", "fusestatic",
                "convexhull", "usethread", "saveinertial", "alignfree"},
        default={"boundmass": "0", "boundinertia": "0", "balanceinertia": "false"}),
    "option": dict(
        use={"timestep", "gravity", "viscosity", "density"},
        ignore={"integrator", "cone", "impratio", "tolerance", "iterations", "ls_iterations",
                "ls_tolerance", "solver", "noslip_iterations", "noslip_tolerance",
                "ccd_iterations", "ccd_tolerance", "mpr_iterations", "mpr_tolerance",
                "sdf_iterations", "sdf_initpoints", "jacobian", "apirate", "magnetic",
                "o_margin", "o_solref", "o_solimp", "o_friction", "collision",
                "actuatorgroupdisable"},
        default={"wind": "0 0 0"}),
    "body": dict(use={"name", "childclass", "pos"} | ORIENT, ignore={"user"},
                 default={"mocap": "false", "gravcomp": "0"}),
    "joint": dict(
        use={"name", "class", "type", "pos", "axis", "range", "limited", "stiffness", "damping",
             "armature", "ref", "springref", "frictionloss"},
        ignore={"group", "margin", "solreflimit", "solimplimit", "solreffriction",
                "solimpfriction", "user"},
        default={"springdamper": "0 0", "actuatorfrclimited": "auto",
                 "actuatorgravcomp": "false"}),
    "geom": dict(
        use={"name", "class", "type", "size", "pos", "fromto", "mass", "density", "friction",
             "contype", "conaffinity", "condim"} | ORIENT,
        ignore={"rgba", "material", "group", "margin", "gap", "solimp", "solref", "solmix",
                "priority", "user"},
        default={"shellinertia": "false", "fluidshape": "none", "fitscale": "1"}),
    "inertial": dict(use={"pos", "mass", "diaginertia", "fullinertia"} | ORIENT),
    "motor": dict(
        use={"name", "class", "joint", "tendon", "gear", "ctrlrange", "ctrllimited", "forcerange",
             "forcelimited"},
        ignore={"group", "user", "lengthrange", "actdim"},
        default={"actlimited": "auto", "actrange": "0 0"}),
    # a fixed tendon: L = sum coef_i q_i, read for the motors that pull on it; its own
    # physics (limits, spring, damper, friction, armature) only at MuJoCo's defaults, which
    # do nothing; rgba, width and material reach it from <default><tendon> (spatial ones')
    "fixed": dict(
        use={"name", "class", "limited", "range"},
        ignore={"group", "user", "rgba", "width", "material", "solreflimit", "solimplimit",
                "solreffriction", "solimpfriction"},
        default={"stiffness": "0", "damping": "0", "frictionloss": "0", "springlength": "-1 -1",
                 "margin": "0", "armature": "0", "actuatorfrclimited": "auto",
                 "actuatorfrcrange": "0 0"}),
    "tendon": dict(),
    "tendon joint": dict(use={"joint", "coef"}),
}
# elements read by the loader, per parent
CHILDREN = {
    "mujoco": {"compiler", "option", "default", "worldbody", "actuator", "tendon"},
    "worldbody": {"body", "geom"},
    "body": {"body", "geom", "joint", "inertial"},
    "actuator": {"motor"},
    "tendon": {"fixed"},
    "fixed": {"joint"},
}
# elements ignored (and reported) wherever they appear: drawing, cameras, sensing, bookkeeping
IGNORED_ELEMENTS = {"size", "visual", "statistic", "custom", "asset", "keyframe", "sensor",
                     "light", "camera", "site", "extension", "exclude"}
# elements that are ignored when empty (a declaration with nothing in it) and a ModelError
# otherwise: each changes physics this loader does not model
EMPTY_ONLY = {"equality": "equality constraints", "contact": "explicit contact pairs"}
SUPPORTED_GEOMS = ("sphere", "capsule", "cylinder", "box", "ellipsoid", "plane")

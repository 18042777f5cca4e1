"""Drawing a Model from its own geometry with matplotlib.

A ``Scene`` owns the artists of one axes: body shapes (``model.shapes``: capsules, boxes,
circles of point masses, circular-arc feet with their heel/toe polygon, all in the body's
local frame), pins (dots at the anchors), rods and axial actuators (lines between anchors),
the terrain curve with tick marks every ``tick_spacing`` metres and distance labels (so that
motion over level ground is visible and readable), contact impulses as arrows, the centre of
mass, a legend and a text overlay (time, speed, gait/state). The two legs of a walker are
coloured apart, by the side their names give (sides.py). ``Scene.draw_state`` moves the
artists to a state; nothing is created per frame, so the same scene serves the exporter and
the interactive viewer. Text is drawn from cached bitmaps (stamps.py).

World coordinates are metres; a body pose is (x, y, theta) of its COM; a local point p is at
x + R(theta) p in the world.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from matplotlib.collections import LineCollection, PolyCollection
from matplotlib.patches import Polygon

from ..model import ACT_AXIAL, JOINT_FREE_BIT
from .sides import SIDE_ORDER, model_sides, side_index
from .legend import com_marker, legend_bitmap
from .plots import save_figure
from .stamps import ImageStamp, TextStamp


@dataclass
class Style:
    """Colours and sizes of a Scene (matplotlib colour specs; sizes in points unless noted)."""
    body_colors: tuple = ("#4c72b0", "#dd8452", "#55a868", "#c44e52", "#8172b3", "#937860",
                          "#da8bc3", "#8c8c8c", "#ccb974", "#64b5cd")   # models without sides
    side_colors: tuple = ("#2c7bb6", "#f28e2b")   # first and second leg (left/right, ...)
    trunk_color: str = "#a0a0a0"                  # parts of a walker on no side
    side_line_width: float = 3.0                  # rods and leg actuators on a side
    edge_color: str = "#1a1a1a"
    body_alpha: float = 0.9
    terrain_color: str = "#3b3b3b"
    ground_fill: str = "#e3ddd0"
    tick_color: str = "#5a4a2a"
    tick_length: float = 0.06            # [m]; labelled ticks are 1.8x longer
    pin_color: str = "white"
    rod_color: str = "#303030"
    rod_width: float = 2.5
    actuator_color: str = "#7a7a7a"
    impulse_color: str = "#d62728"
    com_color: str = "#111111"
    background: str = "white"
    text_color: str = "#111111"
    font_size: float = 9.0
    arc_points: int = 24                 # polygon points per circle / arc
    extra: dict = field(default_factory=dict)


def _rot(theta):
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[c, -s], [s, c]])


def _circle(center, radius, n, a0=0.0, a1=2 * math.pi, endpoint=False):
    a = np.linspace(a0, a1, n, endpoint=endpoint)
    return np.column_stack([center[0] + radius * np.cos(a), center[1] + radius * np.sin(a)])


def shape_outline(shape, n: int = 24) -> np.ndarray:
    """Closed outline (N, 2) of a Shape in its body's local frame [m]."""
    kind, p = shape.kind, shape.params
    if kind == "circle":
        center, radius = p[0], float(p[1])
        return _circle(center, radius, n)
    if kind == "capsule":
        p0, p1, r = np.asarray(p[0], float), np.asarray(p[1], float), float(p[2])
        d = p1 - p0
        ang = math.atan2(d[1], d[0]) if np.any(d) else 0.0
        half = max(4, n // 2)
        cap1 = _circle(p1, r, half, ang - math.pi / 2, ang + math.pi / 2, endpoint=True)
        cap0 = _circle(p0, r, half, ang + math.pi / 2, ang + 3 * math.pi / 2, endpoint=True)
        return np.vstack([cap1, cap0])
    if kind == "box":
        center, w, h = np.asarray(p[0], float), float(p[1]), float(p[2])
        angle = float(p[3]) if len(p) > 3 else 0.0
        corners = np.array([[-w / 2, -h / 2], [w / 2, -h / 2], [w / 2, h / 2], [-w / 2, h / 2]])
        return corners @ _rot(angle).T + center
    if kind == "polygon":
        return np.asarray(p[0], float).reshape(-1, 2).copy()
    if kind == "arc":
        center, r, (a0, a1) = np.asarray(p[0], float), float(p[1]), p[2]
        verts = np.asarray(p[3], float).reshape(-1, 2) if len(p) > 3 and len(p[3]) else np.zeros((0, 2))
        sole = _circle(center, r, max(n, 8), a0, a1, endpoint=True)
        if len(verts) == 0:
            return sole
        # heel/toe/back in angular order after the sole's end, so the polygon closes round the foot
        ang = np.arctan2(verts[:, 1] - center[1], verts[:, 0] - center[0])
        ang = a1 + np.mod(ang - a1, 2 * math.pi)
        return np.vstack([sole, verts[np.argsort(ang)]])
    raise ValueError(f"shape on body {shape.body}: unknown kind {kind!r} (capsule, box, circle, polygon, arc)")


def model_extent(model) -> float:
    """Size [m] of the model in its build pose (largest side of the shapes' bounding box)."""
    pts = [model.q0[:, :2]]
    for s in model.shapes:
        if s.body >= 0:     # world shapes (steps, walls) are scenery, not the model's size
            pts.append(world_points(model.q0, s.body, shape_outline(s, 8)))
    pts = np.vstack(pts)
    return float(max(np.ptp(pts[:, 0]), np.ptp(pts[:, 1]), 0.2))


def world_points(q, body, local) -> np.ndarray:
    """World coordinates (N, 2) of local points (N, 2) on `body` (-1: the world) at poses q."""
    local = np.asarray(local, float).reshape(-1, 2)
    if body < 0:
        return local.copy()
    x, y, th = q[body]
    return local @ _rot(th).T + (x, y)


class Scene:
    """The artists that draw one model on one matplotlib Axes.

    Parameters
    ----------
    model : Model
    ax : matplotlib Axes (the figure's size fixes the view's aspect)
    view_width : width of the view [m] (default: 4x the model's size, at least 2 m)
    tick_spacing : distance between terrain tick marks [m]
    label_spacing : distance between labelled ticks [m], a multiple of tick_spacing
        (default: a round number giving 3 to 7 labels across the view)
    show_impulses, show_com, show_legend : initial toggles (attributes, may change any time)
    impulse_scale : arrow length per newton [m/N] (default: the total weight draws as 0.2 of
        the view height)
    label_names : {label: {value: name}} to print labels (e.g. gait numbers) as names
    overlay_labels : labels to print: a list of names, "all", or None for the default
        (gait and state when present, else the first three)
    sides : {element name: side label or None} where the names do not tell the side
        (sides.py; labels: left, right, outer, inner, leg 0, leg 1, leg a, leg b)
    style : Style
    """

    def __init__(self, model, ax, view_width=None, tick_spacing: float = 0.5, show_impulses=True,
                 show_com=True, impulse_scale=None, label_names=None, style: Style | None = None,
                 show_text=True, overlay_labels=None, label_spacing=None, show_legend=True, sides=None):
        if not (tick_spacing > 0 and math.isfinite(tick_spacing)):
            raise ValueError(f"tick_spacing={tick_spacing} must be a finite distance > 0 m")
        self.model, self.ax = model, ax
        self.step_length = model.dt   # [s] turns an impulse into a mean force (draw_frame: the recording's)
        self.style = style or Style()
        self.tick_spacing = float(tick_spacing)
        self.view_width = float(view_width) if view_width else max(2.0, 4.0 * model_extent(model))
        if not (self.view_width > 0 and math.isfinite(self.view_width)):
            raise ValueError(f"view_width={view_width} must be a finite width > 0 m")
        self.label_spacing = self._label_spacing(label_spacing)
        self.show_impulses, self.show_com, self.show_text = bool(show_impulses), bool(show_com), bool(show_text)
        self.show_legend = bool(show_legend)
        self.label_names = label_names or {}
        self.overlay_labels = overlay_labels
        self.sides = model_sides(model, sides)
        weight = model.total_mass * float(np.hypot(*model.arrays.gravity)) or model.total_mass * 9.81
        self.impulse_scale = impulse_scale if impulse_scale else 0.2 * self.view_height / weight
        self._outlines = [shape_outline(s, self.style.arc_points) for s in model.shapes]
        self._shape_body = [s.body for s in model.shapes]
        self._fallback = self._fallback_shapes()
        self._build_artists()

    # setup ----------------------------------------------------------------------------------
    @property
    def view_height(self) -> float:
        """Height of the view [m], from the axes' aspect on screen."""
        fig = self.ax.figure
        pos = self.ax.get_position(original=True)   # before the equal-aspect adjustment
        w_in, h_in = pos.width * fig.get_figwidth(), pos.height * fig.get_figheight()
        return self.view_width * (h_in / w_in if w_in > 0 else 0.5625)

    def _label_spacing(self, spacing) -> float:
        s = self.tick_spacing
        if spacing is None:
            want = self.view_width / 5.0
            spacing = next(c * 10.0 ** e for e in range(-3, 7) for c in (1, 2, 5) if c * 10.0 ** e >= want)
        spacing = float(spacing)
        if not (spacing > 0 and math.isfinite(spacing)):
            raise ValueError(f"label_spacing={spacing} must be a finite distance > 0 m")
        return s * max(1, round(spacing / s))

    def _fallback_shapes(self):
        """Rigid bodies without any shape get a disk of their radius of gyration."""
        a = self.model.arrays
        have = set(self._shape_body)
        out = []
        for b in range(self.model.n_body):
            if b not in have:
                r = math.sqrt(a.body_inertia[b] / a.body_mass[b]) if a.body_inertia[b] > 0 else 0.03
                out.append((b, _circle((0.0, 0.0), min(max(r, 0.02), 0.3), self.style.arc_points)))
        return out

    @property
    def side_labels(self) -> list:
        """The sides present in the model, in legend order."""
        present = {s for group in self.sides.values() for s in group} - {None}
        return [s for s in SIDE_ORDER if s in present]

    def _body_color(self, b):
        st = self.style
        if b < 0:
            return st.terrain_color     # a world shape (a step, a wall): part of the ground
        if not self.side_labels:
            return st.body_colors[b % len(st.body_colors)]
        i = side_index(self.sides["body"][b])
        return st.trunk_color if i is None else st.side_colors[i]

    def _line_style(self, side, color, width):
        i = side_index(side)
        return (color, width) if i is None else (self.style.side_colors[i], self.style.side_line_width)

    def _build_artists(self):
        st, ax, m = self.style, self.ax, self.model
        ax.set_facecolor(st.background)
        ax.set_aspect("equal", adjustable="box")
        ax.set_xticks([])
        ax.set_yticks([])
        self.ground_fill = Polygon(np.zeros((3, 2)), closed=True, facecolor=st.ground_fill,
                                   edgecolor="none", zorder=0)
        ax.add_patch(self.ground_fill)
        self.terrain_line, = ax.plot([], [], color=st.terrain_color, lw=1.5, zorder=1)
        self.ticks = LineCollection([], colors=st.tick_color, linewidths=1.2, zorder=1)
        ax.add_collection(self.ticks)
        n_labels = int(1.2 * self.view_width / self.label_spacing) + 2
        self.tick_labels = [TextStamp(0.0, 0.0, "", transform=ax.transData, ha="center", va="top",
                                      fontsize=0.85 * st.font_size, color=st.text_color, zorder=1)
                            for _ in range(n_labels)]
        for lab in self.tick_labels:
            ax.add_artist(lab)
        bodies = self._shape_body + [b for b, _ in self._fallback]
        self.bodies = PolyCollection([], facecolors=[self._body_color(b) for b in bodies],
                                     edgecolors=st.edge_color, linewidths=0.8, alpha=st.body_alpha, zorder=3)
        ax.add_collection(self.bodies)
        rod = [self._line_style(s, st.rod_color, st.rod_width) for s in self.sides["rod"]]
        self.rods = LineCollection([], colors=[c for c, _ in rod] or st.rod_color,
                                   linewidths=[w for _, w in rod] or st.rod_width, zorder=2)
        ax.add_collection(self.rods)
        self._axial = [j for j in range(m.n_act) if m.arrays.act_kind[j] == ACT_AXIAL]
        act = [self._line_style(self.sides["act"][j], st.actuator_color, 1.5) for j in self._axial]
        self.actuators = LineCollection([], colors=[c for c, _ in act] or st.actuator_color,
                                        linewidths=[w for _, w in act] or 1.5, linestyles="-", zorder=2)
        ax.add_collection(self.actuators)
        self.pins, = ax.plot([], [], "o", ms=4.5, mfc=st.pin_color, mec=st.edge_color, mew=0.8, zorder=5)
        self.impulses = LineCollection([], colors=st.impulse_color, linewidths=1.6, zorder=6)
        ax.add_collection(self.impulses)
        self.com, = ax.plot([], [], ls="none", marker=com_marker(), ms=8, mfc="white", mec=st.com_color,
                            mew=1.2, zorder=7)
        self.text = TextStamp(0.01, 0.98, "", transform=ax.transAxes, ha="left", va="top",
                              fontsize=st.font_size, color=st.text_color, zorder=9)
        ax.add_artist(self.text)
        self.legend = ImageStamp(self._legend_bitmap, 0.99, 0.98, transform=ax.transAxes, ha="right",
                                 va="top", zorder=9)
        ax.add_artist(self.legend)

    # legend ---------------------------------------------------------------------------------
    def legend_entries(self) -> list:
        """[(label, kind, colour)] of the legend: the sides, contact force, centre of mass."""
        st = self.style
        out = [(side if side.startswith("leg") else f"{side} leg", "side", st.side_colors[side_index(side)])
               for side in self.side_labels]
        if self.model.n_contact:
            out.append(("contact force", "arrow", st.impulse_color))
        out.append(("centre of mass", "com", st.com_color))
        return out

    def _legend_bitmap(self, dpi):
        return legend_bitmap(self.legend_entries(), dpi, self.style)

    # geometry per frame -----------------------------------------------------------------------
    def body_polygons(self, q):
        """World outlines of every drawn shape at poses q (n_body, 3)."""
        polys = [world_points(q, b, o) for b, o in zip(self._shape_body, self._outlines)]
        polys += [world_points(q, b, o) for b, o in self._fallback]
        return polys

    def pin_points(self, q) -> np.ndarray:
        """World positions of the joints (a free body's coordinates are no joints: not drawn)."""
        a = self.model.arrays
        pts = [world_points(q, a.pin_body[j, 1], a.pin_anchor[j, 1])[0] for j in range(self.model.n_pin)
               if not a.pin_kind[j] & JOINT_FREE_BIT]
        return np.array(pts).reshape(-1, 2)

    def _segments(self, q, bodies, anchors):
        return [np.vstack([world_points(q, bodies[j, 0], anchors[j, 0]),
                           world_points(q, bodies[j, 1], anchors[j, 1])]) for j in range(len(bodies))]

    def terrain_geometry(self, x0, x1):
        """(terrain polyline (N, 2), tick segments (M, 2, 2)) for x0 <= x <= x1 [m]; ticks at
        multiples of label_spacing are 1.8x longer."""
        line, ticks, _ = self._terrain(x0, x1)
        return line, ticks

    def _terrain(self, x0, x1):
        ter = self.model.terrain
        if ter is None:         # no ground (ModelBuilder(ground=None)): nothing drawn
            return np.zeros((0, 2)), np.zeros((0, 2, 2)), np.zeros(0, dtype=bool)
        xs = np.linspace(x0, x1, 121)      # 5 cm apart on a 5 m view: smooth for hills of 1 m and more
        line = np.column_stack([xs, ter.height(xs)])
        s = self.tick_spacing
        xt = s * np.arange(math.ceil(x0 / s), math.floor(x1 / s) + 1)
        major = np.abs(xt / self.label_spacing - np.round(xt / self.label_spacing)) < 1e-6
        base = np.column_stack([xt, ter.height(xt)])
        length = self.style.tick_length * np.where(major, 1.8, 1.0)
        tip = base - length[:, None] * ter.normal(xt).reshape(-1, 2)
        return line, np.stack([base, tip], axis=1), major

    def _place_tick_labels(self, ticks, major, center_x):
        """Labels under the labelled ticks inside the view (none cut by its edge)."""
        tips = ticks[major, 1]
        xs = ticks[major, 0, 0]
        keep = np.abs(xs - center_x) <= 0.45 * self.view_width
        tips, xs = tips[keep], xs[keep]
        gap = 0.3 * self.style.tick_length
        for i, lab in enumerate(self.tick_labels):
            if i < len(xs):
                lab.set_text(distance_label(xs[i]))
                lab.set_position((tips[i, 0], tips[i, 1] - gap))
                lab.set_visible(True)
            else:
                lab.set_visible(False)

    def impulse_segments(self, points, impulses, modes=None, normals=None):
        """Arrow segments (shaft and two head strokes) for contact impulses (n_contact, 2)
        (normal, tangential) [N s] at points (n_contact, 2), drawn as mean force x impulse_scale,
        along the contacts' normals (n_contact, 2) where given (a shape pair's), else the
        ground's."""
        segs = []
        dt = self.step_length
        ter = self.model.terrain
        for i in range(len(points)):
            ln, lt = impulses[i]
            if ln == 0.0 and lt == 0.0:
                continue
            if normals is not None and np.all(np.isfinite(normals[i])):
                n = np.asarray(normals[i], float)
            elif ter is None:
                continue        # no normal recorded and no ground to take one from
            else:
                n = ter.normal(points[i, 0]).reshape(2)
            t = np.array([n[1], -n[0]])
            vec = (ln * n + lt * t) / dt * self.impulse_scale
            size = float(np.hypot(*vec))
            if size < 1e-9:
                continue
            p0 = np.asarray(points[i], float)
            p1 = p0 + vec
            head = min(0.35 * size, 0.04 * self.view_width)
            u = vec / size
            side = np.array([-u[1], u[0]])
            segs += [np.array([p0, p1]), np.array([p1, p1 - head * u + 0.5 * head * side]),
                     np.array([p1, p1 - head * u - 0.5 * head * side])]
        return segs

    def com_of(self, q) -> np.ndarray:
        mass = self.model.arrays.body_mass
        return (mass[:, None] * q[:, :2]).sum(axis=0) / mass.sum()

    def overlay_text(self, t=None, speed=None, labels=None) -> str:
        parts = []
        if t is not None:
            parts.append(f"t = {t:7.3f} s")
        if speed is not None:
            parts.append(f"v = {speed:+.2f} m/s")
        lines = ["   ".join(parts)] if parts else []
        for key, val in self._shown_labels(labels or {}).items():
            names = self.label_names.get(key)
            try:
                name = names[int(val)] if names is not None else None
            except (KeyError, IndexError, TypeError, ValueError):
                name = None
            if name is None and isinstance(val, (int, float, np.number)):
                name = f"{int(val)}" if float(val).is_integer() else f"{float(val):.3g}"
            elif name is None:
                name = str(val)
            lines.append(f"{key}: {name}")
        return "\n".join(lines)

    def _shown_labels(self, labels: dict) -> dict:
        pick = self.overlay_labels
        if pick == "all":
            return labels
        if pick is None:
            pick = [k for k in ("gait", "state") if k in labels] or list(labels)[:3]
        return {k: labels[k] for k in pick if k in labels}

    # the frame ------------------------------------------------------------------------------
    def set_view(self, center) -> None:
        """Centre the view on `center` (2,) [m]."""
        w, h = self.view_width, self.view_height
        self.ax.set_xlim(center[0] - w / 2, center[0] + w / 2)
        self.ax.set_ylim(center[1] - h / 2, center[1] + h / 2)

    def draw_state(self, q, center=None, t=None, contact_point=None, contact_impulse=None,
                   labels=None, speed=None, contact_normal=None) -> list:
        """Move every artist to poses q (n_body, 3) with the view centred on `center` [m]
        (default: the COM); t [s] and speed [m/s] go in the overlay. Returns the artists
        (for blitting)."""
        q = np.asarray(q, float)
        a = self.model.arrays
        com = self.com_of(q)
        center = com if center is None else np.asarray(center, float)
        self.set_view(center)
        x0, x1 = center[0] - 0.6 * self.view_width, center[0] + 0.6 * self.view_width
        line, ticks, major = self._terrain(x0, x1)
        self.terrain_line.set_data(line[:, 0], line[:, 1])
        self.ground_fill.set_visible(len(line) > 0)
        if len(line):
            bottom = center[1] - 2.0 * self.view_height - abs(line[:, 1]).max()
            self.ground_fill.set_xy(np.vstack([line, [[x1, bottom], [x0, bottom]]]))
        self.ticks.set_segments(list(ticks))
        self._place_tick_labels(ticks, major, center[0])
        self.bodies.set_verts(self.body_polygons(q))
        self.rods.set_segments(self._segments(q, a.rod_body, a.rod_anchor))
        axial = self._axial
        self.actuators.set_segments(self._segments(q, a.act_body[axial, :2], a.act_anchor[axial])
                                    if axial else [])
        pins = self.pin_points(q)
        self.pins.set_data(pins[:, 0], pins[:, 1])
        show_imp = self.show_impulses and contact_point is not None and contact_impulse is not None
        self.impulses.set_segments(self.impulse_segments(np.asarray(contact_point), np.asarray(contact_impulse),
                                                         normals=contact_normal)
                                   if show_imp else [])
        self.impulses.set_visible(show_imp)
        self.com.set_data([com[0]], [com[1]])
        self.com.set_visible(self.show_com)
        self.text.set_text(self.overlay_text(t, speed, labels) if self.show_text else "")
        self.legend.set_visible(self.show_legend)
        return self.artists

    @property
    def artists(self) -> list:
        return [self.ground_fill, self.terrain_line, self.ticks, *self.tick_labels, self.rods, self.actuators,
                self.bodies, self.pins, self.impulses, self.com, self.text, self.legend]

    def draw_frame(self, traj, k: int, center=None, t=None) -> list:
        """Draw recorded frame k of a Trajectory; t [s] is the time shown (default: its own)."""
        labels = {key: np.asarray(v)[k] for key, v in traj.labels.items()
                  if np.ndim(v) == 1 and len(v) == len(traj.t)}
        speed = float(self.model.arrays.body_mass @ traj.v[k, :, 0] / self.model.total_mass)
        self.step_length = float(traj.info.get("dt", self.model.dt))
        return self.draw_state(traj.q[k], center=center, t=float(traj.t[k]) if t is None else float(t),
                               contact_point=traj.contact_point[k], contact_impulse=traj.contact_impulse[k],
                               labels=labels, speed=speed,
                               contact_normal=None if traj.contact_normal is None else traj.contact_normal[k])


def distance_label(x: float) -> str:
    """'2 m', '0.5 m', '-1 m' for a tick at x [m] (no '-0', no rounding noise)."""
    x = round(float(x), 6)
    return f"{0.0 if x == 0 else x:g} m"


def make_figure(size=(6.4, 3.6), dpi: int = 100):
    """A figure whose single axes fills it (no margins): the frame of an animation."""
    import matplotlib.figure
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    fig = matplotlib.figure.Figure(figsize=size, dpi=dpi)
    FigureCanvasAgg(fig)
    ax = fig.add_axes((0.0, 0.0, 1.0, 1.0))
    ax.set_axis_off()
    ax.patch.set_visible(True)
    return fig, ax


def render_state(model, q, path=None, size=(6.4, 3.6), dpi=100, center=None, **scene_kw):
    """Draw one state (n_body, 3) on a new Agg figure; save it to `path` if given.
    Returns (fig, scene)."""
    fig, ax = make_figure(size, dpi)
    scene = Scene(model, ax, **scene_kw)
    scene.draw_state(q, center=center)
    if path is not None:
        save_figure(fig, path)
    return fig, scene

"""``pmnav annotate FILE``: a Tkinter tool to annotate a building over its floor plan.

The floor plan is drawn with the corridors at their widths, key waypoints, doors,
rooms and landmarks. Modes (toolbar, or keys): select/move (s), add room (r), add
waypoint (w), add landmark (l), add corridor between two waypoints (e), delete (d).
Dragging moves the selected item; the panel on the right edits its id, name,
aliases, sign text and kind. Validation messages (load errors, then 'pmnav validate'
warnings) update after every edit. Ctrl+Z undoes, Ctrl+S saves; the wheel or +/-
zooms at the pointer, the right button (or the arrow keys) pans.
"""

from __future__ import annotations

import base64
import math
import shlex
import tkinter as tk
from pathlib import Path

import cv2
import numpy as np

from pmnav_bt.errors import PmNavError
from pmnav_bt.map.edit import GROUPS, POS_KEY, BuildingEditor, EditError
from pmnav_bt.map.floorplan import FloorPlanImage, load_floor_plan

MODES = (
    ("select", "Select / move", "s"),
    ("room", "Add room", "r"),
    ("waypoint", "Add waypoint", "w"),
    ("landmark", "Add landmark", "l"),
    ("edge", "Add corridor", "e"),
    ("delete", "Delete", "d"),
)
KIND_FILL = {"start": "#1a9e3a", "turn": "#f07d00", "branch": "#a020c0", "end": "#d01c1c"}
ROOM_FILL, LANDMARK_FILL = "#a0522d", "#117a8b"
CORRIDOR_FILL, CORRIDOR_EDGE, SELECT = "#cfe3f7", "#3a78c2", "#ff0000"
PICK_PX = 12  # a click this close to an item picks it
TITLE = "pmnav annotate"


class AnnotateApp:
    """The window: toolbar, map canvas, item fields and messages, over a BuildingEditor."""

    def __init__(self, editor: BuildingEditor, root: tk.Tk | None = None, size=(900, 700)):
        self.editor = editor
        self.root = root or tk.Tk()
        self.root.title(f"{TITLE}: {editor.path or 'new building'}")
        self.mode = tk.StringVar(value="select")
        self.wp_kind = tk.StringVar(value="end")
        self.selected: str | None = None
        self._edge_from: str | None = None
        self._drag: tuple[str, float, float] | None = None
        self._pan: tuple[int, int] | None = None
        self._photo = None
        self.plan = self._load_plan()
        self._build_widgets(size)
        self.scale, self.ox, self.oy = 10.0, 0.0, 0.0
        self.root.update_idletasks()
        self.fit()
        self.refresh()

    # -- setup ----------------------------------------------------------------------------

    def _load_plan(self) -> FloorPlanImage | None:
        try:
            b = self.editor.building()
            base = self.editor.path.parent if self.editor.path else Path(".")
            return load_floor_plan(b, base)
        except PmNavError:
            return None

    def _build_widgets(self, size) -> None:
        bar = tk.Frame(self.root)
        bar.pack(side=tk.TOP, fill=tk.X)
        for value, text, key in MODES:
            tk.Radiobutton(
                bar, text=text, value=value, variable=self.mode, indicatoron=False, padx=6
            ).pack(side=tk.LEFT)
            self.root.bind(f"<Key-{key}>", lambda _e, v=value: self._key_mode(v))
        tk.OptionMenu(bar, self.wp_kind, "start", "turn", "branch", "end").pack(side=tk.LEFT)
        for text, cmd in (("Undo", self.undo), ("Save", self.save), ("Fit", self.fit_redraw)):
            tk.Button(bar, text=text, command=cmd).pack(side=tk.LEFT)
        body = tk.Frame(self.root)
        body.pack(side=tk.TOP, fill=tk.BOTH, expand=True)
        self.canvas = tk.Canvas(body, width=size[0], height=size[1], bg="white")
        self.canvas.pack(side=tk.LEFT, fill=tk.BOTH, expand=True)
        side = tk.Frame(body, width=320)
        side.pack(side=tk.RIGHT, fill=tk.Y)
        self.fields: dict[str, tk.Entry] = {}
        for name in ("id", "name", "aliases", "sign", "kind"):
            row = tk.Frame(side)
            row.pack(fill=tk.X)
            tk.Label(row, text=name, width=8, anchor="w").pack(side=tk.LEFT)
            ent = tk.Entry(row, width=28)
            ent.pack(side=tk.LEFT, fill=tk.X, expand=True)
            ent.bind("<Return>", lambda _e: self.apply_fields())
            self.fields[name] = ent
        tk.Button(side, text="Apply", command=self.apply_fields).pack(fill=tk.X)
        self.status = tk.Label(side, text="", anchor="w", fg="#b00000", wraplength=310)
        self.status.pack(fill=tk.X)
        tk.Label(side, text="Validation", anchor="w").pack(fill=tk.X)
        self.messages = tk.Listbox(side, width=48, height=30)
        self.messages.pack(fill=tk.BOTH, expand=True)
        c = self.canvas
        c.bind("<ButtonPress-1>", self._on_press)
        c.bind("<B1-Motion>", self._on_drag)
        c.bind("<ButtonRelease-1>", self._on_release)
        for seq in ("<ButtonPress-3>", "<ButtonPress-2>"):
            c.bind(seq, lambda e: setattr(self, "_pan", (e.x, e.y)))
        for seq in ("<B3-Motion>", "<B2-Motion>"):
            c.bind(seq, self._on_pan)
        c.bind("<Button-4>", lambda e: self.zoom(1.25, e.x, e.y))
        c.bind("<Button-5>", lambda e: self.zoom(0.8, e.x, e.y))
        c.bind("<MouseWheel>", lambda e: self.zoom(1.25 if e.delta > 0 else 0.8, e.x, e.y))
        c.bind("<Configure>", lambda _e: self.redraw())
        r = self.root
        r.bind("<Control-z>", lambda _e: self.undo())
        r.bind("<Control-s>", lambda _e: self.save())
        r.bind("<plus>", lambda _e: self.zoom(1.25))
        r.bind("<minus>", lambda _e: self.zoom(0.8))
        for key, (dx, dy) in {
            "Left": (40, 0),
            "Right": (-40, 0),
            "Up": (0, 40),
            "Down": (0, -40),
        }.items():
            r.bind(f"<Key-{key}>", lambda _e, d=(dx, dy): self.pan(*d))

    def _key_mode(self, value: str) -> None:
        if not isinstance(self.root.focus_get(), tk.Entry):
            self.mode.set(value)

    # -- view ------------------------------------------------------------------------------

    def world_to_screen(self, xy) -> tuple[float, float]:
        return (xy[0] - self.ox) * self.scale, (self.oy - xy[1]) * self.scale

    def screen_to_world(self, u: float, v: float) -> tuple[float, float]:
        return u / self.scale + self.ox, self.oy - v / self.scale

    def _extent(self) -> tuple[float, float, float, float]:
        pts = [it[POS_KEY[g]] for g in GROUPS for it in self.editor.items(g)]
        if self.plan is not None:
            pts += self.plan.corners_world().tolist()
        if not pts:
            return -10.0, -10.0, 10.0, 10.0
        a = np.array(pts, float)
        return a[:, 0].min() - 2, a[:, 1].min() - 2, a[:, 0].max() + 2, a[:, 1].max() + 2

    def fit(self) -> None:
        x0, y0, x1, y1 = self._extent()
        w = max(self.canvas.winfo_width(), 50)
        h = max(self.canvas.winfo_height(), 50)
        self.scale = min(w / (x1 - x0), h / (y1 - y0))
        self.ox = (x0 + x1) / 2 - w / 2 / self.scale
        self.oy = (y0 + y1) / 2 + h / 2 / self.scale

    def fit_redraw(self) -> None:
        self.fit()
        self.redraw()

    def zoom(self, factor: float, u: float | None = None, v: float | None = None) -> None:
        """Zoom by ``factor`` keeping the point under (u, v) (default: the centre) in place."""
        if u is None:
            u, v = self.canvas.winfo_width() / 2, self.canvas.winfo_height() / 2
        x, y = self.screen_to_world(u, v)
        self.scale = float(np.clip(self.scale * factor, 0.5, 400.0))
        self.ox, self.oy = x - u / self.scale, y + v / self.scale
        self.redraw()

    def pan(self, du: float, dv: float) -> None:
        self.ox -= du / self.scale
        self.oy += dv / self.scale
        self.redraw()

    def _on_pan(self, e) -> None:
        if self._pan is not None:
            self.pan(e.x - self._pan[0], e.y - self._pan[1])
        self._pan = (e.x, e.y)

    # -- drawing ----------------------------------------------------------------------------

    def refresh(self) -> None:
        """Redraw and re-check after an edit."""
        self.redraw()
        self.messages.delete(0, tk.END)
        problems = self.editor.problems()
        for line in problems or ["OK: no problems, no warnings"]:
            self.messages.insert(tk.END, line)
        dirty = " *" if self.editor.dirty else ""
        self.root.title(f"{TITLE}: {self.editor.path or 'new building'}{dirty}")

    def redraw(self) -> None:
        c = self.canvas
        c.delete("all")
        if self.plan is not None:
            self._draw_plan()
        self._draw_corridors()
        for it in self.editor.items("rooms"):
            self._draw_item(it["id"], it["door"], "room", ROOM_FILL)
        for it in self.editor.items("landmarks"):
            self._draw_item(it["id"], it["pos"], "landmark", LANDMARK_FILL)
        for it in self.editor.items("waypoints"):
            self._draw_item(it["id"], it["pos"], "waypoint", KIND_FILL.get(it["kind"], "#444"))

    def _draw_plan(self) -> None:
        w, h = self.canvas.winfo_width(), self.canvas.winfo_height()
        if w < 2 or h < 2:
            return
        s = self.scale
        to_screen = np.array([[s, 0.0, -s * self.ox], [0.0, -s, s * self.oy], [0.0, 0.0, 1.0]])
        to_plan = np.vstack([self.plan.affine(), [0.0, 0.0, 1.0]])
        m = (to_plan @ np.linalg.inv(to_screen))[:2]
        img = cv2.warpAffine(
            self.plan.bgr(),
            m,
            (w, h),
            flags=cv2.INTER_NEAREST | cv2.WARP_INVERSE_MAP,
            borderValue=(255, 255, 255),
        )
        ok, png = cv2.imencode(".png", img)
        self._photo = tk.PhotoImage(data=base64.b64encode(png.tobytes()).decode("ascii"))
        self.canvas.create_image(0, 0, image=self._photo, anchor="nw", tags=("plan",))

    def _draw_corridors(self) -> None:
        pos = {w["id"]: w["pos"] for w in self.editor.items("waypoints")}
        default = float(self.editor.data.get("corridor_width", 2.4))
        for a, b, width in self.editor.edge_ends():
            if a not in pos or b not in pos or a == b:
                continue
            pa, pb = np.array(pos[a], float), np.array(pos[b], float)
            d = pb - pa
            if np.linalg.norm(d) < 1e-6:
                continue
            u = d / np.linalg.norm(d)
            n = np.array([-u[1], u[0]]) * (width or default) / 2.0
            quad = [pa + n, pb + n, pb - n, pa - n]
            flat = [c for p in quad for c in self.world_to_screen(p)]
            self.canvas.create_polygon(
                flat,
                fill=CORRIDOR_FILL,
                outline=CORRIDOR_EDGE,
                stipple="gray50",
                tags=("corridor", f"edge:{a}:{b}"),
            )
            self.canvas.create_line(
                *self.world_to_screen(pa),
                *self.world_to_screen(pb),
                fill=CORRIDOR_EDGE,
                dash=(4, 3),
            )

    def _draw_item(self, ident: str, xy, kind: str, fill: str) -> None:
        u, v = self.world_to_screen(xy)
        r = 7
        outline = SELECT if ident == self.selected else "black"
        width = 3 if ident == self.selected else 1
        tags = ("item", f"id:{ident}")
        if kind == "room":
            self.canvas.create_rectangle(
                u - r,
                v - r / 2,
                u + r,
                v + r / 2,
                fill=fill,
                outline=outline,
                width=width,
                tags=tags,
            )
        elif kind == "landmark":
            pts = [u, v - r, u + r, v, u, v + r, u - r, v]
            self.canvas.create_polygon(pts, fill=fill, outline=outline, width=width, tags=tags)
        else:
            self.canvas.create_oval(
                u - r, v - r, u + r, v + r, fill=fill, outline=outline, width=width, tags=tags
            )
        self.canvas.create_text(
            u + r + 3, v - r, text=ident, anchor="sw", font=("TkDefaultFont", 9), tags=tags
        )

    # -- mouse ------------------------------------------------------------------------------

    def pick(self, u: float, v: float) -> str | None:
        return self.editor.nearest(self.screen_to_world(u, v), PICK_PX / self.scale)

    def _on_press(self, e) -> None:
        self.canvas.focus_set()
        xy = self.screen_to_world(e.x, e.y)
        mode = self.mode.get()
        try:
            if mode == "select":
                self.select(self.pick(e.x, e.y))
                if self.selected:
                    self._drag = (self.selected, e.x, e.y)
                return
            if mode == "room":
                self.select(self.editor.add_room(xy))
            elif mode == "waypoint":
                self.select(self.editor.add_waypoint(xy, self.wp_kind.get()))
            elif mode == "landmark":
                self.select(self.editor.add_landmark(xy))
            elif mode == "delete":
                hit = self.pick(e.x, e.y)
                if hit:
                    self.editor.delete(hit)
                    self.select(None)
            elif mode == "edge":
                hit = self.pick(e.x, e.y)
                if hit and self._edge_from and hit != self._edge_from:
                    self.editor.add_edge(self._edge_from, hit)
                    self._edge_from = None
                else:
                    self._edge_from = hit
                self.select(hit)
            self.say("")
        except EditError as err:
            self.say(str(err))
        self.refresh()

    def _on_drag(self, e) -> None:
        if self._drag is None:
            return
        ident, u0, v0 = self._drag
        self.canvas.move(f"id:{ident}", e.x - u0, e.y - v0)
        self._drag = (ident, e.x, e.y)

    def _on_release(self, e) -> None:
        if self._drag is None:
            return
        ident = self._drag[0]
        self._drag = None
        old = self.world_to_screen(self.editor.position(ident))
        if math.dist(old, (e.x, e.y)) >= 2:
            self.editor.move(ident, self.screen_to_world(e.x, e.y))
            self.refresh()

    # -- fields, undo, save ------------------------------------------------------------------

    def select(self, ident: str | None) -> None:
        self.selected = ident
        for ent in self.fields.values():
            ent.delete(0, tk.END)
        if ident is None:
            return
        _, it = self.editor.find(ident)
        for name, ent in self.fields.items():
            v = it.get(name, "")
            ent.insert(0, ", ".join(v) if isinstance(v, list) else str(v))

    def apply_fields(self) -> None:
        if self.selected is None:
            self.say("select an item first")
            return
        g, _ = self.editor.find(self.selected)
        allowed = {
            "waypoints": ("id", "kind"),
            "rooms": ("id", "name", "aliases", "sign"),
            "landmarks": ("id", "kind", "name", "aliases", "sign"),
        }[g]
        values = {k: self.fields[k].get().strip() for k in allowed}
        try:
            self.selected = self.editor.set_fields(self.selected, **values)
            self.say("")
        except EditError as err:
            self.say(str(err))
        self.refresh()

    def undo(self) -> None:
        if not self.editor.undo():
            self.say("nothing to undo")
        if self.selected and self.selected not in self.editor.ids():
            self.select(None)
        self.refresh()

    def save(self) -> None:
        try:
            path = self.editor.save()
            self.say(f"saved {path}")
        except (EditError, OSError) as err:
            self.say(f"not saved: {err}")
        self.refresh()

    def say(self, text: str) -> None:
        self.status.configure(text=text)


def run(path: str | Path) -> None:
    """Open the tool on a building file and run until the window closes."""
    import os

    if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        raise PmNavError(
            "pmnav annotate opens a window, but DISPLAY is not set (no display): run it on "
            "a desktop, over ssh -X, or in a virtual display: xvfb-run -a pmnav annotate "
            f"{shlex.quote(str(path))} (package xvfb; to see and use the window there, "
            "docs/real-maps.md section 4)"
        )
    try:
        root = tk.Tk()
    except tk.TclError as err:
        raise PmNavError(f"pmnav annotate cannot open a window: {err}") from None
    AnnotateApp(BuildingEditor.open(path), root)
    root.mainloop()

"""A user's method from a TOML file: a routine spec plus a hitbox rule (docs/methods.md).

    name = "shrunk"                 # the method's key in the CSV (default: the file's stem)
    label = "tight box, 1 px in"    # the chart's label (default: the name)
    routine = "aabb8"               # a built-in routine or a spec file (relative to this file); none: host only
    prepare = "aabb_edges_prepare"  # optional: the once-per-object preparation routine
    prepare_per = "object"          # optional: "object" (default) or "kind_pair" (once per pair of kinds)
    hit = "hit"                     # optional: the routine's output that answers (default: its first)

    [hitbox]
    shape = "box"                   # box | circle | mask | function
    fit = "tight"                   # box: "tight" (bounds of the opaque pixels) or "full" (the sprite box)
    inset = 1                       # box: pixels off every side, or [left, top, right, bottom]; circle: off r
    touching = false                # box, circle: whether touching boxes / tangent circles collide
    function = "rule.py:hit"        # function: FILE.py:NAME, hit(a, b, dx, dy) -> one verdict per offset

    [inputs]                        # each routine input as an expression over the case
    ax = "a_x"
    bx = "b_x"
    ...

Every error is one line naming the file and the field. The routine's answer is checked against the
hitbox rule on every measured case (a mismatch stops the run), so the rule is what the chart's
accuracy counts and the routine is what its cycles count.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from retro.analysis.study.corpus import Pair, Shape
from retro.analysis.study.fits import Box, Circle, fitted_circle, full_box, tight_box
from retro.analysis.study.methods.base import ORIGIN, Method
from retro.chips.vic.constants import SPRITE_BYTES, SPRITE_HEIGHT, SPRITE_WIDTH
from retro.errors import InputError, RunError
from retro.fields import Fields
from retro.fileio import parse_toml, read_bytes
from retro.routines import sandbox
from retro.routines.spec import import_user_module


MAX_METHOD_BYTES = 1 << 16
TOP_KEYS = {"name", "label", "routine", "prepare", "prepare_per", "hit", "colour", "marker", "hitbox", "inputs"}
SHAPE_KEYS = {"box": {"shape", "fit", "inset", "touching"}, "circle": {"shape", "inset", "touching"},
              "mask": {"shape"}, "function": {"shape", "function", "time_limit"}}
FITS = {"tight": tight_box, "full": full_box}
NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_-]{0,31}$")
MAX_INSET = SPRITE_WIDTH  # an inset beyond a whole sprite width moves the hitbox off the sprite
SPRITE_SHAPE = (SPRITE_HEIGHT, SPRITE_WIDTH)  # a mask's (rows, columns) when unexpanded
MAX_TEXT = 200  # characters of a name, label, colour or marker

# What an input expression may name: the offset, and per sprite (a_ and b_) its sprite box's position,
# the method's box, the method's circle and the opacity mask, in screen coordinates with sprite a at
# (ORIGIN, ORIGIN). For a circle, mask or function rule the box is the tight box; for a box, mask or
# function rule the circle is the fitted circle (strict).
PER_SPRITE = ("sx", "sy", "x", "y", "w", "h", "right", "right1", "bottom", "bottom1", "cx", "cy", "r", "mask")
NAMES = ("dx", "dy") + tuple(f"{s}_{n}" for s in "ab" for n in PER_SPRITE)
MASKS = frozenset(name for name in NAMES if name.endswith("_mask"))  # tables of bytes; the rest are numbers
DEFAULT_COLOURS = ("#e377c2", "#7f7f7f", "#bcbd22", "#393b79", "#637939", "#843c39", "#7b4173")
DEFAULT_MARKERS = ("v", "<", ">", "p", "8", "H", "1")


@dataclass(frozen=True)
class Hitbox:
    shape: str
    fit: str = "tight"
    inset: tuple[int, int, int, int] = (0, 0, 0, 0)  # left, top, right, bottom (a circle uses the first)
    touching: bool = False
    function: object = None  # the user's function for shape = "function"
    function_text: str = ""
    time_limit: int = sandbox.DEFAULT_SECONDS  # seconds one call of the function may take


@dataclass(frozen=True, kw_only=True)
class UserMethod(Method):
    path: str
    hitbox: Hitbox
    inputs: tuple = ()  # (input name, expression text, compiled function), in the routine's input order
    input_bits: tuple = ()  # per input: bits of a number, or -size for a table of that many bytes
    domain: tuple = field(default=(), repr=False)  # the routine's `where` conditions

    def __reduce__(self):  # workers re-read the file: the user's function is not picklable
        return load_method_file, (self.path,)

    # ---- the hitbox rule ------------------------------------------------------------------------

    def box(self, shape: Shape) -> Box:
        """The hitbox: the fitted box with the inset taken off each side; on an axis where that
        leaves no pixel, the box keeps the middle pixel of the fitted box (rounded down)."""
        x0, y0, x1, y1 = FITS[self.hitbox.fit](shape.mask)
        left, top, right, bottom = self.hitbox.inset

        def side(lo: int, hi: int, cut_lo: int, cut_hi: int) -> tuple[int, int]:
            if lo + cut_lo < hi - cut_hi:
                return lo + cut_lo, hi - cut_hi
            middle = (lo + hi - 1) // 2
            return middle, middle + 1

        (bx0, bx1), (by0, by1) = side(x0, x1, left, right), side(y0, y1, top, bottom)
        return bx0, by0, bx1, by1

    def circle(self, shape: Shape) -> Circle:
        c = fitted_circle(shape.mask, self.hitbox.touching)
        r = c.r - self.hitbox.inset[0]
        if r < 0:
            raise InputError(f"{self.path}: hitbox.inset: {self.hitbox.inset[0]} is more than the radius {c.r} "
                             f"of sprite {shape.name}")
        return Circle(c.cx, c.cy, r)

    def x_extent(self, shape: Shape) -> tuple[int, int]:
        """The X columns of the hitbox (one more on the right when touching counts), the tight box
        for a mask, the sprite box for a function (the corpus decides nothing outside it)."""
        grow = 1 if self.hitbox.touching else 0
        if self.hitbox.shape == "box":
            x0, _, x1, _ = self.box(shape)
            return x0, x1 + grow
        if self.hitbox.shape == "circle":
            c = self.circle(shape)
            return c.cx - c.r, c.cx + c.r + grow
        if self.hitbox.shape == "mask":
            x0, _, x1, _ = tight_box(shape.mask)
            return x0, x1
        return super().x_extent(shape)

    def verdict(self, pair: Pair) -> np.ndarray:
        shape, touching = self.hitbox.shape, self.hitbox.touching
        if shape == "box":
            (ax0, ay0, ax1, ay1), (bx0, by0, bx1, by1) = self.box(pair.a), self.box(pair.b)
            dx, dy = pair.dx, pair.dy
            if touching:
                hit = (ax0 <= bx1 + dx) & (bx0 + dx <= ax1) & (ay0 <= by1 + dy) & (by0 + dy <= ay1)
            else:
                hit = (ax0 < bx1 + dx) & (bx0 + dx < ax1) & (ay0 < by1 + dy) & (by0 + dy < ay1)
            return hit.astype(float)
        if shape == "circle":
            ca, cb = self.circle(pair.a), self.circle(pair.b)
            ddx, ddy = cb.cx + pair.dx - ca.cx, cb.cy + pair.dy - ca.cy
            d2, reach = ddx * ddx + ddy * ddy, (ca.r + cb.r) ** 2
            return (d2 <= reach if touching else d2 < reach).astype(float)
        if shape == "mask":
            return (pair.overlap > 0).astype(float)
        return self._function_verdict(pair)

    def _function_verdict(self, pair: Pair) -> np.ndarray:
        """The user's rule on a pair, under the sandbox's guards; whatever goes wrong (a raise, an exit, a
        hang, an answer of the wrong shape or range) is one line naming the function and the pair, exit 2."""
        key = f"{self.path}: hitbox.function: {self.hitbox.function_text}"
        arguments = (pair.a.mask.copy(), pair.b.mask.copy(), pair.dx.copy(), pair.dy.copy())
        result = sandbox.call_guarded(self.hitbox.function, key, self.hitbox.time_limit, arguments, {},
                                      faults_only=False, case=f"on {pair.name}")
        try:
            out = np.asarray(result, dtype=float)
        except (TypeError, ValueError, OverflowError):
            raise sandbox.UserCodeError(f"{key} returned {sandbox.shown(result)} on {pair.name}: expected one "
                                        "verdict per offset") from None
        if out.shape != pair.dx.shape:
            raise sandbox.UserCodeError(f"{key} returned shape {out.shape} for {pair.dx.size} offsets (one verdict "
                                        f"per offset) on {pair.name}")
        if out.size and (np.isnan(out).any() or out.min() < 0 or out.max() > 1):
            raise sandbox.UserCodeError(f"{key} returned values outside [0, 1] (True/False or a share of hits) "
                                        f"on {pair.name}")
        return out

    # ---- the routine's inputs -------------------------------------------------------------------

    def _sprite_values(self, shape: Shape, sx: int, sy: int) -> list:
        from retro.analysis.study.methods.pixel import opacity_bytes

        x0, y0, x1, y1 = self.box(shape) if self.hitbox.shape == "box" else tight_box(shape.mask)
        c = self.circle(shape) if self.hitbox.shape == "circle" else fitted_circle(shape.mask)
        mask = opacity_bytes(shape) if shape.mask.shape == SPRITE_SHAPE else ()
        return [sx, sy, sx + x0, sy + y0, x1 - x0, y1 - y0, sx + x1, sx + x1 - 1, sy + y1, sy + y1 - 1,
                sx + c.cx, sy + c.cy, c.r, mask]

    def case_maker(self, pair: Pair):
        a = self._sprite_values(pair.a, ORIGIN, ORIGIN)
        b0 = self._sprite_values(pair.b, 0, 0)
        moved_x = {0, 2, 6, 7, 10}  # b's values that move with dx (sx, x, right, right1, cx) ...
        moved_y = {1, 3, 8, 9, 11}  # ... and with dy
        dxs, dys = pair.dx.tolist(), pair.dy.tolist()

        def case(i: int) -> tuple:
            dx, dy = dxs[i], dys[i]
            b = [v + ORIGIN + dx if k in moved_x else v + ORIGIN + dy if k in moved_y else v for k, v in enumerate(b0)]
            values = (dx, dy, *a, *b)
            out = []
            for (name, _, compiled), bits in zip(self.inputs, self.input_bits):
                try:
                    value = compiled(*values)
                except InputError:  # x // 0, a negative shift: one line naming the expression and the case
                    raise
                except Exception as exc:
                    raise RunError(f"{self.path}: inputs.{name}: {type(exc).__name__}: {exc} on {pair.name} at "
                                   f"offset ({dx}, {dy})") from None
                out.append(_checked(value, bits, f"{self.path}: inputs.{name}", f"on {pair.name} at offset ({dx}, {dy})"))
            case_values = tuple(out)
            for condition in self.domain:
                if not condition.test(*case_values):
                    raise RunError(f"{self.path}: inputs: on {pair.name} at offset ({dx}, {dy}) the case is outside "
                                   f"the routine's domain ({condition.text})")
            return dict(zip((name for name, _, _ in self.inputs), case_values))
        return case

    def unmeasurable(self, pair: Pair) -> str:
        if any(bits < 0 for bits in self.input_bits) and {pair.a.mask.shape, pair.b.mask.shape} != {SPRITE_SHAPE}:
            return f"its {SPRITE_BYTES}-byte mask inputs need unexpanded {SPRITE_WIDTH}x{SPRITE_HEIGHT} sprites"
        return ""

    def session(self, pair: Pair):
        if self.routine is None:
            raise RunError(f"{self.path}: routine: none given, the method is host only")
        return super().session(pair)


def _checked(value, bits: int, field_name: str, where: str):
    if bits < 0:  # a table input of -bits bytes
        if not isinstance(value, (tuple, list)) or len(value) != -bits:
            raise RunError(f"{field_name}: expected {-bits} bytes (e.g. a_mask) {where}")
        return tuple(int(v) for v in value)
    if isinstance(value, bool):
        value = int(value)
    if not isinstance(value, int) or not 0 <= value < 1 << bits:
        raise RunError(f"{field_name}: {sandbox.shown(value)} does not fit the input's {bits} bits {where} (use & 255, >> 8)")
    return value


# ---- reading the file ------------------------------------------------------------------------------

def _load_function(fields: Fields, text) -> object:
    key = "hitbox.function"
    if not isinstance(text, str) or ":" not in text:
        raise fields.error(key, "expected FILE.py:NAME (relative to the method file)")
    file_text, _, name = text.rpartition(":")
    if not file_text.endswith(".py") or not name.isidentifier():
        raise fields.error(key, f"{text!r}: expected FILE.py:NAME (relative to the method file)")
    file = fields.file(file_text, key, resolve=True)
    try:
        module = sandbox.call_guarded(import_user_module, file.name, sandbox.DEFAULT_SECONDS,
                                      (str(file), file.stat().st_mtime), {}, faults_only=True, case="at import")
    except sandbox.UserCodeError as exc:  # sys.exit, os._exit, a hang at import time
        raise fields.error(key, f"{file.name} failed to import: {exc}") from None
    except Exception as exc:  # the user's module failed to import: one line, whatever it raised
        raise fields.error(key, f"{file.name} failed to import: {type(exc).__name__}: {exc}") from None
    function = getattr(module, name, None)
    if not callable(function):
        raise fields.error(key, f"{file_text} has no function {name!r}")
    return function


def _hitbox(fields: Fields, doc) -> Hitbox:
    doc = fields.table(doc, "hitbox")
    shape = fields.choice(doc.get("shape"), "hitbox.shape", SHAPE_KEYS)
    fields.known(doc, "hitbox", SHAPE_KEYS[shape])
    fit = fields.choice(doc.get("fit", "tight"), "hitbox.fit", FITS)
    touching = fields.flag(doc.get("touching", False), "hitbox.touching")
    inset = doc.get("inset", 0)
    if shape == "circle" and isinstance(inset, list):
        raise fields.error("hitbox.inset", f"a circle's inset is one integer (pixels off the radius), got {inset}")
    # TOML integers only: an inset is a small count of pixels, never an address in $hex
    inset = fields.integers(inset, "hitbox.inset", 4, -MAX_INSET, MAX_INSET, strings=False)
    function, text, seconds = None, "", sandbox.DEFAULT_SECONDS
    if shape == "function":
        seconds = sandbox.time_limit(fields, doc, "hitbox")
        text = fields.required(doc, "function", "hitbox", "FILE.py:NAME, hit(a, b, dx, dy) -> a verdict per offset")
        function = _load_function(fields, text)
    return Hitbox(shape=shape, fit=fit, inset=inset, touching=touching, function=function, function_text=text,
                  time_limit=seconds)


def _string(fields: Fields, doc: dict, key: str, default: str | None = None) -> str | None:
    value = doc.get(key, default)
    return None if value is None else fields.string(value, key, most=MAX_TEXT)


def _spec_name(path: Path, fields: Fields, key: str, text: str | None) -> str | None:
    """A built-in routine's name as given; a spec path made relative to the method file; checked."""
    if text is None:
        return None
    from retro.analysis.study.methods.base import routine_spec
    from retro.routines.registry import is_spec_path

    name = str((path.parent / text).resolve()) if is_spec_path(text) else text
    try:
        routine_spec(name)
    except InputError as exc:
        raise fields.error(key, str(exc)) from None
    return name


def _inputs(fields: Fields, doc, routine) -> tuple[tuple, tuple]:
    from retro.routines.where import parse_where

    # each input is an expression such as "a_x" or "b_x & 255"
    doc = fields.table(doc, "inputs", routine.input_names)
    compiled, bits = [], []
    for port in routine.inputs:
        text = fields.required(doc, port.name, "inputs", f"routine {routine.name} needs it (names: dx, dy, a_x, "
                                                        "b_right1, a_mask, ... see docs/methods.md)")
        if isinstance(text, int) and not isinstance(text, bool):
            text = str(text)
        if not isinstance(text, str):
            raise fields.error(f"inputs.{port.name}", f"expected an expression as a string, got {text!r}")
        terms = parse_where(text, NAMES, f"{fields.source}: inputs.{port.name}", MASKS)
        if len(terms) != 1:
            raise fields.error(f"inputs.{port.name}", "one value, not a condition joined by `and`")
        compiled.append((port.name, text, terms[0].test))
        bits.append(-len(port.places) if port.table else port.bits)
    return tuple(compiled), tuple(bits)


def load_method_file(path_text: str, index: int = 0) -> UserMethod:
    """Read and check a method file; `index` picks a default colour and marker."""
    path = Path(path_text)
    shown = str(path_text)
    raw = read_bytes(path, "method file", limit=MAX_METHOD_BYTES)
    doc = parse_toml(raw, shown)
    fields = Fields(shown)
    fields.table(doc, "", TOP_KEYS)
    name = _string(fields, doc, "name", path.stem)
    if not NAME.match(name):
        raise fields.error("name", f"{name!r}: a letter, then letters, digits, _ or - (at most 32)")
    label = _string(fields, doc, "label", name)
    hitbox = _hitbox(fields, fields.required(doc, "hitbox", "", "[hitbox] shape = \"box\" (or circle, mask, function)"))
    routine_name = _spec_name(path, fields, "routine", _string(fields, doc, "routine"))
    prepare = _spec_name(path, fields, "prepare", _string(fields, doc, "prepare"))
    from retro.analysis.study.methods.base import OBJECT, PREPARE_SCOPES

    prepare_per = fields.choice(_string(fields, doc, "prepare_per", OBJECT), "prepare_per", PREPARE_SCOPES)
    if "prepare_per" in doc and prepare is None:
        raise fields.error("prepare_per", "needs a prepare routine (prepare = \"aabb_edges_prepare\" or a spec file)")
    inputs, bits, domain, hit = (), (), (), 0
    if routine_name is None:
        for key in ("inputs", "hit", "prepare"):
            if key in doc:
                raise fields.error(key, "needs a routine (routine = \"aabb8\" or a spec file)")
    else:
        from retro.analysis.study.methods.base import routine_spec

        routine = routine_spec(routine_name)
        inputs, bits = _inputs(fields, fields.required(doc, "inputs", "", (
            f"the routine's inputs {', '.join(routine.input_names)} as expressions over the case (docs/methods.md)")),
            routine)
        domain = routine.domain
        hit_name = fields.choice(_string(fields, doc, "hit", routine.output_names[0]), "hit", routine.output_names)
        hit = routine.output_names.index(hit_name)
    colour = _string(fields, doc, "colour", DEFAULT_COLOURS[index % len(DEFAULT_COLOURS)])
    marker = _string(fields, doc, "marker", DEFAULT_MARKERS[index % len(DEFAULT_MARKERS)])
    from matplotlib.colors import is_color_like
    from matplotlib.lines import Line2D

    if not is_color_like(colour):
        raise fields.error("colour", f"{colour!r} is not a colour (e.g. \"#e377c2\" or \"purple\")")
    if marker not in Line2D.markers:
        raise fields.error("marker", f"{marker!r} is not a matplotlib marker (e.g. \"v\", \"p\", \"h\")")
    rule = _describe(hitbox)
    counted = (f"{Path(routine_name).name if routine_name else ''} called through its spec with the inputs of "
               f"{path.name}" if routine_name else "host only: no routine given")
    return UserMethod(key=name, label=label, rule=rule, colour=colour, marker=marker, routine=routine_name,
                      prepare=prepare, prepare_per=prepare_per, hit_output=hit, counted=counted, origin=shown,
                      path=shown, hitbox=hitbox, inputs=inputs, input_bits=bits, domain=domain)


def _describe(h: Hitbox) -> str:
    touching = "touching counts as a hit" if h.touching else "touching is no hit"
    if h.shape == "box":
        inset = "" if not any(h.inset) else f", inset {list(h.inset)} (left, top, right, bottom)"
        return f"the {h.fit} boxes{inset} overlap ({touching})"
    if h.shape == "circle":
        inset = "" if not h.inset[0] else f", radius {-h.inset[0]:+d}"
        return f"the fitted circles{inset}: squared centre distance against (r1+r2)^2 ({touching})"
    if h.shape == "mask":
        return "the opacity masks share a pixel (exact)"
    return f"the function {h.function_text} (hit(a, b, dx, dy))"


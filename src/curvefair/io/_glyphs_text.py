"""Faired nodes written into the text of a Glyphs source, every other byte kept.

glyphsLib does not write every source back as it read it (format 3 files lose ``fontType``,
``kernTop``, background ``imagePath`` entries, an instance's ``visible``; format 2 files lose
custom parameters such as ``Axes`` and round ``329.123456789`` to 5 decimals). So the faired
coordinates are patched into the source's own OpenStep-plist text instead:
:func:`patch_nodes` finds, with a small tokenizer that records where every value starts and
ends (quoted strings with backslash escapes, ``//`` and ``/* */`` comments, ``<data>``), the
``nodes`` list of each changed path -- glyph (``glyphname``) -> ``layers`` (``layerId``) ->
``shapes`` (format 3, components, i.e. shapes with a ``ref``, skipped) or ``paths``
(format 2) -> the path's index among the paths -- and rewrites only the coordinate numbers
that changed: ``(354,0,l)`` / ``(1,2,cs,{...})`` in format 3, the two leading numbers of
``"354 0 LINE SMOOTH"`` in format 2. Node types, ``smooth`` flags, userData, unchanged
numbers (``146.0`` stays ``146.0``) and everything else come back byte for byte.

New numbers are integers when integral, else the shortest decimals that read back as
exactly the float curvefair computed and checked (not glyphsLib's 5 decimals, whose rounding
could move a node past ``tol``); glyphsLib reads them back as those floats.

Every step is checked, and anything that does not check raises :class:`NotPatchable` (the
caller then falls back to glyphsLib's save): the tokenizer's tree must have the shape of
``openstep_plist``'s parse of the same text (same keys, same lengths along the way), the glyph
and the layer must be found exactly once, each located path must hold the nodes glyphsLib
read for it (same count, same coordinates), and ``openstep_plist``'s parse of the patched
text must equal that of the source with only those coordinates replaced.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from typing import Any

__all__ = ["NotPatchable", "format_number", "patch_nodes", "parse_spans"]


class NotPatchable(Exception):
    """The source's text could not be patched safely (the reason is the message)."""


# ------------------------------------------------------------------------------------------
# a tokenizer of OpenStep property lists that keeps positions
# ------------------------------------------------------------------------------------------
_SKIP = re.compile(r"(?:\s+|//[^\n]*(?:\n|\Z)|/\*.*?\*/)*", re.DOTALL)
_QUOTED = {'"': re.compile(r'"(?:[^"\\]|\\.)*"', re.DOTALL),
           "'": re.compile(r"'(?:[^'\\]|\\.)*'", re.DOTALL)}
_UNQUOTED = re.compile(r"[A-Za-z0-9_$+/:.\-]+")
_DATA = re.compile(r"<[0-9A-Fa-f\s]*>")

# span nodes: ("dict", start, end, [(key, value node)]), ("array", start, end, [nodes]),
# ("scalar", start, end); key is the key's text, unquoted when it has no escape (else None)


class _Parser:
    def __init__(self, text: str) -> None:
        self.s = text
        self.i = 0

    def fail(self, what: str) -> NotPatchable:
        line = self.s.count("\n", 0, self.i) + 1
        return NotPatchable(f"unexpected text at line {line} ({what})")

    def skip(self) -> None:
        m = _SKIP.match(self.s, self.i)
        self.i = m.end() if m else self.i
        if self.s.startswith("/*", self.i):
            raise self.fail("unterminated comment")

    def scalar(self) -> tuple[Any, ...]:
        c = self.s[self.i:self.i + 1]
        m = (_QUOTED[c].match(self.s, self.i) if c in _QUOTED
             else _DATA.match(self.s, self.i) if c == "<"
             else _UNQUOTED.match(self.s, self.i))
        if m is None or m.end() == self.i:
            raise self.fail("a value expected")
        self.i = m.end()
        return ("scalar", m.start(), m.end())

    def value(self) -> tuple[Any, ...]:
        self.skip()
        c = self.s[self.i:self.i + 1]
        start = self.i
        if c == "{":
            self.i += 1
            items: list[tuple[str | None, tuple[Any, ...]]] = []
            while True:
                self.skip()
                if self.s.startswith("}", self.i):
                    self.i += 1
                    return ("dict", start, self.i, items)
                k = self.scalar()
                key = self.s[k[1]:k[2]]
                if key[:1] in _QUOTED:
                    key = key[1:-1] if "\\" not in key else None  # type: ignore[assignment]
                self.skip()
                if not self.s.startswith("=", self.i):
                    raise self.fail("'=' expected")
                self.i += 1
                v = self.value()
                self.skip()
                if not self.s.startswith(";", self.i):
                    raise self.fail("';' expected")
                self.i += 1
                items.append((key, v))
        if c == "(":
            self.i += 1
            elems: list[tuple[Any, ...]] = []
            while True:
                self.skip()
                if self.s.startswith(")", self.i):
                    self.i += 1
                    return ("array", start, self.i, elems)
                elems.append(self.value())
                self.skip()
                if self.s.startswith(",", self.i):
                    self.i += 1
                elif not self.s.startswith(")", self.i):
                    raise self.fail("',' or ')' expected")
        return self.scalar()


def parse_spans(text: str) -> tuple[Any, ...]:
    """The span tree of an OpenStep property list (the whole text must be one value)."""
    p = _Parser(text)
    root = p.value()
    p.skip()
    if p.i != len(text):
        raise p.fail("text after the top-level value")
    return root


def _get(span: tuple[Any, ...], data: Any, key: str) -> tuple[tuple[Any, ...], Any]:
    """The value of ``key`` in a dict, as span and as openstep_plist's value."""
    if span[0] != "dict" or not isinstance(data, dict):
        raise NotPatchable(f"a dictionary expected for {key!r}")
    found = [v for k, v in span[3] if k == key]
    if len(found) != 1 or key not in data or any(k is None for k, _ in span[3]):
        raise NotPatchable(f"key {key!r} not found once")
    return found[0], data[key]


def _array(span: tuple[Any, ...], data: Any, what: str) -> list[tuple[Any, ...]]:
    if span[0] != "array" or not isinstance(data, list) or len(span[3]) != len(data):
        raise NotPatchable(f"{what}: the list is not read as openstep_plist reads it")
    return list(span[3])


# ------------------------------------------------------------------------------------------
# numbers
# ------------------------------------------------------------------------------------------
def format_number(v: float) -> str:
    """A coordinate as written into the text: an integer when integral, else the shortest
    positional decimal that reads back as exactly this float (never an exponent, never
    ``-0``). Not glyphsLib's 5 decimals (``floatToString5``): its rounding moves a node that
    the write-back rules put exactly ``tol`` from its input past ``tol`` (IntegerFloat.glyphs
    at tol 1: 1.0000056)."""
    import numpy as np

    v = float(v)
    if v.is_integer():
        return str(int(v)) if v != 0 else "0"
    s = np.format_float_positional(v, unique=True, trim="-")
    if float(s) != v:  # pragma: no cover - numpy's shortest repr reads back exactly
        raise NotPatchable(f"{v!r} has no exact decimal form here")
    return s


def _plist_number(s: str) -> int | float:
    """What openstep_plist (use_numbers) makes of a number written by format_number."""
    return int(s) if re.fullmatch(r"-?\d+", s) else float(s)


_V2_NODE = re.compile(r"([-.e\d]+) ([-.e\d]+) ")  # glyphsLib's GSNode.read pattern, start


def _is_number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


# ------------------------------------------------------------------------------------------
# the patch
# ------------------------------------------------------------------------------------------
def patch_nodes(text: str, fmt: int,
                targets: Sequence[tuple[str, str, int, Sequence[tuple[float, float]],
                                        Sequence[tuple[float, float]]]]) -> str:
    """``text`` with the given paths' node coordinates replaced.

    ``targets``: ``(glyph name, layerId, path index among the layer's paths, the nodes'
    coordinates as glyphsLib read them, the new coordinates)``. ``fmt``: the source's format
    version (3, else 2). Raises :class:`NotPatchable` when anything cannot be located or
    checked (module docstring)."""
    import openstep_plist

    try:
        data = openstep_plist.loads(text, use_numbers=True)
    except Exception as exc:
        raise NotPatchable(f"openstep_plist does not read the text ({exc})") from None
    root = parse_spans(text)
    gspan, gdata = _get(root, data, "glyphs")
    glyphs = _array(gspan, gdata, "glyphs")
    edits: list[tuple[int, int, str]] = []
    done: set[tuple[str, str, int]] = set()
    for gname, layer_id, ci, old, new in targets:
        if (gname, layer_id, ci) in done or len(old) != len(new):
            raise NotPatchable(f"glyph {gname!r}: path {ci} given twice or with other counts")
        done.add((gname, layer_id, ci))
        gi = [i for i, g in enumerate(gdata)
              if isinstance(g, dict) and str(g.get("glyphname")) == gname]
        if len(gi) != 1:
            raise NotPatchable(f"glyph {gname!r} found {len(gi)} times")
        lspan, ldata = _get(glyphs[gi[0]], gdata[gi[0]], "layers")
        layers = _array(lspan, ldata, f"glyph {gname!r} layers")
        li = [i for i, la in enumerate(ldata)
              if isinstance(la, dict) and str(la.get("layerId")) == layer_id]
        if len(li) != 1:
            raise NotPatchable(f"glyph {gname!r}: layer {layer_id!r} found {len(li)} times")
        lay_span, lay_data = layers[li[0]], ldata[li[0]]
        if fmt >= 3:
            sspan, sdata = _get(lay_span, lay_data, "shapes")
            shapes = _array(sspan, sdata, f"glyph {gname!r} shapes")
            idx = [i for i, sh in enumerate(sdata) if isinstance(sh, dict) and "ref" not in sh]
        else:
            sspan, sdata = _get(lay_span, lay_data, "paths")
            shapes = _array(sspan, sdata, f"glyph {gname!r} paths")
            idx = list(range(len(sdata)))
        if ci >= len(idx):
            raise NotPatchable(f"glyph {gname!r}: no path {ci}")
        nspan, ndata = _get(shapes[idx[ci]], sdata[idx[ci]], "nodes")
        nodes = _array(nspan, ndata, f"glyph {gname!r} path {ci} nodes")
        if len(nodes) != len(old):
            raise NotPatchable(f"glyph {gname!r} path {ci}: {len(nodes)} nodes in the text, "
                               f"{len(old)} read by glyphsLib")
        for k, (sp, dv, (x0, y0), (x1, y1)) in enumerate(zip(nodes, ndata, old, new,
                                                             strict=True)):
            where = f"glyph {gname!r} path {ci} node {k}"
            sx, sy = format_number(x1), format_number(y1)
            if fmt >= 3:
                if (sp[0] != "array" or not isinstance(dv, list) or len(dv) < 3
                        or len(sp[3]) != len(dv) or not (_is_number(dv[0])
                                                         and _is_number(dv[1]))
                        or sp[3][0][0] != "scalar" or sp[3][1][0] != "scalar"):
                    raise NotPatchable(f"{where}: not a (x,y,type) node")
                if dv[0] != x0 or dv[1] != y0:
                    raise NotPatchable(f"{where}: not the node glyphsLib read")
                for j, (val, s) in enumerate(((x1, sx), (y1, sy))):
                    if float(dv[j]) != float(val):  # an unmoved number keeps its text
                        edits.append((sp[3][j][1], sp[3][j][2], s))
                        dv[j] = _plist_number(s)
            else:
                if sp[0] != "scalar" or not isinstance(dv, str) or text[sp[1]] != '"':
                    raise NotPatchable(f"{where}: not a quoted node string")
                raw = _V2_NODE.match(text, sp[1] + 1)
                got = _V2_NODE.match(dv)
                if raw is None or got is None or raw.group(0) != got.group(0):
                    raise NotPatchable(f"{where}: not an 'X Y TYPE' node")
                if float(got.group(1)) != x0 or float(got.group(2)) != y0:
                    raise NotPatchable(f"{where}: not the node glyphsLib read")
                parts = [got.group(1), got.group(2)]
                for j, (val, s) in enumerate(((x1, sx), (y1, sy))):
                    if float(parts[j]) != float(val):
                        edits.append((raw.start(j + 1), raw.end(j + 1), s))
                        parts[j] = s
                ndata[k] = f"{parts[0]} {parts[1]} " + dv[got.end():]
    if not edits:
        return text
    out, pos = [], 0
    for a, b, s in sorted(edits):
        if a < pos:
            raise NotPatchable("overlapping edits")
        out.append(text[pos:a])
        out.append(s)
        pos = b
    out.append(text[pos:])
    patched = "".join(out)
    try:
        back = openstep_plist.loads(patched, use_numbers=True)
    except Exception as exc:
        raise NotPatchable(f"the patched text does not read ({exc})") from None
    if back != data:
        raise NotPatchable("the patched text reads back with other changes than the nodes")
    return patched

"""The ``curvefair`` command: a thin layer over the public API.

Every command calls the same functions a Python user would: :func:`curvefair.read_curves`,
:func:`curvefair.fair`, :func:`curvefair.write_curves`, :func:`curvefair.analyze`,
:func:`curvefair.plot.figure` and the method registry :data:`curvefair.fairing.METHODS`.

Exit codes: 0 success; 1 bad input (the message names the file and, for text formats, the line)
or a curve that could not be faired; 2 usage error (unknown option, missing argument, output
equal to input without ``--in-place``, nonexistent input file).
"""

from __future__ import annotations

import contextlib
import inspect
import json
import math
import os
import sys
import time
import warnings
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any, cast

try:
    import click
except ImportError:  # pragma: no cover - exercised only without the extra
    sys.stderr.write("the curvefair command needs click and rich: pip install 'curvefair[cli]'\n")
    raise SystemExit(1) from None

from . import __version__
from ._fileid import file_key
from .errors import CurvefairError

__all__ = ["main"]

EXIT_OK = 0
EXIT_INPUT = 1
EXIT_USAGE = 2

_EXAMPLES = """\b
Examples:
  curvefair fair profile.csv -o profile_faired.csv --tol 0.05 --plot before_after.png
  curvefair fair part.dxf -o part_faired.dxf --method knot-removal --tol 0.01 --report r.json
  curvefair fair foil.dat --in-place --tol 1e-4 --clamp g2
  curvefair fair part.dxf -o part_faired.dxf -m eck-hadenfeld -O schedule=sweep -O l=3
  curvefair analyze profile.csv
  curvefair analyze part.dxf --json > analysis.json
  curvefair plot profile.csv --compare profile_faired.csv -o compare.svg
  curvefair view profile.csv --compare profile_faired.csv -o compare.html
  curvefair methods
"""


# ------------------------------------------------------------------------------------------
# errors and output helpers
# ------------------------------------------------------------------------------------------
class InputFailure(click.ClickException):
    """Bad input: exit code 1, ``Error: <message>`` on stderr, no traceback."""

    exit_code = EXIT_INPUT


@contextlib.contextmanager
def _user_errors() -> Iterator[None]:
    """Turn curvefair's errors and OS errors into exit code 1 with a one-line message."""
    try:
        yield
    except CurvefairError as exc:
        raise InputFailure(str(exc)) from None
    except OSError as exc:
        where = f"{exc.filename}: " if getattr(exc, "filename", None) else ""
        raise InputFailure(f"{where}{exc.strerror or exc}") from None


_file_key = file_key


def _check_outputs(inputs: Sequence[tuple[str, str]], outputs: Sequence[tuple[str | None, str]],
                   in_place: bool = False) -> None:
    """Refuse an output that is empty, a folder, an input (unless ``in_place`` for the first
    output and the first input) or another output; usage errors naming the options."""
    seen: list[tuple[tuple[Any, ...], str, str]] = []
    keys_in = [(_file_key(p), p, what) for p, what in inputs]
    for k, (p, opt) in enumerate(outputs):
        if p is None:
            continue
        if not p.strip():
            raise click.BadParameter("the file name is empty", param_hint=opt)
        if os.path.isdir(p) and not (opt == "-o/--output" and p.lower().rstrip("/\\")
                                     .endswith(".ufo")):  # a UFO font is a folder
            raise click.BadParameter(f"{p!r} is a folder; give a file name"
                                     + (f" (or {p.rstrip('/')}/ to write into the folder)"
                                        if opt == "-o/--output" else ""), param_hint=opt)
        key = _file_key(p)
        for kin, pin, what in keys_in:
            if key == kin and not (in_place and k == 0 and what == "IN"):
                extra = "; pass --in-place to replace it" if k == 0 and what == "IN" else ""
                raise click.UsageError(f"{opt} {p!r} is the input file {what} ({pin!r}){extra}")
        for kout, pout, optout in seen:
            if key == kout:
                raise click.UsageError(f"{opt} {p!r} is the same file as {optout} {pout!r}")
        seen.append((key, p, opt))


def _format_of(path: str, what: str = "") -> str:
    """The format of ``path`` from its extension (the CLI has no format option)."""
    from .io import FORMATS, detect_format

    try:
        return detect_format(path)
    except CurvefairError:
        known = ", ".join(e for exts in FORMATS.values() for e in exts)
        raise InputFailure(f"{what + ' ' if what else ''}{path!r}: cannot tell the format from "
                           "the extension "
                           f"{Path(path).suffix!r}; known: {known}") from None


def _console(stderr: bool = False, quiet: bool = False) -> Any:
    from rich.console import Console

    stream = sys.stderr if stderr else sys.stdout
    width = None if stream.isatty() else 200  # no wrapping when piped
    return Console(file=stream, width=width, quiet=quiet, highlight=False,
                   soft_wrap=not stream.isatty())


def _fmt(v: Any, digits: int = 4) -> str:
    if v is None:
        return "-"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, int):
        return str(v)
    try:
        x = float(v)
    except (TypeError, ValueError):
        return str(v)
    return f"{x:.{digits}g}"


def _arrow(a: Any, b: Any, digits: int = 4) -> str:
    return f"{_fmt(a, digits)} → {_fmt(b, digits)}"


def _write_json(path: str, obj: Any) -> None:
    from .io import atomic_write

    # a fair() report keeps its per-point arrays (FairingReport); they become lists only here
    atomic_write(path, json.dumps(obj, indent=2, allow_nan=False, default=_json_array) + "\n")


def _json_array(obj: Any) -> Any:
    import numpy as np

    from .fairing.fair import jsonable

    if isinstance(obj, np.ndarray):
        return jsonable(obj)
    raise TypeError(f"Object of type {type(obj).__name__} is not JSON serializable")


def _save_figure(fig: Any, path: str) -> None:
    from .io import atomic_path

    fmt = Path(path).suffix.lower().lstrip(".")
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=fmt, dpi=150)


_FIG_FORMATS = ("png", "svg", "pdf")


def _check_figure_path(path: str, option: str) -> None:
    ext = Path(path).suffix.lower().lstrip(".")
    if ext not in _FIG_FORMATS:
        raise click.BadParameter(
            f"{path!r}: the figure format comes from the extension, one of "
            + ", ".join("." + e for e in _FIG_FORMATS), param_hint=option)


def _parse_protect(value: str | None) -> list[int]:
    if not value:
        return []
    out = []
    for tok in value.replace(" ", "").split(","):
        if not tok:
            continue
        try:
            i = int(tok)
        except ValueError:
            raise click.BadParameter(f"{tok!r} is not an integer point index",
                                     param_hint="--protect") from None
        if i < 0:
            raise click.BadParameter(f"{i} is negative; point indices start at 0",
                                     param_hint="--protect")
        out.append(i)
    return out


def _parse_value(text: str) -> Any:
    """``-O`` values: an int literal, else a float, else true/false, else the string itself."""
    try:
        return int(text)
    except ValueError:
        pass
    try:
        return float(text)
    except ValueError:
        pass
    low = text.strip().lower()
    if low in ("true", "false"):
        return low == "true"
    return text


#: fair()'s own arguments the command sets, and how (the others keep fair()'s defaults)
_FAIR_FLAGS = {"curve": "the IN argument", "method": "-m/--method", "tol": "--tol",
               "eps": "--eps", "max_steps": "--max-steps", "clamp": "--clamp",
               "protect": "--protect", "mode": "--mode"}
#: fair()'s own arguments ``-O`` passes on (they reach fair() with the method's options)
_FAIR_VIA_OPTION = ("corner_turn", "g1_angle")


def _parse_method_options(items: Sequence[str]) -> dict[str, Any]:
    """``("schedule=sweep", "l=3")`` -> ``{"schedule": "sweep", "l": 3}`` (the last wins)."""
    out: dict[str, Any] = {}
    for item in items:
        key, sep, value = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise click.BadParameter(f"{item!r} is not KEY=VALUE (e.g. -O schedule=sweep)",
                                     param_hint="'-O' / '--option'")
        if key in _fair_arguments() and key not in _FAIR_VIA_OPTION:
            flag = _FAIR_FLAGS.get(key)
            raise click.BadParameter(
                f"{key!r} is not a method option; " + (f"use {flag}" if flag else
                                                      "the command keeps fair()'s default"),
                param_hint="'-O' / '--option'")
        out[key] = _parse_value(value)
    return out


def _option_kind(default: Any, annotation: Any) -> str | None:
    """``"bool"``, ``"int"``, ``"float"`` or None (anything) for a method option."""
    ann = str(annotation).replace(" ", "").replace("typing.", "")
    ann = ann.replace("Optional[", "").rstrip("]").replace("|None", "")
    if isinstance(default, bool) or ann in ("bool", "<class'bool'>"):
        return "bool"
    if isinstance(default, int) or ann in ("int", "<class'int'>"):
        return "int"
    if isinstance(default, float) or ann in ("float", "<class'float'>"):
        return "float"
    return None


def _check_option_values(method: str | None, options: dict[str, Any]) -> None:
    """Usage error for a ``-O`` value of the wrong type (``pair=3``, ``relative=maybe``).

    The type comes from the method driver's default and annotation; with no ``--method``
    every method that has the option is checked (the default method depends on the curve).
    """
    from .fairing import METHODS

    names = [method] if method is not None and method in METHODS else list(METHODS)
    for key, val in options.items():
        for name in names:
            try:
                spec = METHODS[name]
                fn = spec.solver if spec.solver is not None else spec.driver
                par = inspect.signature(fn).parameters.get(key)
            except (TypeError, ValueError):
                continue
            if par is None or par.kind is par.VAR_KEYWORD:
                continue
            kind = _option_kind(par.default, par.annotation)
            ok = (kind is None or (kind == "bool" and isinstance(val, bool))
                  or (kind == "int" and isinstance(val, int) and not isinstance(val, bool))
                  or (kind == "float" and isinstance(val, (int, float))
                      and not isinstance(val, bool) and math.isfinite(val)))
            if not ok:
                want = {"bool": "true or false", "int": "an integer",
                        "float": "a finite number"}[kind]  # type: ignore[index]
                shown = ("true" if val else "false") if isinstance(val, bool) else val
                raise click.BadParameter(f"{key}={shown}: method {name!r} takes {want} for "
                                         f"{key!r}", param_hint="'-O' / '--option'")


def _check_protect_range(records: Sequence[Any], user: Sequence[int]) -> None:
    """Usage error for a ``--protect`` index beyond every curve of the file (the API would
    refuse it; a point list split at corners would silently drop it)."""
    if not user:
        return
    counts = []
    for rec in records:
        if "indices" in rec.source:
            counts.append(int(rec.source["n_points"]))
        else:
            pts = getattr(rec.curve, "control_points", None)
            if pts is None:
                pts = getattr(rec.curve, "points", None)
            if pts is not None:
                counts.append(int(pts.shape[0]))
    if not counts:
        return
    n = max(counts)
    bad = [i for i in user if i >= n]
    if bad:
        what = ("points" if any("indices" in r.source for r in records)
                else "points / control points")
        raise click.BadParameter(f"index {bad[0]} is out of range: the curves of IN have at most "
                                 f"{n} {what} (indices 0..{n - 1})", param_hint="--protect")


#: Most curvature-comb hairs a plot draws (memory: a few hundred bytes each).
_MAX_HAIRS = 2_000_000
#: Longest hair allowed, in multiples of the drawing's size.
_MAX_HAIR_RATIO = 1000.0


def _check_comb(curves: Sequence[Any], scale: float | None, density: int | None,
                no_comb: bool) -> None:
    """Usage errors for a comb that cannot be drawn: too many hairs (``--comb-density``) or
    hairs overflowing the drawing (``--comb-scale``, longest hair = S * max curvature)."""
    import numpy as np

    if density is not None:
        segs = sum(int(c.piecewise.n_segments) for c in curves)
        if density * segs > _MAX_HAIRS:
            raise click.BadParameter(
                f"{density} hairs per segment on {segs} segments is {density * segs:,} hairs; "
                f"at most {_MAX_HAIRS:,}", param_hint="--comb-density")
    if scale is None or no_comb:
        return
    kmax, lo, hi = 0.0, None, None
    for c in curves:
        pp = c.piecewise
        f = np.linspace(0.0, 1.0, 9)
        br = np.asarray(pp.breaks, dtype=float)
        u = (br[:-1, None] + np.diff(br)[:, None] * f[None, :]).reshape(-1)
        d1, d2, r = pp.evaluate(u, 1), pp.evaluate(u, 2), pp.evaluate(u)
        if d1.shape[1] == 2:
            cross = np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])
        else:
            cross = np.linalg.norm(np.cross(d1, d2), axis=1)
        speed = np.linalg.norm(d1, axis=1)
        with np.errstate(all="ignore"):
            k = np.where(speed > 0, cross / speed**3, 0.0)
        k = k[np.isfinite(k)]
        kmax = max(kmax, float(k.max()) if k.size else 0.0)
        lo = r.min(axis=0) if lo is None else np.minimum(lo, r.min(axis=0))
        hi = r.max(axis=0) if hi is None else np.maximum(hi, r.max(axis=0))
    size = float(np.linalg.norm(hi - lo)) if lo is not None else 0.0
    longest = scale * kmax
    if not math.isfinite(longest) or longest > _MAX_HAIR_RATIO * max(size, 1e-300):
        raise click.BadParameter(
            f"{scale:g} makes the longest hair {longest:.3g} long (max curvature {kmax:.3g}), "
            f"more than {_MAX_HAIR_RATIO:g} times the size of the drawing ({size:.3g})",
            param_hint="--comb-scale")


def _fair_arguments() -> set[str]:
    """The named parameters of :func:`curvefair.fair` (they have their own flags)."""
    from . import fair

    return {p.name for p in inspect.signature(fair).parameters.values()
            if p.kind is not p.VAR_KEYWORD}


def _warn(message: str, quiet: bool) -> None:
    """One warning on stderr (``Warning: ...``), unless ``--quiet``."""
    if not quiet:
        click.echo(f"Warning: {message}", err=True)


@contextlib.contextmanager
def _warnings_to_stderr(quiet: bool, prefix: str = "",
                        into: list[str] | None = None) -> Iterator[None]:
    """Show the library's warnings raised inside the block as ``Warning:`` lines on stderr
    (and collect them in ``into``), instead of Python's warning format."""
    import warnings

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            yield
        finally:
            from .io import ReadNote

            seen: set[str] = set()
            for w in caught:
                msg = prefix + str(w.message)
                if msg in seen:
                    continue
                seen.add(msg)
                if into is not None:
                    into.append(str(w.message))
                if isinstance(w.message, ReadNote):  # a note, not a warning
                    if not quiet:
                        click.echo(f"Note: {msg}", err=True)
                    continue
                _warn(msg, quiet)


class _AllSkipped(Exception):
    """Every curve entity of the file was skipped as unsupported (``n`` of them), or is a
    straight-line shape left as drawn (``drawn`` of them: a drawing's polygons, or a font's
    straight contours when ``font``)."""

    def __init__(self, n: int, message: str, drawn: int = 0, font: bool = False) -> None:
        super().__init__(message)
        self.n = n
        self.drawn = drawn
        self.font = font


def _read(path: str, corner_angle: float | None, strict: bool = False,
          quiet: bool = False, glyphs: str | None = None,
          all_skipped_ok: bool = False, fmt: str | None = None,
          polylines: bool = False, columns: tuple[int, ...] | None = None) -> list[Any]:
    """The records of a file; entities curvefair cannot represent are skipped with a warning
    (kept untouched on write-back) unless ``strict``, which refuses the file. With
    ``all_skipped_ok``, a file whose every curve entity was skipped raises
    :class:`_AllSkipped` (the caller writes it back unchanged) instead of failing.
    ``polylines`` (``--polylines``) reads a drawing's straight-line shapes (SVG, DXF, 3dm) as
    point lists; it means nothing for other formats (point data are point lists always).
    ``columns`` (``--columns``): a points file's coordinate columns."""
    from . import read_curves
    from .io import columns_for, polylines_for

    kind = fmt if fmt is not None else _format_of(path)  # a CLI message (not format=)
    extra: dict[str, Any] = {} if glyphs is None else {"glyphs": glyphs}
    if columns is not None and kind != "points":
        raise click.BadParameter(f"{path!r} is a {kind} file; --columns is for point lists "
                                 "(points files)", param_hint="--columns")
    cols = columns_for(kind, columns)
    if cols is not None:
        extra["columns"] = cols
    seen: list[str] = []
    try:
        with _warnings_to_stderr(quiet, into=seen):
            return read_curves(path, corner_angle=corner_angle, format=cast(Any, fmt),
                               on_unsupported="raise" if strict else "skip",
                               polylines=polylines_for(kind, polylines), **extra)
    except CurvefairError as exc:
        skipped = sum(": skipped " in w for w in seen)
        drawn = int(getattr(exc, "n_drawn", 0))
        if (skipped or drawn) and all_skipped_ok and "no curves in the" in str(exc):
            raise _AllSkipped(skipped, str(exc), drawn,
                              not getattr(exc, "polylines_option", True)) from None
        if skipped:
            raise InputFailure(f"{exc} ({skipped} unsupported entit"
                               f"{'y' if skipped == 1 else 'ies'} skipped"
                               + (")" if quiet else ", see the warnings)")
                               ) from None
        if strict and "on_unsupported='skip'" in str(exc):
            raise InputFailure(f"{exc}; without --strict the curvefair command skips it with "
                               "a warning") from None
        raise


def _write_unchanged(infile: str, out: str, report: str | None, n_skipped: int,
                     quiet: bool, n_drawn: int = 0, font: bool = False) -> None:
    """A file holding only entities curvefair cannot fair (each skipped with a warning, kept
    untouched on write-back), straight-line shapes of a drawing left as drawn, or a font's
    straight contours (``font``): nothing to fair; OUT is the input's bytes (a UFO folder
    copied), exit 0."""
    from .io import atomic_path, copy_input

    with _user_errors():
        if not (os.path.exists(out) and os.path.samefile(infile, out)):   # not --in-place
            with atomic_path(out) as tmp:
                copy_input(infile, tmp)
        if report is not None:
            _write_json(report, {
                "curvefair": __version__, "input": os.path.abspath(infile),
                "output": os.path.abspath(out), "n_curves": 0, "n_failed": 0,
                "n_skipped_unsupported": n_skipped, "n_drawn_shapes": n_drawn,
                "output_written": True, "output_check": None, "curves": []})
    if not quiet:
        from .batch import _nothing_why

        click.echo(f"Note: {infile}: nothing to fair "
                   f"({_nothing_why(n_skipped, n_drawn, font)}); {out} written unchanged",
                   err=True)


def _nothing_to_fair(rec: Any) -> bool:
    """A point list of two points (a straight segment between corners, e.g. a rectangle's
    side): no interior point, nothing a fairing method could move."""
    pts = getattr(rec, "points", None)
    if pts is None:
        return False
    n = len(pts) - (1 if getattr(rec.curve, "closed", False) else 0)
    return n <= 2


def _record_label(rec: Any, i: int) -> str:
    return rec.name if rec.name else f"curve {i}"


# shared options ---------------------------------------------------------------------------
def _reading_options(f: Any) -> Any:
    f = click.option("--corner-angle", type=click.FloatRange(0, 180, min_open=True),
                     default=60.0, show_default=True, metavar="DEG",
                     help="Point lists turning by DEG degrees or more at a point are split "
                          "there into separate curves (the corner is kept fixed).")(f)
    f = click.option("--no-corners", is_flag=True,
                     help="Never split point lists at corners.")(f)
    f = click.option("--polylines", is_flag=True,
                     help="SVG, DXF, 3dm: read straight-line shapes (polygons, polylines, "
                          "lines, rectangles; DXF LWPOLYLINE and POLYLINE; 3dm "
                          "PolylineCurve) as point lists to fair [default: leave them as "
                          "drawn].")(f)
    f = click.option("--columns", callback=_columns_option, metavar="I,J[,K]",
                     help="Point files: the 0-based columns holding x, y (z), e.g. 1,2 for "
                          "'id x y' rows; the others are kept as they are [default: the "
                          "columns a header names x, y, z, else all of a 2- or 3-column "
                          "file].")(f)
    f = click.option("--strict", is_flag=True,
                     help="Refuse a file holding an entity curvefair cannot represent exactly "
                          "(rational or degree-1 splines, arcs, ...) [default: skip it with a "
                          "warning and write it back untouched].")(f)
    return f


def _columns_option(ctx: Any, param: Any, value: str | None) -> tuple[int, ...] | None:
    """``--columns 1,2`` as ``(1, 2)``: 2 or 3 different column indices, 0-based."""
    if value is None:
        return None
    try:
        cols = tuple(int(v) for v in value.split(","))
    except ValueError:
        raise click.BadParameter(f"{value!r}: give 2 or 3 column indices (0-based) separated "
                                 "by commas, e.g. 1,2") from None
    if len(cols) not in (2, 3) or len(set(cols)) != len(cols) or min(cols) < 0:
        raise click.BadParameter(f"{value!r}: give 2 or 3 different column indices (0-based, "
                                 ">= 0) separated by commas, e.g. 1,2")
    return cols


def _quiet_option(f: Any) -> Any:
    return click.option("-q", "--quiet", is_flag=True,
                        help="Print nothing but errors.")(f)


def _corner(corner_angle: float, no_corners: bool) -> float | None:
    return None if no_corners else corner_angle


# ------------------------------------------------------------------------------------------
# the group
# ------------------------------------------------------------------------------------------
@click.group(context_settings={"help_option_names": ["-h", "--help"], "max_content_width": 100},
             epilog=_EXAMPLES)
@click.version_option(__version__, "-V", "--version", prog_name="curvefair",
                      message="%(prog)s %(version)s")
def main() -> None:
    """Fair spline curves (remove curvature wiggles) by the published local methods, never
    moving anything farther than a tolerance you set.

    Files: point lists (.csv .txt .xyz .pts), airfoils (.dat), curvefair JSON (.json), and with
    the optional extras DXF, Rhino .3dm, SVG, IGES and STEP. Point indices are 0-based.
    """


# ------------------------------------------------------------------------------------------
# methods
# ------------------------------------------------------------------------------------------
def _option_default(v: Any) -> Any:
    """An option's default as JSON (None for "no default"; other objects as their repr)."""
    if v is inspect.Parameter.empty:
        return None
    if v is None or isinstance(v, (bool, int, str)):
        return v
    if isinstance(v, float):
        return v if math.isfinite(v) else repr(v)
    return repr(v)


def _option_text(name: str, v: Any) -> str:
    """``name=default`` as it would be typed after ``-O``."""
    if v is inspect.Parameter.empty:
        return f"{name} (required)"
    if isinstance(v, bool):
        return f"{name}={'true' if v else 'false'}"
    return f"{name}={v}"


def _method_rows(raw_defaults: bool = False) -> list[dict[str, Any]]:
    from .fairing import METHODS
    from .fairing.fair import method_options

    conv = (lambda v: v) if raw_defaults else _option_default
    return [{"name": s.name, "curve_types": [t.__name__ for t in s.curve_types],
             "default": bool(s.default), "modes": list(s.modes), "summary": s.summary,
             "source": s.source,
             "options": {k: conv(v) for k, v in method_options(s.name).items()},
             "default_options": _default_options_text(s),
             "default_reason": s.default_reason if s.default else ""}
            for s in METHODS.values()]


def _default_options_text(spec: Any) -> str:
    """The options a default method gets when chosen by default, as ``-O`` text."""
    d = spec.default_options
    if callable(d):
        doc = (getattr(d, "__doc__", "") or "").strip().splitlines()
        return doc[0] if doc else "chosen per curve"
    return " ".join(f"{k}={v}" for k, v in d.items())


def _default_methods_text() -> str:
    try:
        rows = _method_rows()
    except Exception:  # pragma: no cover - help must always render
        return "the registry's default for the curve type"
    # one entry per curve type; a type with several defaults (chosen by size or kind, e.g.
    # points-l1 for open point data, poliakoff otherwise) lists them once, joined by "or"
    per_type: dict[str, list[str]] = {}
    for r in rows:
        if not r["default"]:
            continue
        label = r["name"] + (f" ({r['default_options']})" if r["default_options"] else "")
        for t in r["curve_types"]:
            if label not in per_type.setdefault(t, []):
                per_type[t].append(label)
    pairs = [f"{t}: {' or '.join(labels)}" for t, labels in per_type.items()]
    if not pairs:
        return "the first method accepting the curve type"
    text = "; ".join(pairs)
    if any(len(labels) > 1 for labels in per_type.values()):
        text += " (which one, by size and kind: 'curvefair methods')"
    return text


@main.command("methods")
@click.option("--json", "as_json", is_flag=True, help="Machine-readable output.")
def methods_cmd(as_json: bool) -> None:
    """List the fairing methods: curve types, one line each, the source paper, and the
    method's options with their defaults (pass them to 'curvefair fair' as -O KEY=VALUE)."""
    if as_json:
        click.echo(json.dumps(_method_rows(), indent=2))
        return
    rows = _method_rows(raw_defaults=True)
    from rich.table import Table

    table = Table(show_lines=True, title="curvefair fairing methods (* = default for its type)")
    table.add_column("method", no_wrap=True, style="bold")
    table.add_column("curves")
    table.add_column("what it does")
    table.add_column("source")
    table.add_column("options (-O KEY=VALUE), defaults")
    for r in rows:
        opts = "\n".join(_option_text(k, v) for k, v in r["options"].items()) or "-"
        table.add_row(r["name"] + (" *" if r["default"] else ""), ", ".join(r["curve_types"]),
                      r["summary"], r["source"], opts)
    _console().print(table)
    for r in rows:
        if r["default"]:
            extra = f" ({r['default_options']})" if r["default_options"] else ""
            why = r["default_reason"] or "the registered default for its type"
            click.echo(f"default for {', '.join(r['curve_types'])}: {r['name']}{extra}: {why}")


# ------------------------------------------------------------------------------------------
# analyze
# ------------------------------------------------------------------------------------------
@main.command("analyze")
@click.argument("infile", metavar="IN", type=click.Path(exists=True, dir_okay=True))
@click.option("--json", "as_json", is_flag=True, help="Machine-readable output (JSON on stdout).")
@click.option("--top", type=click.IntRange(min=0), default=10, show_default=True,
              help="Bad points listed per curve in the table (--json lists all).")
@_reading_options
@_quiet_option
def analyze_cmd(infile: str, as_json: bool, top: int, corner_angle: float, no_corners: bool,
                polylines: bool, columns: tuple[int, ...] | None, strict: bool,
                quiet: bool) -> None:
    """Analyse every curve of IN: energies, inflections, curvature extrema, the worst jumps,
    and the ranked list of bad points (index, measure, kind)."""
    from . import analyze
    from .analysis import rank_bad_points

    with _user_errors():
        records = _read(infile, _corner(corner_angle, no_corners), strict, quiet,
                        polylines=polylines, columns=columns)
        out = []
        for i, rec in enumerate(records):
            a = analyze(rec.curve)
            out.append({"index": i, "name": rec.name, "kind": rec.kind,
                        "curve_type": type(rec.curve).__name__, "corners": list(rec.corners),
                        "analysis": a.to_dict(),
                        "bad_points": [b.to_dict() for b in rank_bad_points(rec.curve, a)]})
    if as_json:
        click.echo(json.dumps({"file": infile, "curves": out}, indent=2, allow_nan=False))
        return
    if quiet:
        return
    from rich.table import Table

    con = _console()
    for i, (rec, item) in enumerate(zip(records, out, strict=True)):
        a = item["analysis"]
        con.print(f"[bold]{_record_label(rec, i)}[/bold]: {item['curve_type']}, "
                  f"{a['dim']}-D, degree {a['degree']}, {a['n_segments']} segments"
                  + (", closed" if a["closed"] else "")
                  + (f"; corners kept fixed: {item['corners']}" if item["corners"] else ""))
        t = Table(show_header=False, box=None, padding=(0, 2))
        t.add_column(style="dim")
        t.add_column(justify="right")
        for label, key in (("strain energy ∫|r''|² dt", "energy2"),
                           ("jerk energy ∫|r'''|² dt", "energy3"),
                           ("arc length", "arc_length"), ("∫(dκ/ds)² ds", "dkds_energy"),
                           ("inflections", "inflections"), ("curvature extrema", "extrema"),
                           ("max |κ|", "max_curvature"), ("max |Δr'''|", "max_jump"),
                           ("at breakpoint", "max_jump_index"),
                           ("Sapidis Σ|Δκ_s|", "sapidis_sum")):
            t.add_row(label, _fmt(a[key], 6))
        con.print(t)
        bad = item["bad_points"]
        if not bad:
            con.print("  no bad points\n")
            continue
        bt = Table(title=f"bad points (worst first, {min(top, len(bad))} of {len(bad)})",
                   title_justify="left")
        for col in ("rank", "index", "t", "measure", "kind"):
            bt.add_column(col, justify="right" if col != "kind" else "left")
        for r, b in enumerate(bad[:top], start=1):
            bt.add_row(str(r), f"{b['index_of']} {b['index']}", _fmt(b["param"], 6),
                       f"{b['measure_name']} = {_fmt(b['measure'], 4)}", b["kind"])
        con.print(bt)
        con.print()


# ------------------------------------------------------------------------------------------
# plot
# ------------------------------------------------------------------------------------------
@main.command("plot")
@click.argument("infile", metavar="IN", type=click.Path(exists=True, dir_okay=True))
@click.option("--compare", "other", metavar="OTHER",
              type=click.Path(exists=True, dir_okay=False),
              help="A second file with as many curves (e.g. the faired one): drawn over IN, "
                   "with a deviation panel.")
@click.option("-o", "--output", "out", metavar="FIG", required=True,
              help="Figure file: .png, .svg or .pdf.")
@click.option("--comb-scale", type=click.FloatRange(0, min_open=True), metavar="S",
              help="Hair length per unit curvature [default: longest hair = 1/5 of the size].")
@click.option("--comb-density", type=click.IntRange(min=1), metavar="D",
              help="Hair intervals per curve segment [default: about 600 hairs].")
@click.option("--no-comb", is_flag=True, help="Leave out the curvature comb.")
@click.option("--no-markers", is_flag=True,
              help="Leave out inflection, extremum and bad-point markers.")
@click.option("--tol", type=click.FloatRange(0, min_open=True), metavar="T",
              help="Tolerance line on the deviation panel.")
@click.option("--projection", type=click.Choice(["plane", "xy", "xz", "yz"]), default="plane",
              show_default=True, help="3-D curves: best-fit plane or a coordinate plane.")
@click.option("--title", help="Figure title [default: the file name(s)].")
@_reading_options
@_quiet_option
def plot_cmd(infile: str, other: str | None, out: str, comb_scale: float | None,
             comb_density: int | None, no_comb: bool, no_markers: bool, tol: float | None,
             projection: str, title: str | None, corner_angle: float, no_corners: bool,
             polylines: bool, columns: tuple[int, ...] | None, strict: bool,
             quiet: bool) -> None:
    """Draw the curves of IN with their curvature combs and curvature plots into FIG."""
    _check_outputs([(infile, "IN")] + ([(other, "--compare")] if other else []),
                   [(out, "-o/--output")])
    _check_figure_path(out, "-o/--output")
    from .plot import figure

    corner = _corner(corner_angle, no_corners)
    with _user_errors():
        recs = _read(infile, corner, strict, quiet, polylines=polylines, columns=columns)
        curves = [r.curve for r in recs]
        others = None if other is None else [r.curve for r in _read(
            other, corner, strict, quiet, polylines=polylines, columns=columns)]
    _check_comb(curves + (others or []), comb_scale, comb_density, no_comb)
    with _user_errors():
        labels = (Path(infile).name, Path(other).name if other else "")
        fig = figure(curves, compare=others, labels=labels, tol=tol, comb=not no_comb,
                     comb_scale=comb_scale, comb_density=comb_density, markers=not no_markers,
                     projection=projection,  # type: ignore[arg-type]
                     names=[_record_label(r, i) for i, r in enumerate(recs)],
                     y_down=_format_of(infile) == "svg",
                     title=title if title is not None else
                     (f"{labels[0]} vs {labels[1]}" if other else labels[0]))
        _save_figure(fig, out)
    if not quiet:
        click.echo(f"wrote {out}")


# ------------------------------------------------------------------------------------------
# view
# ------------------------------------------------------------------------------------------
@main.command("view")
@click.argument("infile", metavar="IN", type=click.Path(exists=True, dir_okay=False))
@click.option("--compare", "other", metavar="OTHER",
              type=click.Path(exists=True, dir_okay=False),
              help="A second file with as many curves (e.g. the faired one): before/after "
                   "toggle and the deviation along each curve.")
@click.option("-o", "--output", "out", metavar="PAGE.html", required=True,
              help="The HTML page to write (self-contained: opens from disk, no network).")
@click.option("--tol", type=click.FloatRange(0, min_open=True), metavar="T",
              help="Tolerance shown on the deviation plot [default: the report's tol].")
@click.option("--report", "report_path", metavar="REPORT.json",
              type=click.Path(exists=True, dir_okay=False),
              help="A fairing report (curvefair fair --report) shown on the page.")
@click.option("--title", help="Page title [default: the file name(s)].")
@_reading_options
@_quiet_option
def view_cmd(infile: str, other: str | None, out: str, tol: float | None,
             report_path: str | None, title: str | None, corner_angle: float,
             no_corners: bool, polylines: bool, columns: tuple[int, ...] | None,
             strict: bool, quiet: bool) -> None:
    """Write an interactive HTML page of the curves of IN: combs, curvature, deviation."""
    _check_outputs([(infile, "IN")] + ([(other, "--compare")] if other else [])
                   + ([(report_path, "--report")] if report_path else []),
                   [(out, "-o/--output")])
    if Path(out).suffix.lower() not in (".html", ".htm"):
        raise click.BadParameter(f"{out!r}: the page is HTML; give a .html file name",
                                 param_hint="-o/--output")
    from .view import write_html

    corner = _corner(corner_angle, no_corners)
    report = None
    if report_path is not None:
        try:
            report = json.loads(Path(report_path).read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, ValueError) as exc:
            raise InputFailure(f"--report {report_path!r}: not a JSON file ({exc})") from None
        if tol is None and isinstance(report, dict):
            # a run report (curvefair fair --report) holds it in "options", a fair() report
            # at the top
            opts = report.get("options")
            t = report.get("tol", opts.get("tol") if isinstance(opts, dict) else None)
            if isinstance(t, (int, float)) and not isinstance(t, bool) and t > 0:
                tol = float(t)
    with _user_errors():
        recs = _read(infile, corner, strict, quiet, polylines=polylines, columns=columns)
        others = None if other is None else [r.curve for r in _read(
            other, corner, strict, quiet, polylines=polylines, columns=columns)]
        if others is not None and len(others) != len(recs):
            raise InputFailure(f"--compare {other!r} has {len(others)} curves but {infile!r} "
                               f"has {len(recs)}; they are paired in order")
        labels = (Path(infile).name, Path(other).name if other else "")
        write_html(out, [r.curve for r in recs], others,
                   names=[_record_label(r, i) for i, r in enumerate(recs)], tol=tol,
                   report=report, y_down=_format_of(infile) == "svg",
                   title=title if title is not None else
                   (f"{labels[0]} vs {labels[1]}" if other else labels[0]))
    if not quiet:
        click.echo(f"wrote {out}")


# ------------------------------------------------------------------------------------------
# fair
# ------------------------------------------------------------------------------------------
def _local_protect(rec: Any, user: Sequence[int]) -> list[int]:
    """User indices (file point order for point lists, else the curve's own) + corners."""
    idx = rec.source.get("indices") if hasattr(rec, "source") else None
    if idx is not None and user:
        pos = {int(fi): k for k, fi in enumerate(idx)}
        mine = [pos[i] for i in user if i in pos]
    else:
        mine = list(user)
    return sorted(set(mine) | set(rec.corners))


@contextlib.contextmanager
def _progress(total: int, enabled: bool) -> Iterator[Any]:
    """A transient rich progress bar on stderr (only on a terminal)."""
    if not enabled:
        yield None
        return
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    with Progress(TextColumn("[progress.description]{task.description}"), BarColumn(),
                  MofNCompleteColumn(), TimeElapsedColumn(), console=_console(stderr=True),
                  transient=True) as prog:
        task = prog.add_task("fairing", total=total)
        yield (prog, task)


def _where(r: dict[str, Any]) -> str:
    where = r.get("max_deviation_point")
    return "" if where is None else " at (" + ", ".join(f"{v:.4g}" for v in where) + ")"


def _deviation_cell(r: dict[str, Any]) -> str:
    """The max deviation of a curve's row: the fair's, or 0 when the file holds the input
    (a font contour the write-side never-worse guard kept: its other after-figures are
    those of the file already)."""
    if r.get("written") == "input":
        return "0 (written unchanged)"
    return _fmt(r["max_deviation"]) + _where(r)


def _summary_card(row: dict[str, Any]) -> Any:
    """One curve's before/after summary as a narrow table."""
    from rich.table import Table

    if row["status"] == "nothing to fair":
        return f"[bold]#{row['index']} {row['label']}[/bold]: nothing to fair (two points)"
    if row["status"] != "ok":
        return f"[bold]#{row['index']} {row['label']}[/bold]: [red]failed[/red] (error below)"
    r = row["report"]
    from rich.console import Group

    head = (f"[bold]#{row['index']} {row['label']}[/bold]: {r['method']}, {r['steps']} steps "
            f"({r['stop_reason']}), {r['time_s']:.3g} s")
    t = Table()
    t.add_column("")
    t.add_column("before", justify="right")
    t.add_column("after", justify="right")
    for label, key in (("energy", "energy"), ("max |Δr" + "'" * 3 + "|", "max_jump"),
                       ("inflections", "inflections"), ("κ extrema", "extrema")):
        t.add_row(label, _fmt(r[f"{key}_before"]), _fmt(r[f"{key}_after"]))
    t.add_row("max deviation", "", _deviation_cell(r))
    return Group(head, t)


def _summary_table(rows: list[dict[str, Any]]) -> Any:
    from rich.table import Table

    t = Table(title="before → after", title_justify="left")
    for col, just in (("#", "right"), ("curve", "left"), ("method", "left"), ("steps", "right"),
                      ("energy", "right"), ("max |Δr'''|", "right"), ("inflections", "right"),
                      ("κ extrema", "right"), ("max deviation (at)", "right"),
                      ("time", "right")):
        t.add_column(col, justify=just)  # type: ignore[arg-type]
    for row in rows:
        if row["status"] == "nothing to fair":
            t.add_row(str(row["index"]), row["label"], "nothing to fair", "0 (two points)", "-",
                      "-", "-", "-", "0", "-")
            continue
        if row["status"] != "ok":
            t.add_row(str(row["index"]), row["label"], "[red]failed[/red]", "-", "-", "-", "-",
                      "-", "(error below)", "-")
            continue
        r = row["report"]
        t.add_row(str(row["index"]), row["label"], r["method"],
                  f"{r['steps']} ({r['stop_reason']})",
                  _arrow(r["energy_before"], r["energy_after"]),
                  _arrow(r["max_jump_before"], r["max_jump_after"]),
                  _arrow(r["inflections_before"], r["inflections_after"]),
                  _arrow(r["extrema_before"], r["extrema_after"]),
                  _deviation_cell(r), f"{r['time_s']:.3g} s")
    return t


def _batch_options(f: Any) -> Any:
    """The many-files options of ``curvefair fair`` (see :mod:`curvefair._batch_cli`)."""
    from ._batch_cli import batch_options

    return batch_options(f)


def _batch_fair_options(method: str | None, tol: float | None, eps: float | None,
                        max_steps: int | None, clamp: str, protect: str | None, mode: str,
                        method_option: tuple[str, ...], decimals: int | None, history: bool,
                        corner_angle: float, no_corners: bool, strict: bool,
                        batch: dict[str, Any], polylines: bool = False,
                        columns: tuple[int, ...] | None = None) -> dict[str, Any]:
    """The options of :func:`curvefair.batch.fair_file`, checked as for one file."""
    options = _parse_method_options(method_option)
    _check_option_values(method if method and "=" not in method else None, options)
    return {"method": method, "tol": tol, "eps": eps, "max_steps": max_steps, "clamp": clamp,
            "protect": tuple(_parse_protect(protect)), "mode": mode, "method_options": options,
            "decimals": decimals, "history": history,
            "corner_angle": _corner(corner_angle, no_corners), "strict": strict,
            "polylines": bool(polylines), "columns": columns,
            "layer": batch["layer"], "name": batch["name"],
            "handle": batch["handle"], "hold_shared": batch["hold_shared"],
            "shared_distance": batch["shared_distance"]}


@main.command("fair", epilog="Default method per curve type: " + _default_methods_text()
              + ". List all with 'curvefair methods'.")
@click.argument("paths", metavar="IN...", nargs=-1, required=True)
@click.option("-o", "--output", "out", metavar="OUT",
              help="Output file; its extension picks the format (default: IN's format). "
                   "Required unless --in-place. With several inputs, a folder or a glob: the "
                   "output folder (inputs keep their paths relative to the folder or glob "
                   "base; per-file JSON reports and the run report go to OUT/.curvefair/). "
                   "'-': stdout.")
@click.option("--in-place", is_flag=True, help="Allow OUT to be IN (or omit -o to replace IN).")
@click.option("--method", "-m", metavar="M",
              help="Fairing method (see 'curvefair methods'); default: the best general method "
                   "for the curve type, " + _default_methods_text() + ".")
@click.option("--tol", type=click.FloatRange(0, min_open=True), metavar="T",
              help="No data/control point ends farther than T from where it was "
                   "[default: no limit].")
@click.option("--eps", type=click.FloatRange(min=0), metavar="E",
              help="Stop when the worst point's measure is below E [default: method's].")
@click.option("--max-steps", type=click.IntRange(min=0), metavar="N",
              help="Step cap [default: method's].")
@click.option("--clamp", type=click.Choice(["g0", "g1", "g2"]), default="g0", show_default=True,
              help="Ends kept exactly: g0 end points, g1 also the tangents, g2 also curvature.")
@click.option("--protect", metavar="I,J,...",
              help="Point indices that never move (0-based; file order for point lists, "
                   "control points for B-splines). Corners found on reading are always kept.")
@click.option("--mode", type=click.Choice(["spline", "hermite"]), default="spline",
              show_default=True,
              help="Hermite methods: re-interpolate after each step, or keep the step's "
                   "derivatives.")
@click.option("-O", "--option", "method_option", metavar="KEY=VALUE", multiple=True,
              help="A method option, repeatable (e.g. -m eck-hadenfeld -O schedule=sweep "
                   "-O l=3). VALUE is read as an integer, else a number, else true/false, "
                   "else text; a repeated KEY: the last wins. 'curvefair methods' lists each "
                   "method's options and defaults; a KEY the method does not take fails the "
                   "curve. fair()'s corner_turn and g1_angle (degrees) are taken too: "
                   "-O corner_turn=inf lets B-spline corners turn more than 1 degree.")
@click.option("--decimals", type=click.IntRange(min=0), metavar="N",
              help="Text formats: write every number with N decimals [default: a "
                   "moved number keeps its own or its column's decimals where they write it "
                   "exactly, else it is written in full (never rounded unasked)]. A "
                   "rounding that puts a curve read back farther than --tol from the input, "
                   "or points onto each other, writes nothing (exit 1).")
@click.option("--report", metavar="REPORT.json", help="Write the full report as JSON.")
@click.option("--history", is_flag=True, help="Include every step in the JSON report.")
@click.option("--plot", "plot_path", metavar="PLOT.png",
              help="Write a before/after figure (.png, .svg or .pdf).")
@click.option("--glyphs", metavar="A,B,...",
              help="Fonts (.ufo, .ttf, .otf): fair only these glyphs (names, comma separated).")
@_batch_options
@_reading_options
@_quiet_option
def fair_cmd(paths: tuple[str, ...], out: str | None, in_place: bool, method: str | None,
             tol: float | None, eps: float | None, max_steps: int | None, clamp: str,
             protect: str | None, mode: str, method_option: tuple[str, ...],
             decimals: int | None, report: str | None,
             history: bool,
             plot_path: str | None, corner_angle: float, no_corners: bool,
             polylines: bool, columns: tuple[int, ...] | None, strict: bool, quiet: bool,
             glyphs: str | None = None, **batch: Any) -> None:
    """Fair every curve in IN and write them to OUT.

    Prints a before/after table: strain energy, largest third-derivative jump, inflections,
    curvature extrema, largest deviation and where, steps and time. A curve that cannot be
    faired is reported and written unchanged; the others are still processed and the exit
    code is 1.

    OUT is written to a temporary file and read back first: every curve read back is measured
    against IN's (the figure is printed and in the report). Farther than --tol: SVG rounding
    to the file's decimals is undone, point data get smaller moves; otherwise OUT is not
    written (exit 1).

    IN... may be several files, folders and glob patterns (quote them), or '-' for stdin;
    then OUT is a folder and every file is faired on its own (--jobs processes, or Dask
    workers with --scheduler); one failing file does not stop the others (exit 1).

    A file with many curves (a drawing's entities, a font's glyphs) has its curves faired on
    --jobs processes (default: one per core) once the first ones show that the rest would take
    a few seconds; the curves written are the same.
    """
    from ._batch_cli import fair_many, wants_batch

    if len(paths) == 1 and paths[0].lower().endswith(".designspace"):
        _fair_designspace_cmd(paths[0], out, in_place=in_place, method=method, tol=tol,
                              eps=eps, max_steps=max_steps, clamp=clamp, protect=protect,
                              mode=mode, method_option=method_option, report=report,
                              plot_path=plot_path, glyphs=glyphs, quiet=quiet)
        return
    chunk, overlap = batch.pop("chunk", None), batch.pop("overlap", None)
    from ._batch_cli import fair_in_chunks, wants_chunks

    if wants_chunks(paths, chunk):
        fair_in_chunks(paths, out, in_place, _batch_fair_options(
            method, tol, eps, max_steps, clamp, protect, mode, method_option, decimals,
            history, corner_angle, no_corners, strict, batch, polylines, columns),
            {k: batch[k] for k in ("layer", "name", "handle", "hold_shared", "shared_distance",
                                   "resume", "dry_run", "diff", "in_format")},
            chunk=chunk, overlap=overlap, jobs=batch["jobs"], scheduler=batch["scheduler"],
            report=report, quiet=quiet, plot_path=plot_path)
        return
    if overlap is not None:
        raise click.UsageError("--overlap goes with --chunk")
    if wants_batch(paths, out, method, batch):
        if glyphs:
            raise click.BadParameter("--glyphs works on one font file (IN, -o OUT)",
                                     param_hint="--glyphs")
        fair_many(paths, out, in_place, _batch_fair_options(
            method, tol, eps, max_steps, clamp, protect, mode, method_option, decimals,
            history, corner_angle, no_corners, strict, batch, polylines, columns),
            jobs=batch["jobs"],
            resume=batch["resume"], dry_run=batch["dry_run"], diff=batch["diff"],
            scheduler=batch["scheduler"], report=report, fmt=batch["in_format"], quiet=quiet,
            plot_path=plot_path)
        return
    infile = paths[0]
    if not (os.path.isfile(infile) or (os.path.isdir(infile)
                                       and infile.rstrip("/\\").lower().endswith(".ufo"))):
        raise click.BadParameter(f"file {infile!r} does not exist", param_hint="IN")
    from .io import detect_format

    if out is None:
        if not in_place:
            raise click.UsageError("missing option '-o' / '--output' (or pass --in-place to "
                                   "replace IN)")
        out = infile
    _check_outputs([(infile, "IN")], [(out, "-o/--output"), (report, "--report"),
                                      (plot_path, "--plot")], in_place)
    user_protect = _parse_protect(protect)
    options = _parse_method_options(method_option)
    _check_option_values(method, options)
    if plot_path is not None:
        _check_figure_path(plot_path, "--plot")
    for p, opt in ((report, "--report"), (plot_path, "--plot"), (out, "-o/--output")):
        if p is not None and not Path(p).resolve().parent.is_dir():
            raise click.BadParameter(f"the folder of {p!r} does not exist", param_hint=opt)
    from .fairing import METHODS

    if method is not None and method not in METHODS:
        raise click.BadParameter(f"unknown method {method!r}; valid: " + ", ".join(METHODS),
                                 param_hint="--method")
    in_fmt = _format_of(infile, "IN")
    with _user_errors():
        try:
            out_fmt: str = detect_format(out)
        except CurvefairError:
            out_fmt = in_fmt
        try:
            records = _read(infile, _corner(corner_angle, no_corners), strict, quiet, glyphs,
                            all_skipped_ok=out_fmt == in_fmt, polylines=polylines,
                            columns=columns)
        except _AllSkipped as exc:
            _write_unchanged(infile, out, report, exc.n, quiet, exc.drawn, exc.font)
            return
    _check_protect_range(records, user_protect)
    from . import fair
    from .io import read_columns, reads_polylines, write_checked

    rows: list[dict[str, Any]] = []
    faired: list[Any] = []
    t0 = time.perf_counter()
    show_progress = not quiet and sys.stderr.isatty()
    from ._batch_cli import PHASE_NAMES
    from .fairing.fair import PHASES

    # one bar: PHASES steps per curve (curvefair.fair's progress) and one for the write
    bar = contextlib.ExitStack()
    prog = bar.enter_context(_progress(len(records) * PHASES + 1, show_progress))
    from . import _records

    # many curves: once the first ones have shown what the rest would take, the rest are
    # faired on a pool of processes (curvefair._records: the same bits, so the same file)
    jobs = batch.get("jobs")
    workers = _records.default_workers() if jobs is None else int(jobs)
    pool: _records.Pool | None = None
    # (record index, fair() arguments, task) of the curves given to the pool
    pending: list[tuple[int, dict[str, Any], _records.Task]] = []
    done_here = 0

    def finish(i: int, row: dict[str, Any], rec: Any, res: Any, error: str | None) -> None:
        if error is not None:
            row.update(status="failed", error=error)
            faired[i] = rec
            return
        row.update(status="ok", report=res.report)
        if history:
            row["history"] = res.history.to_dict()
        faired[i] = rec.with_curve(res.curve)

    try:
        for i, rec in enumerate(records):
            phase = None
            if prog is not None:
                def phase(done: int, total: int, _i: int = i) -> None:
                    prog[0].update(prog[1], completed=_i * PHASES + done,
                                   description=f"curve {_i}: "
                                               f"{PHASE_NAMES[max(done, 1) - 1]} done")
            label = _record_label(rec, i)
            row: dict[str, Any] = {"index": i, "label": label, "name": rec.name,
                                   "kind": rec.kind}
            rows.append(row)
            faired.append(rec)
            if _nothing_to_fair(rec):
                row.update(status="nothing to fair",
                           note="two points (a straight piece between corners): no interior "
                                "point to move; written back unchanged")
                if prog is not None:
                    prog[0].update(prog[1], completed=(i + 1) * PHASES)
                continue
            kwargs = dict(tol=tol, eps=eps, max_steps=max_steps, clamp=clamp,
                          protect=_local_protect(rec, user_protect), mode=mode, **options)
            if pool is None and _records.worth_a_pool(time.perf_counter() - t0, done_here,
                                                      len(records) - i, workers):
                pool = _records.Pool(workers - 1)
            if pool is not None:
                pending.append((i, kwargs, pool.submit(rec.curve, method, kwargs)))
                continue
            notes: list[str] = []
            try:
                with _warnings_to_stderr(quiet, f"{infile}: curve {i} ({label}): ", notes):
                    res = fair(rec.curve, method, progress=phase, **kwargs)
            except CurvefairError as exc:
                finish(i, row, rec, None, str(exc))
            else:
                finish(i, row, rec, res, None)
                if notes:
                    row["warnings"] = notes
            done_here += 1
            if prog is not None:
                prog[0].update(prog[1], completed=(i + 1) * PHASES)
        # while the workers start and work from the front, this process takes curves from
        # the end until it meets one a worker has begun
        taken = set()
        for i, _, task in reversed(pending):
            if not task.take():
                break
            taken.add(i)
            if prog is not None:
                prog[0].advance(prog[1], PHASES)
        for i, kwargs, task in pending:
            row, rec = rows[i], records[i]
            status, value, caught = task.result()
            if prog is not None and i not in taken:
                prog[0].advance(prog[1], PHASES)
            notes = []
            with _warnings_to_stderr(quiet, f"{infile}: curve {i} ({row['label']}): ", notes):
                for category, message in caught:  # the worker's warnings, shown as here
                    warnings.warn(message, category, stacklevel=1)
                if status == "crashed":  # the error as it would surface without a pool
                    try:
                        value = fair(rec.curve, method, **kwargs)
                        status = "ok"
                    except CurvefairError as exc:
                        status, value = "failed", str(exc)
            finish(i, row, rec, value if status == "ok" else None,
                   value if status == "failed" else None)
            if notes and status == "ok":
                row["warnings"] = notes
    finally:
        if pool is not None:  # interrupted: the workers are not waited for
            pool.close(wait=sys.exc_info()[0] is None)
    if prog is not None:
        prog[0].update(prog[1], description="write and read back")
    failures = [r for r in rows if r["status"] == "failed"]
    wrote_out = len(failures) < len(rows)  # every curve failed: nothing to write
    check = None
    corner = _corner(corner_angle, no_corners)
    with bar, _user_errors(), _warnings_to_stderr(quiet):
        if wrote_out:
            # written to a temporary file, read back and measured against the input; moved
            # onto OUT only when every curve read back is within tol
            check = write_checked(out, faired, records, tol=tol,
                                  # the temporary file has OUT's extension, which need
                                  # not name a format (-o OUT without one: IN's format)
                                  # point data written to a drawing are polylines
                                  reader=lambda p: _read(p, corner, strict, True, glyphs,
                                                         fmt=out_fmt, polylines=polylines
                                                         or bool(reads_polylines(faired,
                                                                                 out_fmt)),
                                                         columns=read_columns(faired,
                                                                              out_fmt)),
                                  template=infile if out_fmt == in_fmt else None,
                                  format=out_fmt, overwrite=in_place, decimals=decimals)
            if prog is not None:
                prog[0].advance(prog[1])
            from .io import on_disk_report

            kept_notes: list[str] = []
            for i, (row, d, kind) in enumerate(zip(rows, check.deviations, check.kinds,
                                                   strict=True)):
                if row["status"] == "ok":
                    if check.read_back:
                        # the after-figures of what is on disk: scaled moves, or point data
                        # rebuilt through the written points
                        row["report"] = on_disk_report(row["report"], records[i].curve,
                                                       faired[i].curve, check.read_back[i],
                                                       check.move_scale[i])
                    row["report"]["on_disk_deviation"] = d
                    row["report"]["on_disk_deviation_kind"] = kind
                    if d == 0.0 and "outline" in records[i].source and \
                            faired[i].curve is not records[i].curve:
                        # a font contour the write-side never-worse guard kept as it was
                        # (curvefair.io.fonts.record_points): the figures above are the fair's,
                        # the file holds the input
                        row["report"]["written"] = "input"
                        kept_notes.append(
                            f"curve {i} ({row['label']}): written unchanged: the outline as "
                            "written (smooth nodes, integer grid) was not fairer than the input")
            for note in check.notes:
                click.echo(f"Warning: {out}: {note}", err=True)
            if not quiet:
                for note in kept_notes:
                    click.echo(f"Note: {out}: {note}", err=True)
        if plot_path is not None:
            from .plot import figure

            fig = figure([r.curve for r in records], compare=[r.curve for r in faired],
                         labels=("before", "after"), tol=tol,
                         title=f"{Path(infile).name}: before and after fairing")
            _save_figure(fig, plot_path)
        if report is not None:
            _write_json(report, {
                "curvefair": __version__, "input": os.path.abspath(infile),
                "output": os.path.abspath(out), "format": out_fmt,
                "options": {"method": method, "tol": tol, "eps": eps, "max_steps": max_steps,
                            "clamp": clamp, "protect": user_protect, "mode": mode,
                            "method_options": {k: _option_default(v)
                                               for k, v in options.items()},
                            "corner_angle": _corner(corner_angle, no_corners),
                            "polylines": polylines, "columns": columns,
                            "strict": strict},
                "n_curves": len(rows), "n_failed": len(failures),
                "n_nothing_to_fair": sum(r["status"] == "nothing to fair" for r in rows),
                "output_written": wrote_out,
                "output_check": None if check is None else check.to_dict(),
                "time_s": time.perf_counter() - t0, "curves": rows})
    if not quiet:
        con = _console()
        if con.width >= 130:
            con.print(_summary_table(rows))
        else:  # a narrow terminal: one small before/after table per curve
            for row in rows:
                con.print(_summary_card(row))
        for row in rows:  # the never-worse guard: say what was kept instead of the result
            g = row.get("report", {}).get("guard") if row["status"] == "ok" else None
            if g and g.get("kept") != "output":
                con.print(f"#{row['index']} {row['label']}: {g.get('reason')}", markup=False)
        written = [f"wrote {out}" if wrote_out else f"{out} not written"]
        if check is not None:
            written[0] += (f" (read back: max deviation {check.max_deviation:.6g} from the input"
                           + (f", tol {tol:g})" if tol is not None else ")"))
        written += [f"report {report}"] if report else []
        written += [f"plot {plot_path}"] if plot_path else []
        con.print(", ".join(written))
    if failures:
        for r in failures:
            click.echo(f"Error: {infile}: curve {r['index']} ({r['label']}): {r['error']}",
                       err=True)
        raise SystemExit(EXIT_INPUT)


def _fair_designspace_cmd(infile: str, out: str | None, *, in_place: bool, method: str | None,
                          tol: float | None, eps: float | None, max_steps: int | None,
                          clamp: str, protect: str | None, mode: str,
                          method_option: tuple[str, ...], report: str | None,
                          plot_path: str | None, glyphs: str | None, quiet: bool) -> None:
    """``curvefair fair X.designspace --tol T -o OUTDIR``: every master faired with the same
    options by :func:`curvefair.fonts.fair_designspace`, written into OUTDIR (a copy of the
    document and of each source UFO, same relative names); exit 1 when the result has an
    interpolation problem the input did not have."""
    if not os.path.isfile(infile):
        raise click.BadParameter(f"file {infile!r} does not exist", param_hint="IN")
    if out is None or in_place:
        raise click.UsageError("a designspace is faired into a new folder: pass -o OUTDIR "
                               "(not --in-place); OUTDIR gets the document and its masters")
    if out == "-":
        raise click.BadParameter("a designspace is written as a folder, not to stdout",
                                 param_hint="-o/--output")
    if tol is None:
        raise click.UsageError("--tol is required for a designspace (font units): every master "
                               "is faired within the same tolerance")
    for opt, val in (("--protect", protect), ("--plot", plot_path)):
        if val is not None:
            raise click.BadParameter("not available for a designspace (the masters are "
                                     "written as UFOs; use them on one master)", param_hint=opt)
    parent = Path(out).resolve().parent
    if not parent.is_dir():
        raise click.BadParameter(f"the folder of {out!r} does not exist", param_hint="-o/--output")
    if os.path.exists(out) and not os.path.isdir(out):
        raise click.BadParameter(f"{out!r} is a file; a designspace is written into a folder",
                                 param_hint="-o/--output")
    if Path(out).resolve() == Path(infile).resolve().parent:
        raise click.UsageError(f"-o/--output {out!r} is the folder of the designspace: the "
                               "masters would be replaced; give another folder")
    options = _parse_method_options(method_option)
    _check_option_values(method, options)
    from .fairing import METHODS

    if method is not None and method not in METHODS:
        raise click.BadParameter(f"unknown method {method!r}; valid: " + ", ".join(METHODS),
                                 param_hint="--method")
    from .fonts import fair_designspace

    t0 = time.perf_counter()
    with _user_errors(), _warnings_to_stderr(quiet):
        res = fair_designspace(infile, out, tol, glyphs=glyphs, method=method, eps=eps,
                               max_steps=max_steps, clamp=clamp, mode=mode, **options)
    kinds = {p["type"] for p in res["problems"]}
    new_kinds = sorted(kinds - {p["type"] for p in res["problems_before"]})
    if report is not None:
        _write_json(report, {"curvefair": __version__, "input": os.path.abspath(infile),
                             "output": os.path.abspath(out), "format": "designspace",
                             "options": {"method": method, "tol": tol, "eps": eps,
                                         "max_steps": max_steps, "clamp": clamp, "mode": mode,
                                         "method_options": {k: _option_default(v)
                                                            for k, v in options.items()}},
                             "time_s": time.perf_counter() - t0, **res})
    if not quiet:
        for s in res["sources"]:
            where = s["ufo"] + (f" (layer {s['layer']})" if s.get("layer") else "")
            click.echo(f"{where}: {s['contours']} contours, {s['changed']} changed "
                       f"(faired within {tol:g})")
        click.echo(f"wrote {out} (interpolation problems: {len(res['problems_before'])} in the "
                   f"input, {len(res['problems'])} in the output)")
    if new_kinds:
        click.echo(f"Error: {out}: the faired masters have interpolation problems the input "
                   f"did not have: {', '.join(new_kinds)}", err=True)
        raise SystemExit(EXIT_INPUT)


from ._batch_cli import check_cmd as _check_cmd  # noqa: E402  (curvefair check)

main.add_command(_check_cmd)

if __name__ == "__main__":  # pragma: no cover
    main()

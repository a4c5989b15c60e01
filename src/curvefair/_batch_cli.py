"""The many-files side of ``curvefair fair`` (folders, globs, ``-o DIR``, ``--jobs``, ``--resume``,
``-`` for stdin/stdout, selection filters, per-kind methods, ``--dry-run``/``--diff``,
``--scheduler``) and the ``curvefair check`` command. The per-file work is
:func:`curvefair.batch.fair_file`; :mod:`curvefair.cli` hands over here when any of those is
asked for and keeps its single-file path otherwise.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import sys
import time
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

import click

from . import batch as _batch
from .errors import CurvefairError, MissingDependencyError

EXIT_OK, EXIT_INPUT, EXIT_USAGE = 0, 1, 2
#: Point files larger than this are faired in chunks (``--chunk``) without being asked.
AUTO_CHUNK_BYTES = 256 << 20
#: What :func:`curvefair.fair` has just finished when it reports phase 1, 2, 3, 4.
PHASE_NAMES = ("analysis", "fairing", "analysis after", "certificate")


class _Failure(click.ClickException):
    exit_code = EXIT_INPUT


def wants_batch(paths: Sequence[str], out: str | None, method: str | None,
                extra: Mapping[str, Any]) -> bool:
    """Whether the command line needs the many-files path (anything the single-file path of
    ``curvefair fair`` does not know)."""
    if len(paths) != 1:
        return True
    p = paths[0]
    if p == "-" or (os.path.isdir(p) and not p.rstrip("/\\").lower().endswith(".ufo")):
        return True
    if not os.path.exists(p) and _batch._GLOB_CHARS.search(p):
        return True
    # one file and -o naming an existing folder stays a usage error (a file name was likely
    # meant); a trailing slash asks for the folder
    if out is not None and (out == "-" or out.endswith(("/", os.sep))):
        return True
    if method is not None and "=" in method:
        return True
    # --jobs alone: one file's curves on that many processes (the single-file path)
    return any(bool(v) for k, v in extra.items() if k != "jobs")


def _fmt(v: Any, digits: int = 4) -> str:
    if v is None:
        return "-"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, int):
        return str(v)
    try:
        return f"{float(v):.{digits}g}"
    except (TypeError, ValueError):
        return str(v)


def diff_lines(rep: Mapping[str, Any]) -> list[str]:
    """What changed in one file, one line per curve (for ``--diff`` / ``--dry-run``)."""
    out = []
    for row in rep.get("curves", []):
        head = f"  #{row['index']} {row['label']} [{row['kind']}]"
        st = row["status"]
        if st != "ok":
            out.append(f"{head}: {st}" + (f": {row['error']}" if st == "failed" else ""))
            continue
        r, ch = row["report"], row.get("change", {})
        dev = r.get("on_disk_deviation", r.get("max_deviation"))
        out.append(
            f"{head}: {r.get('method')}, moved {_fmt(ch.get('moved'))}/{_fmt(ch.get('points'))}"
            f" points (largest move {_fmt(ch.get('max_move'), 6)}), deviation {_fmt(dev, 6)}; "
            f"inflections {_fmt(r.get('inflections_before'))} → "
            f"{_fmt(r.get('inflections_after'))}, κ extrema {_fmt(r.get('extrema_before'))} → "
            f"{_fmt(r.get('extrema_after'))}, energy {_fmt(r.get('energy_before'))} → "
            f"{_fmt(r.get('energy_after'))}")
    return out


@contextlib.contextmanager
def _progress(enabled: bool, n_files: int) -> Iterator[Any]:
    """Two rich bars on stderr (only on a terminal): files, and curves (the total grows as
    each file is read)."""
    if not enabled:
        yield None
        return
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    with Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
                  TimeElapsedColumn(), console=Console(file=sys.stderr),
                  transient=True) as prog:
        files = prog.add_task("files", total=n_files)
        curves = prog.add_task("curves", total=0)
        within = prog.add_task("", total=None, visible=False)

        def event(name: str, what: str, value: Any) -> None:
            if what == "curves":
                prog.update(curves, total=(prog.tasks[curves].total or 0) + value)
            elif what == "curve":
                prog.advance(curves, value)
            elif what in ("file", "skipped"):
                prog.advance(files, value)
            elif what == "phase":  # within one curve: curvefair.fair's phases
                done, total = value
                phase = PHASE_NAMES[min(max(done, 1), len(PHASE_NAMES)) - 1]
                prog.update(within, completed=done, total=total, visible=True,
                            description=f"{os.path.basename(name)}: {phase} done")
            elif what == "write":
                prog.update(within, completed=value, total=1, visible=True,
                            description=f"{os.path.basename(name)}: write and read back")
            elif what == "chunk":  # within one chunked curve
                done, total = value
                prog.update(within, completed=done, total=total, visible=True,
                            description=f"{os.path.basename(name)}: chunks")

        yield event


def fair_many(paths: Sequence[str], out: str | None, in_place: bool, options: dict[str, Any],
              *, jobs: int | None, resume: bool, dry_run: bool, diff: bool,
              scheduler: str | None, report: str | None, fmt: str | None, quiet: bool,
              plot_path: str | None) -> None:
    """``curvefair fair`` over many inputs; exits 1 when any file failed."""
    t0 = time.perf_counter()
    if plot_path is not None:
        raise click.UsageError("--plot takes one input file and one output file")
    if out is None and not in_place and not dry_run:
        raise click.UsageError("missing option '-o' / '--output' (a folder for many inputs, "
                               "or pass --in-place to replace each input)")
    if out == "-" and (len(paths) != 1 or (paths[0] != "-" and not os.path.isfile(paths[0]))):
        raise click.UsageError("-o - (stdout) takes exactly one input")
    if out is not None and in_place and out != "-":
        raise click.UsageError("--in-place replaces each input; do not also give -o")
    try:
        _batch.parse_methods(options.get("method"))
    except CurvefairError as exc:
        raise click.BadParameter(str(exc), param_hint="--method") from None
    to_stdout = out == "-"
    single = (out is not None and not to_stdout and len(paths) == 1 and paths[0] != "-"
              and os.path.isfile(paths[0]) and not os.path.isdir(out)
              and not out.endswith(("/", os.sep)))
    con_err = to_stdout
    with contextlib.ExitStack() as stack:
        tmp = stack.enter_context(_batch.temp_folder()) if ("-" in paths or to_stdout) else None
        try:
            if single or to_stdout:
                jobs_list = _single_job(paths[0], out, tmp, fmt, report)
            else:
                if out is not None:
                    if os.path.exists(out) and not os.path.isdir(out):
                        raise click.BadParameter(f"{out!r} is a file; many inputs need an "
                                                 "output folder", param_hint="-o/--output")
                    parent = Path(out.rstrip("/" + os.sep) or ".").resolve().parent
                    if not parent.is_dir():
                        raise click.BadParameter(f"the folder of {out!r} does not exist",
                                                 param_hint="-o/--output")
                # a dry run without -o: the jobs are planned in place (it writes nothing)
                jobs_list = _batch.plan_inputs(paths, out, stdin_format=fmt,
                                               in_place=in_place or (dry_run and out is None))
                for j in jobs_list:
                    if j.input == "-":
                        assert tmp is not None
                        j.input = _batch.spool_stdin(fmt, tmp)
        except CurvefairError as exc:
            raise click.UsageError(str(exc)) from None
        if report is not None and not (single or to_stdout):
            from .cli import _check_outputs

            _check_outputs([(j.input, "IN") for j in jobs_list], [(report, "--report")])
            for j in jobs_list:
                if _batch._file_key(j.output) == _batch._file_key(report):
                    raise click.UsageError(f"--report {report!r} is the output of {j.display!r}")
        if not dry_run and out is not None and not to_stdout and not single:
            os.makedirs(out, exist_ok=True)
        client = None
        if scheduler is not None:
            client = stack.enter_context(_dask_client(scheduler))
        show = not quiet and sys.stderr.isatty()
        try:
            with _progress(show, len(jobs_list)) as event:
                reports = _batch.run_jobs(jobs_list, options, jobs_n=jobs, client=client,
                                          dry_run=dry_run, resume=resume, in_format=fmt,
                                          on_event=event)
        except (_batch._Terminated, KeyboardInterrupt) as exc:
            signum = exc.args[0] if isinstance(exc, _batch._Terminated) else 2
            click.echo(f"Error: stopped by signal {signum}; the outputs already written are "
                       "complete, the others were not written (run again with --resume)",
                       err=True)
            raise SystemExit(128 + int(signum)) from None
        run = _batch.run_report(jobs_list, reports, options, t0, dry_run, jobs_n=jobs,
                                client=client)
        run_path = None
        if not dry_run and not (single or to_stdout):
            from .io import atomic_write

            run_path = report or os.path.join(out or os.path.dirname(
                os.path.abspath(jobs_list[0].input)), _batch.REPORT_DIR, "run.json")
            os.makedirs(os.path.dirname(os.path.abspath(run_path)), exist_ok=True)
            atomic_write(run_path, json.dumps(run, indent=2, allow_nan=False) + "\n")
        if to_stdout and reports[0].get("status") in ("ok", "partial"):
            with open(jobs_list[0].output, "rb") as f:
                shutil.copyfileobj(f, sys.stdout.buffer)
            sys.stdout.flush()
    _print_summary(jobs_list, reports, run, run_path, quiet, diff or dry_run, con_err)
    bad = [(j, r) for j, r in zip(jobs_list, reports, strict=True)
           if r.get("status") in ("failed", "partial")]
    for j, r in bad:
        msgs = [r["error"]] if r.get("error") else []
        msgs += [f"curve {c['index']} ({c['label']}): {c['error']}" for c in r.get("curves", [])
                 if c.get("status") == "failed"]
        for m in msgs or ["failed"]:
            click.echo(f"Error: {j.display}: {m}", err=True)
    if bad:
        raise SystemExit(EXIT_INPUT)


def _single_job(path: str, out: str | None, tmp: str | None, fmt: str | None,
                report: str | None) -> list[_batch.Job]:
    """One input (a file or ``-``) to one output (a file or ``-``)."""
    from .cli import _check_outputs

    display = "<stdin>" if path == "-" else path
    if path == "-":
        assert tmp is not None
        path = _batch.spool_stdin(fmt, tmp)
    if out == "-":
        assert tmp is not None
        from .io import FORMATS, detect_format

        ofmt = fmt or detect_format(path)
        out_path = os.path.join(tmp, "stdout" + FORMATS[ofmt][0])
        rep = report
    else:
        assert out is not None
        _check_outputs([(path, "IN")], [(out, "-o/--output"), (report, "--report")])
        if not Path(out).resolve().parent.is_dir():
            raise click.BadParameter(f"the folder of {out!r} does not exist",
                                     param_hint="-o/--output")
        out_path = out
        rep = report or os.path.join(os.path.dirname(os.path.abspath(out)), _batch.REPORT_DIR,
                                     os.path.basename(out) + ".json")
        if _batch._file_key(rep) == _batch._file_key(path):
            raise click.UsageError(f"the report {rep!r} is the input file")
    return [_batch.Job(path, out_path, rep, os.path.basename(out_path), display)]


@contextlib.contextmanager
def _dask_client(address: str) -> Iterator[Any]:
    try:
        from distributed import Client
    except ImportError:
        raise _Failure(str(MissingDependencyError("distributed", "dask", "--scheduler"))) from None
    try:
        client = Client(address, timeout="10s")
    except (OSError, TimeoutError, ValueError) as exc:
        raise _Failure(f"--scheduler {address!r}: cannot connect ({exc})") from None
    try:
        yield client
    finally:
        client.close()


def _print_summary(jobs: Sequence[_batch.Job], reports: Sequence[Mapping[str, Any]],
                   run: Mapping[str, Any], run_path: str | None, quiet: bool, diff: bool,
                   to_err: bool) -> None:
    if quiet:
        return
    echo = (lambda s: click.echo(s, err=True)) if to_err else click.echo
    for j, r in zip(jobs, reports, strict=True):
        st: Any = r.get("status")
        if r.get("skipped"):
            echo(f"skipped {j.display}: output {j.output} is up to date")
            continue
        n_ok = sum(c.get("status") == "ok" for c in r.get("curves", []))
        dev = (r.get("output_check") or {}).get("max_deviation")
        what = {"ok": "wrote", "partial": "wrote (some curves failed)", "dry-run": "would write",
                "failed": "FAILED"}.get(st, st)
        tail = f"{r.get('n_curves', 0)} curves, {n_ok} faired"
        if dev is not None:
            tail += f", read back: max deviation {dev:.6g}"
        dest = "<stdout>" if "stdout" in os.path.basename(j.output) and to_err else j.output
        echo(f"{what} {dest} from {j.display} ({tail})" if st != "failed"
             else f"FAILED {j.display}: {r.get('error') or 'a curve failed'}")
        if diff:
            for line in diff_lines(r):
                echo(line)
    counts = (f"{run['n_files']} file(s): {run['n_ok']} written, {run['n_skipped']} up to date, "
              f"{run['n_partial']} partial, {run['n_failed']} failed")
    if run["dry_run"]:
        counts += " (dry run: nothing written)"
    echo(counts + (f"; run report {run_path}" if run_path else ""))


# ------------------------------------------------------------------------------------------
# one point list in chunks
# ------------------------------------------------------------------------------------------
def wants_chunks(paths: Sequence[str], chunk: int | None) -> bool:
    """``--chunk`` given, or one input that only the chunked path reads (``.npy``) or that is
    a point file larger than :data:`AUTO_CHUNK_BYTES`."""
    from ._chunked import NPY_EXTS, TEXT_EXTS

    if chunk is not None:
        return True
    if len(paths) != 1 or not os.path.isfile(paths[0]):
        return False
    ext = Path(paths[0]).suffix.lower()
    return ext in NPY_EXTS or (ext in TEXT_EXTS and ext != ".dat"
                               and os.path.getsize(paths[0]) > AUTO_CHUNK_BYTES)


def fair_in_chunks(paths: Sequence[str], out: str | None, in_place: bool,
                   options: Mapping[str, Any], extra: Mapping[str, Any], *, chunk: int | None,
                   overlap: int | None, jobs: int | None, scheduler: str | None,
                   report: str | None, quiet: bool, plot_path: str | None) -> None:
    """``curvefair fair BIG -o OUT --tol T --chunk N``: :func:`curvefair.batch.fair_chunked`
    with a progress bar over the chunks; exit 1 on bad input (nothing written)."""
    from ._chunked import DEFAULT_CHUNK, DEFAULT_OVERLAP

    if len(paths) != 1 or paths[0] == "-" or not os.path.isfile(paths[0]):
        raise click.UsageError("--chunk fairs one point file (IN -o OUT)")
    if out is None or out == "-" or in_place:
        raise click.UsageError("--chunk needs -o OUT (a point file; not '-', not --in-place)")
    if options.get("tol") is None:
        raise click.UsageError("--chunk needs --tol (each chunk is faired within it)")
    for opt, v in (("--plot", plot_path), ("--decimals", options.get("decimals")),
                   ("--history", options.get("history") or None),
                   ("--columns", options.get("columns"))):
        if v is not None:
            raise click.UsageError(f"{opt} does not apply with --chunk")
    for key, v in extra.items():
        if v:
            raise click.UsageError(f"--{key.replace('_', '-')} does not apply with --chunk "
                                   "(one point list)")
    method = options.get("method")
    if method is not None and "=" in method:
        raise click.BadParameter("one method name with --chunk", param_hint="--method")
    infile = paths[0]
    from .cli import _check_outputs

    _check_outputs([(infile, "IN")], [(out, "-o/--output"), (report, "--report")])
    rep_path = report or os.path.join(os.path.dirname(os.path.abspath(out)), _batch.REPORT_DIR,
                                      os.path.basename(out) + ".json")
    client_cm: Any = _dask_client(scheduler) if scheduler else contextlib.nullcontext()
    show = not quiet and sys.stderr.isatty()
    kw = {k: options[k] for k in ("eps", "max_steps") if options.get(k) is not None}
    if options.get("mode") not in (None, "spline"):
        kw["mode"] = options["mode"]
    with client_cm as client, _progress(show, 1) as event:
        def prog(done: int, total: int) -> None:
            if event is not None:
                event(infile, "chunk", (done, total))
        try:
            os.makedirs(os.path.dirname(rep_path), exist_ok=True)
            rep = _batch.fair_chunked(
                infile, out, tol=options["tol"], chunk=chunk or DEFAULT_CHUNK,
                overlap=overlap or DEFAULT_OVERLAP, client=client, jobs=jobs, method=method,
                clamp=options.get("clamp", "g0"), corner_angle=options.get("corner_angle"),
                protect=options.get("protect", ()), progress=prog, report=rep_path,
                **kw, **dict(options.get("method_options") or {}))
        except (CurvefairError, OSError) as exc:
            msg = _batch._err(exc)
            # a file error names the file itself (and its line)
            where = "" if msg.startswith((f"{infile}:", f"{os.path.abspath(infile)}:")) \
                else f"{infile}: "
            raise _Failure(f"{where}{msg}; nothing written") from None
    if not quiet:
        click.echo(f"wrote {out} from {infile} ({rep['n_points']} points in "
                   f"{rep['n_chunks']} chunks; read back: max deviation "
                   f"{rep['max_deviation']:.6g}, largest point move "
                   f"{rep['max_point_displacement']:.6g}; joins G2 to "
                   f"{rep['joins_g2_max']:.3g} (tolerance {rep['g2_tol']:g}); report "
                   f"{rep_path})")
        for note in rep.get("notes", []):
            click.echo(f"Warning: {out}: {note}", err=True)


# ------------------------------------------------------------------------------------------
# options of `curvefair fair` for many files
# ------------------------------------------------------------------------------------------
def _selection_options(f: Any) -> Any:
    f = click.option("--layer", multiple=True, metavar="PATTERN",
                     help="Only the curves on a layer matching PATTERN (glob, repeatable: "
                          "any matches); fair writes the others back untouched.")(f)
    f = click.option("--name", multiple=True, metavar="PATTERN",
                     help="Only the curves whose name matches PATTERN (glob, repeatable).")(f)
    f = click.option("--handle", "--id", "handle", multiple=True, metavar="PATTERN",
                     help="Only the curves whose DXF handle, Rhino object id or SVG element "
                          "id matches PATTERN (glob, repeatable).")(f)
    return f


def batch_options(f: Any) -> Any:
    f = _selection_options(f)
    f = click.option("--hold-shared", is_flag=True,
                     help="Hull networks: hold every point that coincides with a point of "
                          "another curve of the file, and where two curves cross elsewhere "
                          "the control points of the B-spline span or the vertices around "
                          "the point-data segment (station / longitudinal intersections "
                          "stay shared).")(f)
    f = click.option("--shared-distance", type=click.FloatRange(min=0), metavar="D",
                     help="--hold-shared: points closer than D coincide [default: 1e-9 times "
                          "the drawing's diagonal].")(f)
    f = click.option("--jobs", "-j", type=click.IntRange(min=1), metavar="N",
                     help="Fair N files (one file: N of its curves) at a time in separate "
                          "processes [default: the number of cores].")(f)
    f = click.option("--resume", is_flag=True,
                     help="Skip a file whose output exists and matches: its per-file report "
                          "records the same input SHA-256, the same options and the output's "
                          "SHA-256.")(f)
    f = click.option("--dry-run", is_flag=True,
                     help="Fair and print what would change (points moved, deviation, counts "
                          "before and after); write nothing.")(f)
    f = click.option("--diff", is_flag=True,
                     help="Print what changed in each curve (points moved, largest move, "
                          "deviation, inflections, curvature extrema, energy).")(f)
    f = click.option("--scheduler", metavar="ADDRESS",
                     help="Run the per-file work on this Dask distributed scheduler (e.g. "
                          "tcp://host:8786; the workers must see the same files).")(f)
    f = click.option("--chunk", type=click.IntRange(min=10), metavar="N",
                     help="Fair one point list (.csv/.txt/.xyz/.pts/.dat columns or a .npy "
                          "array) in overlapping chunks of N points, read and written in "
                          "blocks (bounded memory; for curves too large for one machine); "
                          "each chunk is certified, the file is read back within --tol. "
                          "Automatic for .npy inputs and point files over "
                          f"{AUTO_CHUNK_BYTES >> 20} MiB [default N: 5000].")(f)
    f = click.option("--overlap", type=click.IntRange(min=1), metavar="M",
                     help="--chunk: points of context on each side of a chunk [default: "
                          "64].")(f)
    f = click.option("--format", "in_format", metavar="FMT",
                     type=click.Choice(["points", "airfoil", "json", "dxf", "3dm", "svg",
                                        "iges", "step"]),
                     help="The format of '-' (stdin) and of -o - (stdout).")(f)
    return f


# ------------------------------------------------------------------------------------------
# curvefair check
# ------------------------------------------------------------------------------------------
def _threshold(value: str | None, name: str) -> float | None:
    from . import _check

    if value is None:
        return _check.THRESHOLDS[name]
    if value.strip().lower() in ("off", "none"):
        return None
    try:
        x = float(value)
    except ValueError:
        raise click.BadParameter(f"{value!r} is not a number or 'off'",
                                 param_hint="--" + name.replace("_", "-")) from None
    if not (x >= 0 and x < float("inf")):
        raise click.BadParameter(f"{value!r} must be a finite number >= 0",
                                 param_hint="--" + name.replace("_", "-"))
    return x


def _columns(ctx: Any, param: Any, value: str | None) -> tuple[int, ...] | None:
    """``--columns`` parsed as the other commands parse it."""
    from .cli import _columns_option

    return _columns_option(ctx, param, value)


@click.command("check")
@click.argument("paths", metavar="PATH...", nargs=-1, required=True)
@click.option("--format", "out_format", type=click.Choice(["text", "json", "sarif"]),
              default="text", show_default=True, help="Output format (SARIF 2.1.0 for code "
              "scanning tools).")
@click.option("--kink-angle", metavar="DEG|off",
              help="A join turning by more than DEG (and less than --corner-angle) is a kink "
                   "[default: 0.05].")
@click.option("--corner-angle", "corner", metavar="DEG|off",
              help="Joins turning by DEG or more are corners drawn on purpose [default: 10].")
@click.option("--g2-rel", metavar="R|off",
              help="Relative curvature jump at a tangent-continuous join that is a G2 break "
                   "(joins with a straight side, e.g. a line meeting a curve, are not "
                   "G2-tested) [default: 0.05].")
@click.option("--wiggle", metavar="F|off",
              help="Two inflections closer than F times the arc length are an S-wiggle "
                   "[default: 0.02].")
@click.option("--max-inflections", metavar="N|off",
              help="More inflections than N is a finding [default: off].")
@click.option("--max-bad", metavar="Z|off",
              help="A breakpoint whose Sapidis-Farin jump of dκ/ds divided by κ² + 1/L² (L "
                   "the arc length) is above Z is a bad point [default: 5000].")
@click.option("-o", "--output", "out", metavar="FILE",
              help="Write the report to FILE instead of stdout.")
@click.option("--read-corner-angle", type=click.FloatRange(0, 180, min_open=True),
              default=60.0, show_default=True, metavar="DEG",
              help="Point lists turning by DEG or more at a point are split there on reading.")
@click.option("--polylines", is_flag=True,
              help="SVG, DXF, 3dm: read straight-line shapes (polygons, polylines, lines, "
                   "rectangles; DXF LWPOLYLINE and POLYLINE; 3dm PolylineCurve) as point "
                   "lists and check them too [default: they are drawn shapes, not curves].")
@click.option("--columns", callback=lambda ctx, param, value: _columns(ctx, param, value),
              metavar="I,J[,K]",
              help="Point files: the 0-based columns holding x, y (z) [default: the columns a "
                   "header names x, y, z, else all of a 2- or 3-column file].")
@click.option("--strict", is_flag=True, help="Refuse files with entities curvefair cannot "
              "represent (default: skip them).")
@_selection_options
def check_cmd(paths: tuple[str, ...], out_format: str, kink_angle: str | None,
              corner: str | None, g2_rel: str | None, wiggle: str | None,
              max_inflections: str | None, max_bad: str | None, out: str | None,
              read_corner_angle: float, polylines: bool,
              columns: tuple[int, ...] | None, strict: bool,
              layer: tuple[str, ...],
              name: tuple[str, ...], handle: tuple[str, ...]) -> None:
    """Report curves whose fairness measures exceed thresholds; write nothing.

    Findings: kinks at joins meant to be smooth, G2 breaks (curvature jumps at tangent-
    continuous joins), extra inflections (S-wiggles), and the worst bad points. PATH: files,
    folders (every file of a known format) or glob patterns. Exit code 0: no finding; 1: at
    least one finding (or an unreadable file); 2: usage error.
    """
    from . import _check

    th = {"kink_angle": _threshold(kink_angle, "kink_angle"),
          "corner_angle": _threshold(corner, "corner_angle"),
          "g2_rel": _threshold(g2_rel, "g2_rel"), "wiggle": _threshold(wiggle, "wiggle"),
          "max_inflections": _threshold(max_inflections, "max_inflections"),
          "max_bad": _threshold(max_bad, "max_bad")}
    try:
        files = [p for p, _rel in _batch.expand_inputs(list(paths))]
    except CurvefairError as exc:
        raise click.UsageError(str(exc)) from None
    if "-" in files:
        raise click.UsageError("check reads files, not stdin")
    if out is not None:
        from .cli import _check_outputs

        _check_outputs([(f, "PATH") for f in files], [(out, "-o/--output")])
    select = {"layer": layer, "name": name, "handle": handle}
    findings: list[Any] = []
    n_curves = 0
    for f in files:
        got, n = _check.check_file(f, th, corner_angle=read_corner_angle, strict=strict,
                                   select=select, polylines=polylines, columns=columns)
        findings += got
        n_curves += n
    if out_format == "json":
        text = _check.to_json(findings, len(files), n_curves) + "\n"
    elif out_format == "sarif":
        text = json.dumps(_check.to_sarif(findings, os.getcwd()), indent=2,
                          allow_nan=False) + "\n"
    else:
        lines = []
        for x in findings:
            where = ("" if x.point is None
                     else " at (" + ", ".join(f"{v:.6g}" for v in x.point) + ")")
            who = f"curve {x.curve} ({x.label})" if x.curve >= 0 else "file"
            lines.append(f"{x.file}: {who}: {x.rule}: {x.message}{where}")
        lines.append(f"{len(files)} file(s), {n_curves} curve(s) checked: "
                     f"{len(findings)} finding(s)")
        text = "\n".join(lines) + "\n"
    if out is not None:
        from .io import atomic_write

        atomic_write(out, text)
    else:
        click.echo(text, nl=False)
    if findings:
        raise SystemExit(EXIT_INPUT)

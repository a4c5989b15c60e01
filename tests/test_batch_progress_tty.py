"""The progress bars of ``curvefair fair PATH... -o DIR`` on a real terminal (a pseudo-terminal),
and their absence when stderr is not a terminal.

The command runs in a subprocess whose stdin, stdout and stderr are the slave side of a pty
(what a user's terminal is); everything it writes there is read from the master side. Checked:
the bars were drawn (their labels, the ``done/total`` counts reaching ``3/3`` files) and then
erased (rich's transient display), the summary is printed, and the outputs are the same bytes
as those of a run with stderr on a pipe, which shows no bar at all.
"""

from __future__ import annotations

import os
import re
import select
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from curvefair import interpolate_bspline, write_curves

pty = pytest.importorskip("pty")

DATA = Path(__file__).parent / "data"
ANSI = re.compile(r"\x1b\[[0-9;?]*[A-Za-z]")


def _tree(root: Path) -> Path:
    src = root / "in"
    (src / "sub").mkdir(parents=True)
    x = np.linspace(0.0, 10.0, 40)
    y = np.sin(x / 2.0) + 0.02 * np.random.default_rng(0).standard_normal(40)
    rows = "".join(f"{a!r},{b!r}\n" for a, b in zip(x.tolist(), y.tolist(), strict=True))
    (src / "a.csv").write_text("x,y\n" + rows)
    shutil.copy(DATA / "naca2412.dat", src / "sub" / "naca2412.dat")
    write_curves(src / "sub" / "b.json", [interpolate_bspline(np.c_[x, y])])
    return src


def _env() -> dict[str, str]:
    env = dict(os.environ)
    env.update({"TERM": "xterm-256color", "COLUMNS": "120", "LINES": "40",
                "CURVEFAIR_QUIET": "1"})
    env.pop("NO_COLOR", None)
    return env


def _run_in_pty(args: list[str], cwd: Path, timeout: float = 600.0) -> tuple[int, str]:
    master, slave = pty.openpty()
    proc = subprocess.Popen(args, cwd=cwd, env=_env(), stdin=slave, stdout=slave, stderr=slave,
                            close_fds=True)
    os.close(slave)
    chunks: list[bytes] = []
    end = time.monotonic() + timeout
    while True:
        r, _, _ = select.select([master], [], [], 0.2)
        if r:
            try:
                data = os.read(master, 65536)
            except OSError:  # EIO: the child closed the terminal
                data = b""
            if not data:
                break
            chunks.append(data)
        elif proc.poll() is not None:
            break
        if time.monotonic() > end:
            proc.kill()
            pytest.fail("the command did not finish on the pseudo-terminal")
    rc = proc.wait(timeout=60)
    os.close(master)
    return rc, b"".join(chunks).decode("utf-8", "replace")


def _outputs(root: Path) -> dict[str, bytes]:
    return {str(p.relative_to(root)): p.read_bytes() for p in sorted(root.rglob("*"))
            if p.is_file() and ".curvefair" not in p.parts}


def test_bars_drawn_then_erased_on_a_terminal_and_absent_on_a_pipe(tmp_path: Path):
    _tree(tmp_path)
    cmd = [sys.executable, "-m", "curvefair", "fair", "in", "-o", "tty", "--tol", "0.05",
           "-j", "1", "--method", "airfoil=poliakoff"]
    rc, text = _run_in_pty(cmd, tmp_path)
    assert rc == 0, text
    plain = ANSI.sub("", text)
    # drawn: both bars' labels and the files count reaching the total
    assert "files" in plain and "curves" in plain, plain
    assert re.search(r"\b3/3\b", plain), plain
    # erased at the end (transient): the cursor-up / erase-line sequences rich uses, after the
    # last bar frame
    last_bar = text.rfind("3/3")
    assert re.search(r"\x1b\[(2K|1A|\?25h)", text[last_bar:]), repr(text[last_bar:][:400])
    # the same outputs as with stderr on a pipe (no terminal: no bars)
    pipe = subprocess.run([*cmd[:6], "pipe", *cmd[7:]], cwd=tmp_path, env=_env(),
                          capture_output=True, text=True, timeout=600)
    assert pipe.returncode == 0, pipe.stderr
    assert "\x1b[" not in pipe.stderr and "3/3" not in pipe.stderr
    assert _outputs(tmp_path / "tty") == _outputs(tmp_path / "pipe")
    assert len(_outputs(tmp_path / "tty")) == 3

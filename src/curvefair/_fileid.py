"""File identity for the output-path checks of the CLI and of many-file runs."""

from __future__ import annotations

import os
from typing import Any


def file_key(path: str) -> tuple[Any, ...]:
    """What identifies the file ``path`` names: device and inode of an existing file (any
    spelling, symbolic or hard link), else the resolved absolute path."""
    real = os.path.realpath(path)
    try:
        st = os.stat(real)
    except OSError:
        return ("path", os.path.normcase(real))
    return ("inode", st.st_dev, st.st_ino)

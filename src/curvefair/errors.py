"""Errors raised by curvefair.

Every error curvefair raises on purpose derives from :class:`CurvefairError`, which is a
:class:`ValueError`, so ``except ValueError`` keeps working in code that does not know curvefair.
"""

from __future__ import annotations

__all__ = [
    "CurvefairError",
    "InputError",
    "FileFormatError",
    "MissingDependencyError",
]


class CurvefairError(ValueError):
    """Base class of every error raised by curvefair."""


class InputError(CurvefairError):
    """An argument is malformed: wrong shape, NaN/inf, too few points, bad name, ...

    The message names the argument and, where it applies, the offending index and value.
    """


class FileFormatError(CurvefairError):
    """A file cannot be read as the format it claims to be.

    Attributes
    ----------
    path : str or None
        The file.
    line : int or None
        1-based line number for text formats, when known.
    """

    def __init__(self, message: str, path: object = None, line: int | None = None) -> None:
        self.path = None if path is None else str(path)
        self.line = None if line is None else int(line)  # a numpy integer too
        line = self.line
        where = ""
        if self.path is not None:
            where = self.path + (f":{line}" if line is not None else "") + ": "
        super().__init__(where + message)


class MissingDependencyError(CurvefairError, ImportError):
    """An optional dependency is not installed; the message names the extra to install."""

    def __init__(self, package: str, extra: str, what: str) -> None:
        super().__init__(
            f"{what} needs the optional package {package!r}: "
            f"pip install 'curvefair[{extra}]'"
        )
        self.package = package
        self.extra = extra

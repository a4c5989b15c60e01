"""``python -m curvefair``: the same as the ``curvefair`` command."""

from .cli import main

if __name__ == "__main__":  # pragma: no cover
    main(prog_name="curvefair")

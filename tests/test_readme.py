"""The README's worked example runs and prints what its comments claim (docs stay honest)."""

import contextlib
import io
import re
from pathlib import Path

import numpy as np

README = Path(__file__).resolve().parents[1] / "README.md"


def test_readme_example_matches_its_comments():
    text = README.read_text()
    block = re.search(r"```python\n(.*?)```", text, re.S).group(1)
    expected = []
    for line in block.splitlines():
        if line.startswith("print(") and "#" in line:
            expected.append(line.split("#", 1)[1].strip())
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        exec(compile(block, "README.md", "exec"), {})
    printed = buf.getvalue().strip().splitlines()
    assert len(printed) == len(expected)
    num = re.compile(r"-?\d+(?:\.\d+)?(?:e-?\d+)?")
    for got, want in zip(printed, expected, strict=True):
        want_nums = [float(x) for x in num.findall(want)]
        got_nums = [float(x) for x in num.findall(got.replace("[", " ").replace("]", " "))]
        assert len(got_nums) == len(want_nums), (got, want)
        for g, w in zip(got_nums, want_nums, strict=True):
            digits = len(str(w).split(".")[1]) if "." in str(w) else 0
            assert np.isclose(g, w, rtol=0, atol=0.51 * 10.0**-digits), (got, want)
        want_words = re.sub(num, "", want).split()
        for word in want_words:
            assert word in got, (got, want)

"""The compiled reader of a points file's bulk rows (:mod:`curvefair._kernels.text`) against
its slow reference (``str.split``, ``re`` and Python's ``float``): the same values bit for bit,
the same decimals per column, the same blocks refused."""

from __future__ import annotations

import numpy as np
import pytest

from curvefair._kernels.text import plain_rows_reference, scan_plain_rows


@pytest.fixture(params=[False, True], ids=["whole", "halves"])
def halves(request, monkeypatch):
    """Long blocks as they run on two threads (cut in two halves from 2 rows on,
    ``io._text._row_halves``), or whole."""
    if request.param:
        from curvefair import _threads
        from curvefair.io import _text

        monkeypatch.setattr(_threads, "THREADS", 2)
        monkeypatch.setattr(_text, "_HALVES_MIN_ROWS", 2)
    return request.param


def _scan(text: str, sep: str, width: int):
    from curvefair.io._text import _scan_rows

    buf = np.frombuffer(text.encode("utf-8"), dtype=np.uint8)
    nrows = text.count("\n") + 1
    values = np.empty(nrows * width)
    col_dec = np.zeros(width, dtype=np.int64)
    s0 = np.empty(nrows * width, dtype=np.int64)
    s1 = np.empty(nrows * width, dtype=np.int64)
    nslow = _scan_rows(buf, ord(sep), width, nrows, values, col_dec, s0, s1)
    if nslow < 0:
        return None
    raw = text.encode("utf-8")
    values[np.isnan(values)] = [float(raw[a:b]) for a, b in
                               zip(s0[:nslow], s1[:nslow], strict=True)]
    return values, col_dec.tolist(), nslow


def _number(rng: np.random.Generator) -> str:
    """A number text of every style the grammar has: plain, bare point, trailing point,
    signed, exponent (either case, signed), long mantissas past 2^53, leading zeros, tiny and
    huge magnitudes (subnormal, overflow to inf), exact halfway cases of the fast path's
    limits."""
    u = rng.random()
    if u < 0.3:
        return f"{rng.normal() * 10.0 ** rng.integers(-6, 7):.{rng.integers(0, 12)}f}"
    if u < 0.45:
        return repr(float(rng.normal() * 10.0 ** rng.integers(-30, 30)))
    if u < 0.55:
        digits = "".join(rng.choice(list("0123456789"), size=rng.integers(1, 25)))
        point = rng.integers(0, len(digits) + 1)
        s = digits[:point] + "." + digits[point:]
        return s if s != "." else "0."
    if u < 0.65:
        mant = f"{rng.integers(0, 10 ** 6)}.{rng.integers(0, 10 ** 4)}"
        return (rng.choice(["", "+", "-"]) + mant + rng.choice(["e", "E"])
                + rng.choice(["", "+", "-"]) + str(rng.integers(0, 40)))
    if u < 0.75:
        return str(rng.choice(["9007199254740993", "9007199254740992.0", "1e22", "1e23",
                               "123456789012345678901234567890", "4.9e-324", "1e-400",
                               "1e400", "-0.0", "+0", "0.000", ".5", "-.5e-3", "5.", "-5.e2",
                               "00000000000000000000001.5", "1.7976931348623157e308",
                               "2.2250738585072014e-308", "0.1e-22", "1e-22", "123e-25"]))
    return str(int(rng.integers(-10 ** 9, 10 ** 9)))


@pytest.mark.parametrize("sep", [",", ";", " ", "\t"])
@pytest.mark.parametrize("width", [2, 3])
def test_values_and_decimals_are_pythons(sep, width, halves):
    rng = np.random.default_rng(width * 10 + ord(sep))
    rows = [sep.join(_number(rng) for _ in range(width)) for _ in range(3000)]
    text = "\n".join(rows)
    got = _scan(text, sep, width)
    ref = plain_rows_reference(text, sep, width)
    assert got is not None and ref is not None
    values, dec, nslow = got
    assert values.tobytes() == ref[0].tobytes()  # bit for bit, signed zeros and infinities too
    assert dec == ref[1]
    assert 0 < nslow < values.size // 2  # both paths were taken


@pytest.mark.parametrize("bad", ["1.0,abc", "1.0,,2.0", "1.0", "1.0,2.0,3.0", "", ",1.0",
                                 "1.0, 2.0", "1e,2.0", "1e+,2.0", "-,2.0", ".,2.0",
                                 "1.0,2.0,", "nan,1.0", "inf,1.0", "1.2.3,4", "--1,2",
                                 "e5,1", "1.0;2.0", "1.0\r,2.0", "1\u00e9,2", "+-1,2", "1e5.0,2"])
def test_refuses_what_the_reference_refuses(bad, halves):
    rng = np.random.default_rng(5)
    for where in (20, 24, 25, 49) if halves else (20,):  # (halves: rows 0-24 and 25-49)
        rows = [f"{rng.normal():.6f},{rng.normal():.6f}" for _ in range(50)]
        rows[where] = bad
        text = "\n".join(rows)
        assert plain_rows_reference(text, ",", 2) is None
        assert _scan(text, ",", 2) is None


def test_last_row_and_row_count():
    """The block ends exactly after its last number: a final newline or a missing row is not
    rows of this layout."""
    assert _scan("1,2\n3,4", ",", 2)[0].tolist() == [1, 2, 3, 4]
    buf = np.frombuffer(b"1,2\n3,4\n", dtype=np.uint8)
    out = np.empty(4)
    dec = np.zeros(2, dtype=np.int64)
    idx = np.empty(4, dtype=np.int64)
    assert scan_plain_rows(buf, ord(","), 2, 2, out, dec, idx, idx.copy()) == -1
    buf = np.frombuffer(b"1,2", dtype=np.uint8)
    assert scan_plain_rows(buf, ord(","), 2, 2, out, dec, idx, idx.copy()) == -1


@pytest.mark.parametrize("sep", [",", " ", "\t"])
def test_block_writer_at_the_fast_paths_edges(tmp_path, monkeypatch, sep, halves):
    """Rows rewritten by the compiled block writer against the row renderer (every row by
    :func:`curvefair.io._text._render_line`), with values at the edges of the writer's exact
    test: decimals at and around ``|v| 10**d = 2**49``, halfway and one-ulp-off decimals,
    signed zeros and tiny negatives, large and tiny magnitudes, values exact only at the
    column's decimals."""
    from curvefair.io import _text
    from curvefair.io._text import parse_text

    rng = np.random.default_rng(ord(sep))
    n = 2000
    d = rng.integers(1, 9, size=(n, 2))
    text = "\n".join(sep.join(f"{rng.normal() * 100:.{d[i, j]}f}" for j in range(2))
                     for i in range(n)) + "\n"
    path = tmp_path / "p.txt"
    path.write_text(text)
    lay = parse_text(path, header=False, ncols=None)
    new = lay.values.copy()
    for i in range(n):
        for j in range(2):
            u = rng.integers(0, 10)
            dd = int(d[i, j])
            if u == 0:
                kk = 2 ** 49 + int(rng.integers(-3, 4))       # at the fast path's bound
                new[i, j] = kk / 10.0 ** dd * rng.choice([-1, 1])
            elif u == 1:
                new[i, j] = np.nextafter(float(f"{new[i, j] + 1:.{dd}f}"), np.inf)  # 1 ulp off
            elif u == 2:
                new[i, j] = float(f"{new[i, j] + 0.5:.{dd}f}") + 0.5 * 10.0 ** -dd  # halfway
            elif u == 3:
                new[i, j] = float(rng.choice([-0.0, 0.0, -1e-300, 5e-324, -2.5e-9]))
            elif u == 4:
                new[i, j] = float(f"{rng.normal() * 1e9:.{lay.column_decimals[j]}f}")
            elif u == 5:
                new[i, j] = rng.normal() * 10.0 ** rng.integers(-20, 20)
            elif u == 6:
                new[i, j] = float(f"{rng.normal():.{int(rng.integers(0, 12))}f}")
    fast = lay.render(new)
    monkeypatch.setattr(_text, "_BLOCK_MIN_ROWS", 10 ** 12)
    assert fast == lay.render(new)
    if halves:  # the halves' texts are also those of the whole block, and their values read
        monkeypatch.setattr(_text, "_HALVES_MIN_ROWS", 10 ** 12)
        monkeypatch.setattr(_text, "_BLOCK_MIN_ROWS", 0)
        assert fast == lay.render(new)
        lay2 = parse_text(path, header=False, ncols=None)
        assert lay2.values.tobytes() == lay.values.tobytes()
        assert lay2.column_decimals == lay.column_decimals
    back = tmp_path / "back.txt"
    back.write_text(fast)
    np.testing.assert_array_equal(parse_text(back, header=False, ncols=None).values, new)


def test_long_mantissas_are_rounded_once():
    """The mantissas past 2^53 (Python's 17-digit ``repr``, up to 18 digits) divided by
    ``10**q`` with one rounding: random mantissas and every ``q`` of the range, exact halves
    between two floats (ties to even) and their neighbours, against Python's ``float``."""
    from curvefair._kernels.text import _long_quotient

    rng = np.random.default_rng(11)
    cases = [(int(m), int(q)) for m, q in zip(rng.integers(2 ** 53 + 1, 10 ** 18, size=20000),
                                              rng.integers(0, 23, size=20000), strict=True)]
    for base in (2 ** 54, 2 ** 55, 2 ** 58, 3 * 2 ** 55):
        for odd in range(1, 40, 2):
            cases += [(base + odd, 0), (base + odd - 1, 0), (base + odd + 1, 0)]
    for m in (9007199254740993, 18014398509481985, 18014398509481987, 999999999999999999,
              123456789012345678, 100000000000000001):
        cases += [(m, q) for q in range(23)]
    for m, q in cases:
        assert _long_quotient(m, q) == float(f"{m}e-{q}"), (m, q)
    # and through the reader: 17-digit texts of random floats, bit for bit
    vals = rng.normal(size=5000) * 10.0 ** rng.integers(-4, 8, size=5000)
    text = "\n".join(f"{float(a)!r},{float(b)!r}" for a, b in zip(vals, -vals, strict=True))
    text = text.replace("e", "E")  # no exponent form is ever kept out of the check
    got = _scan(text, ",", 2)
    assert got is not None
    assert got[0].tobytes() == np.ravel(np.c_[vals, -vals]).tobytes()


def test_shortest_form_is_pythons_repr():
    """The writer's compiled shortest form (:func:`shortest_decimal`, :func:`write_shortest`)
    against Python's ``repr`` (with :func:`curvefair.io._text._shortest`'s ``.0`` dropped),
    character for character, wherever the kernel decides it: random magnitudes over the whole
    range, short decimals, neighbours of short decimals one unit in the last place away,
    powers of ten and their neighbours, the range's ends; the values it leaves to Python are
    only those out of its range, power-of-two significands and ties."""
    from curvefair._kernels.text import shortest_decimal, shortest_length, write_shortest
    from curvefair.io._text import _shortest

    rng = np.random.default_rng(12)
    n = 60000
    short = [float(f"{x:.{k}f}") for x, k in zip(rng.normal(size=n) * 1000,
                                                 rng.integers(0, 10, size=n), strict=True)]
    tens = [10.0 ** e for e in range(-4, 15)]
    vals = np.concatenate([
        rng.normal(size=n) * 10.0 ** rng.integers(-5, 16, size=n),
        rng.random(n), short, np.nextafter(short, np.inf), np.nextafter(short, -np.inf),
        tens, np.nextafter(tens, 0), np.nextafter(tens, np.inf), np.arange(1, 3000) / 7.0,
        [1e-4, np.nextafter(1e-4, 0), 9.999999999999999e14, 1e15, 0.1, 0.2, 0.3, 2 / 3]])
    vals = np.concatenate([vals, -vals])
    buf = np.empty(64, dtype=np.uint8)
    fast = 0
    for v in vals.tolist():
        ok, d, kk, nd = shortest_decimal(v)
        a = abs(v)
        if not ok:
            frac = np.frexp(a)[0]
            assert (not 1e-4 <= a < 1e15) or frac == 0.5 or len(repr(v).strip("-")) >= 17, v
            continue
        fast += 1
        end = write_shortest(buf, 0, v, d, kk, nd)
        assert end == shortest_length(v, d, kk, nd)
        assert buf[:end].tobytes().decode() == _shortest(v), v
    assert fast > 0.8 * len(vals)


@pytest.mark.parametrize("newline", ["\n", "\r\n", "\r"])
@pytest.mark.parametrize("final", [True, False])
@pytest.mark.parametrize("around", [False, True])
def test_whole_block_render_is_the_row_renderers(tmp_path, monkeypatch, newline, final, around,
                                                halves):
    """A file whose data rows are one run of plain lines is rendered as one block, unchanged
    rows included, the header and any lines after the data joined around it: the same text as
    the row renderer, for every line ending, with and without a final newline, with comment
    and blank lines before and after the data; a row that is not plain sends the file back to
    the line-by-line path (the same text again)."""
    from curvefair.io import _text
    from curvefair.io._text import parse_text

    rng = np.random.default_rng(len(newline) + 2 * final + 4 * around)
    rows = [f"{x:.6f},{y:.4f}" for x, y in rng.normal(size=(300, 2)) * 10]
    lines = (["# exported", "x,y"] if around else ["x,y"]) + rows
    if around:
        lines += ["", "# end of data"]
    path = tmp_path / "p.csv"
    path.write_bytes((newline.join(lines) + (newline if final else "")).encode())
    lay = parse_text(path)
    for odd in (False, True):
        new = lay.values.copy()
        moved = rng.random(len(new)) < 0.7
        new[moved] += rng.normal(size=(moved.sum(), 2)) * 1e-3
        new[5] = [float(f"{new[5, 0]:.6f}"), float(f"{new[5, 1]:.4f}")]
        if odd:
            new[7, 0] = np.nan                     # not a plain row: the line-by-line path
        fast = lay.render(new)
        with monkeypatch.context() as mp:
            mp.setattr(_text, "_BLOCK_MIN_ROWS", 10 ** 12)
            slow = lay.render(new)
        assert fast == slow
        assert fast.count(newline) == path.read_bytes().decode().count(newline)

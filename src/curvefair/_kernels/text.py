"""Compiled kernels of the numeric text files' bulk rows (:mod:`curvefair.io._text`).

A points file of a million rows is a million lines of the same layout: numbers joined by one
separator character. :func:`scan_plain_rows` reads such a block from its bytes in one pass
(the checks, the values, the decimals per column), where the Python reader made two million
string objects; :func:`plain_rows_reference` is the same reading by Python's ``str.split``
and ``float``, the slow reference it is tested against.

Values: a number whose decimal mantissa ``M`` (all its digits, the point ignored) is at most
2^53 and whose decimal exponent ``e`` (the written exponent minus the digits after the point)
is within [-22, 22] is ``M * 10**e`` or ``M / 10**-e`` with ``10**|e|`` exact: one correctly
rounded IEEE operation on exact operands, hence the correctly rounded value of the text, the
one Python's ``float`` gives (Clinger 1990, "How to read floating point numbers accurately",
the fast path). A number of up to 18 digits, ``e`` in [-22, 0], whose mantissa is larger
(the 17 digits of Python's ``repr``) is the quotient of two integers rounded once
(:func:`_long_quotient`). Every other number is left to Python's ``float`` (its position
returned).
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import njit

# 10**k exactly, k = 0..22 (every power up to 22 is a float64 without rounding: 5**22 < 2**53)
POW10 = np.array([float(10 ** k) for k in range(23)])
_TWO53 = 2 ** 53
_MANT_CAP = 10 ** 17  # digits beyond this are not accumulated (the number goes to Python)


# 5**q exactly, q = 0..22 (5**22 < 2**52)
POW5 = np.array([5 ** q for q in range(23)], dtype=np.int64)


@njit(cache=True)
def _long_quotient(mant, q):
    """The float nearest ``mant / 10**q`` (ties to even) for ``2**53 < mant < 10**18`` and
    ``0 <= q <= 22``, the 17-digit numbers of Python's ``repr``: ``mant / 10**q =
    (mant / 5**q) 2**-q``, and the quotient by ``D = 5**q < 2**52`` is computed by long
    division to ``Q = floor(mant 2**s / D)`` with at least 55 bits and the remainder ``r``;
    ``Q`` is rounded to 53 bits (a discarded half with ``r > 0`` rounds up, an exact half to
    even) and scaled by ``2**-(s + q)`` (exact: no result is near the subnormal range)."""
    d = POW5[q]
    quo = mant // d
    r = mant - quo * d
    s = 0
    while quo < (1 << 54):
        r2 = r + r
        bit = 1 if r2 >= d else 0
        quo = quo + quo + bit
        r = r2 - bit * d
        s += 1
    nbits = 0
    x = quo
    while x > 0:
        nbits += 1
        x >>= 1
    shift = nbits - 53
    top = quo >> shift
    rest = quo - (top << shift)
    half = np.int64(1) << (shift - 1)
    if rest > half or (rest == half and (r != 0 or (top & 1) == 1)):
        top += 1
    return math.ldexp(float(top), shift - s - q)


@njit(cache=True)
def scan_plain_rows(buf, sep, width, nrows, values, col_dec, slow_start, slow_end):
    """Read ``nrows`` rows of ``width`` numbers from ``buf`` (uint8: the rows' text joined by
    ``\\n``, no final newline), every row its numbers joined by the one byte ``sep`` and
    nothing else, every number ``[+-]?(\\d+\\.?\\d*|\\.\\d+)([eE][+-]?\\d+)?`` (what Python's
    ``float`` reads over these characters).

    Fills ``values`` (``nrows * width``, row after row; NaN where Python must read the
    number), ``col_dec`` (the largest number of decimals per column: digits between the point
    and the end of the mantissa) and the byte ranges of the numbers left to Python in
    ``slow_start`` / ``slow_end``. Returns the count of those, or -1 when the block is not
    such rows (then nothing filled is meaningful).
    """
    n = buf.shape[0]
    pos = 0
    tok = 0
    nslow = 0
    for c in range(width):
        col_dec[c] = 0
    for r in range(nrows):
        for c in range(width):
            start = pos
            neg = False
            if pos < n and (buf[pos] == 43 or buf[pos] == 45):  # + -
                neg = buf[pos] == 45
                pos += 1
            mant = 0
            big = False
            ndig = 0
            frac = 0
            point = -1
            while pos < n and 48 <= buf[pos] <= 57:
                if mant < _MANT_CAP:
                    mant = mant * 10 + (buf[pos] - 48)
                elif not big:
                    big = True
                ndig += 1
                pos += 1
            if pos < n and buf[pos] == 46:  # .
                point = pos
                pos += 1
                while pos < n and 48 <= buf[pos] <= 57:
                    if mant < _MANT_CAP:
                        mant = mant * 10 + (buf[pos] - 48)
                        frac += 1
                    elif not big:
                        big = True
                    ndig += 1
                    pos += 1
            if ndig == 0:
                return -1
            mant_end = pos
            ex = 0
            if pos < n and (buf[pos] == 101 or buf[pos] == 69):  # e E
                pos += 1
                eneg = False
                if pos < n and (buf[pos] == 43 or buf[pos] == 45):
                    eneg = buf[pos] == 45
                    pos += 1
                edig = 0
                while pos < n and 48 <= buf[pos] <= 57:
                    if ex < 100000:
                        ex = ex * 10 + (buf[pos] - 48)
                    edig += 1
                    pos += 1
                if edig == 0:
                    return -1
                if eneg:
                    ex = -ex
            if c < width - 1:
                if pos >= n or buf[pos] != sep:
                    return -1
            elif r < nrows - 1:
                if pos >= n or buf[pos] != 10:
                    return -1
            elif pos != n:
                return -1
            end = pos
            pos += 1
            if point >= 0:
                d = mant_end - point - 1
                if d > col_dec[c]:
                    col_dec[c] = d
            e10 = ex - frac
            if not big and mant <= _TWO53 and -22 <= e10 <= 22:
                v = float(mant)
                if e10 >= 0:
                    v = v * POW10[e10]
                else:
                    v = v / POW10[-e10]
                values[tok] = -v if neg else v
            elif not big and -22 <= e10 <= 0:
                v = _long_quotient(mant, -e10)
                values[tok] = -v if neg else v
            else:
                values[tok] = np.nan
                slow_start[nslow] = start
                slow_end[nslow] = end
                nslow += 1
            tok += 1
    return nslow


def plain_rows_reference(text: str, sep: str, width: int
                         ) -> tuple[np.ndarray, list[int]] | None:
    """:func:`scan_plain_rows` by Python's ``str.split``, ``re`` and ``float``: the values
    (row after row) and the decimals per column, or None when the text is not rows of ``width``
    numbers joined by ``sep``."""
    import re

    num = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
    vals: list[float] = []
    dec = [0] * width
    for line in text.split("\n"):
        parts = line.split(sep)
        if len(parts) != width:
            return None
        for c, p in enumerate(parts):
            if num.fullmatch(p) is None:
                return None
            mant = re.split("[eE]", p)[0]
            if "." in mant:
                dec[c] = max(dec[c], len(mant) - mant.index(".") - 1)
            vals.append(float(p))
    return np.array(vals), dec


# decimals of the changed numbers of a block (:func:`plain_block_plan`)
KEEP = 0      # unchanged: the token's text
FIXED = 1     # exact at the decimals in ``dec_out``: written by :func:`plain_block_write`
PYTHON = 2    # outside the fast path's range: Python decides (the row renderer's rule)
SHORTEST = 3  # exact at neither the token's nor the column's decimals: the shortest form
ODD_ROW = 4   # a row not of the plain layout (or a non-finite value): left as it is
_TWO49 = float(2 ** 49)


@njit(cache=True)
def _exact_at(v, d):
    """1 when ``v`` is written exactly with ``d`` decimals (``float('%.{d}f' % v) == v``),
    0 when not, -1 when not decided here (``d > 22`` or ``|v| 10**d >= 2**49``). Within the
    range, ``x = v 10**d`` is within 1/4 of the integer ``k`` of any d-decimal ``k 10**-d``
    that rounds to ``v``, so ``k = rint(x)``, and ``k / 10**d`` (exact operands, one rounding)
    is that decimal's float; the d-decimals are then at least 4 units in the last place
    apart, so at most one rounds to ``v`` and ``%.{d}f`` (the nearest) is it."""
    if d > 22:
        return -1
    x = v * POW10[d]
    if not abs(x) < _TWO49:
        return -1
    return 1 if np.rint(x) / POW10[d] == v else 0


@njit(cache=True)
def plain_block_plan(buf, sep, k, m, new, old, col_dec, status, dec_out, tok_start,
                     tok_len, new_len, row_ok):
    """Plan the rewrite of ``m`` rows of ``k`` plain fixed-point numbers (``buf``: the rows
    joined by ``\\n``; only digits, ``.``, ``-`` and ``sep``) with the values ``new`` (``old``:
    the values read), the rule of :func:`curvefair.io._text._render_plain_block`: a value
    equal to the one read keeps its text; a changed one is written with its token's decimals,
    else the column's (``col_dec``, when positive and not the token's), where that reads back
    as exactly the value, else in the shortest exact form. A row with a token that is not
    plain (digits before and after one point, no ``+``) or a non-finite new value is left.

    Fills per token ``status`` (:data:`KEEP` ... :data:`ODD_ROW`), ``dec_out``, ``tok_start``,
    ``tok_len`` and ``new_len`` (the written length without padding; -1 for :data:`PYTHON`
    and :data:`SHORTEST`), and ``row_ok``. Returns the number of tokens Python must write
    (:data:`PYTHON` and :data:`SHORTEST`), or -1 when ``buf`` is not ``m`` rows of ``k``
    pieces of those characters (then the caller leaves every row to the row renderer).
    """
    n = buf.shape[0]
    pos = 0
    t = 0
    npy = 0
    for r in range(m):
        ok = True
        t0 = t
        for c in range(k):
            start = pos
            point = -1
            minus = False
            while pos < n and buf[pos] != sep and buf[pos] != 10:
                b = buf[pos]
                if b == 46:
                    if point < 0:
                        point = pos - start
                elif b == 45:
                    if pos == start:
                        minus = True
                elif not (48 <= b <= 57):
                    return -1
                pos += 1
            length = pos - start
            if c < k - 1:
                if pos >= n or buf[pos] != sep:
                    return -1
            elif r < m - 1:
                if pos >= n or buf[pos] != 10:
                    return -1
            elif pos != n:
                return -1
            pos += 1
            dec = length - point - 1
            plain = point > 0 and not (point == 1 and minus) and dec > 0
            if not plain or not np.isfinite(new[t]):
                ok = False
            tok_start[t] = start
            tok_len[t] = length
            new_len[t] = length
            status[t] = KEEP
            dec_out[t] = dec
            t += 1
        row_ok[r] = ok
        for j in range(t0, t):
            if not ok:
                status[j] = ODD_ROW
                continue
            v = new[j]
            if v == old[j]:
                continue
            dt = dec_out[j]
            res = _exact_at(v, dt)
            d = dt
            if res == 0:
                cd = col_dec[j - t0]
                if cd > 0 and cd != dt:
                    res = _exact_at(v, cd)
                    d = cd
            if res == 1:
                q = np.int64(abs(np.rint(v * POW10[d])))
                neg = np.signbit(v) and (q != 0 or buf[tok_start[j]] == 45)
                digits = 1
                while q >= 10:
                    digits += 1
                    q //= 10
                if digits < d + 1:
                    digits = d + 1
                status[j] = FIXED
                dec_out[j] = d
                new_len[j] = digits + 1 + (1 if neg else 0)
            else:
                status[j] = PYTHON if res == -1 else SHORTEST
                new_len[j] = -1
                npy += 1
    return npy


@njit(cache=True)
def _shortest_pieces(short_buf, nshort):
    """Start and length of each of the ``nshort`` numbers in ``short_buf`` (the text of
    Python's ``repr`` of a list of floats without its brackets: ``1.5, -0.0, 2.0``), each
    made the shortest form of :func:`curvefair.io._text._shortest`: a ``.0`` ending dropped,
    then ``-0`` written ``0``."""
    start = np.empty(nshort, dtype=np.int64)
    length = np.empty(nshort, dtype=np.int64)
    size = short_buf.shape[0]
    a = 0
    for i in range(nshort):
        p = a
        while p < size and short_buf[p] != 44:  # a float's repr has no comma
            p += 1
        ln = p - a
        if ln >= 2 and short_buf[a + ln - 2] == 46 and short_buf[a + ln - 1] == 48:
            ln -= 2
        if ln == 2 and short_buf[a] == 45 and short_buf[a + 1] == 48:
            a += 1
            ln = 1
        start[i] = a
        length[i] = ln
        a = p + 2
    return start, length


@njit(cache=True)
def plain_block_write(buf, sep, k, m, new, status, dec_out, tok_start, tok_len, new_len,
                      short_buf, nshort, py_buf, py_start):
    """The rows planned by :func:`plain_block_plan`, as bytes joined by ``\\n``: kept tokens
    and odd rows copied, :data:`FIXED` ones written digit by digit (the decimal ``k 10**-d``
    of :func:`_exact_at`, a minus where the value is negative and not a zero the token wrote
    without one), the :data:`SHORTEST` ones from ``short_buf`` (Python's ``repr`` of their
    list, :func:`_shortest_pieces`), the :data:`PYTHON` ones from ``py_buf`` (number ``i`` of
    them at ``py_start[i]:py_start[i + 1]``), both in token order; with a blank or tab
    separator a changed number shorter than the text it replaces gets the blanks it gave up
    in front (not the first of a row), so right-aligned columns stay aligned."""
    blank = sep == 32 or sep == 9
    s_start, s_len = _shortest_pieces(short_buf, nshort)
    total = 0
    t = 0
    ip = 0
    js = 0
    for _r in range(m):
        for c in range(k):
            st = status[t]
            ln = new_len[t]
            if st == PYTHON:
                ln = py_start[ip + 1] - py_start[ip]
                ip += 1
            elif st == SHORTEST:
                ln = s_len[js]
                js += 1
            if blank and c > 0 and st != KEEP and st != ODD_ROW and ln < tok_len[t]:
                ln = tok_len[t]
            total += ln + 1
            t += 1
    out = np.empty(max(total - 1, 0), dtype=np.uint8)
    w = 0
    t = 0
    ip = 0
    js = 0
    for r in range(m):
        for c in range(k):
            st = status[t]
            a = tok_start[t]
            if st == KEEP or st == ODD_ROW:
                for i in range(tok_len[t]):
                    out[w] = buf[a + i]
                    w += 1
            else:
                if st == FIXED:
                    ln = new_len[t]
                elif st == PYTHON:
                    ln = py_start[ip + 1] - py_start[ip]
                else:
                    ln = s_len[js]
                if blank and c > 0 and ln < tok_len[t]:
                    for _ in range(tok_len[t] - ln):
                        out[w] = sep
                        w += 1
                if st == FIXED:
                    d = dec_out[t]
                    v = new[t]
                    q = np.int64(abs(np.rint(v * POW10[d])))
                    neg = np.signbit(v) and (q != 0 or buf[a] == 45)
                    j = w + ln - 1
                    for _ in range(d):
                        out[j] = 48 + q % 10
                        q //= 10
                        j -= 1
                    out[j] = 46
                    j -= 1
                    while True:  # the integer part: at least one digit
                        out[j] = 48 + q % 10
                        q //= 10
                        j -= 1
                        if q == 0:
                            break
                    if neg:
                        out[j] = 45
                    w += ln
                elif st == PYTHON:
                    src = py_start[ip]
                    for i in range(ln):
                        out[w] = py_buf[src + i]
                        w += 1
                    ip += 1
                else:
                    src = s_start[js]
                    for i in range(ln):
                        out[w] = short_buf[src + i]
                        w += 1
                    js += 1
            if c < k - 1:
                out[w] = sep
                w += 1
            elif r < m - 1:
                out[w] = 10
                w += 1
            t += 1
    return out

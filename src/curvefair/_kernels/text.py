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

Rewriting the block (:func:`plain_block_plan`, :func:`plain_block_write`): a changed number is
written with its token's or its column's decimals where that is exact (decided exactly, see
:func:`_exact_at`), else in the shortest form Python's ``repr`` gives, which
:func:`shortest_decimal` computes with exact integer arithmetic for ``1e-4 <= |v| < 1e15``
(the rest, and the rare values it does not decide, by ``repr`` itself). The writer is tested
against the row renderer of :mod:`curvefair.io._text` and ``repr``, character for character.
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import njit

# 10**k exactly, k = 0..22 (every power up to 22 is a float64 without rounding: 5**22 < 2**53)
POW10 = np.array([float(10 ** k) for k in range(23)])
_TWO53 = 2 ** 53
_MANT_CAP = 10 ** 17  # digits beyond this are not accumulated (the number goes to Python)


@njit(cache=True, inline="always")
def _bit_length(x):
    """Bits of the integer ``0 <= x < 2**63``: the binary exponent of ``float(x)``, one less
    where the conversion rounded up to the next power of two."""
    if x == 0:
        return 0
    n = math.frexp(float(x))[1]
    if (x >> (n - 1)) == 0:
        n -= 1
    return n


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
    room = 62 - _bit_length(d)  # r < d: r 2**room stays below 2**62
    while quo < (np.int64(1) << 54):
        t = min(room, 55 - _bit_length(quo))  # quo 2**t below 2**55
        rr = r << t
        bits = rr // d
        r = rr - bits * d
        quo = (quo << t) + bits
        s += t
    nbits = _bit_length(quo)
    shift = nbits - 53
    top = quo >> shift
    rest = quo - (top << shift)
    half = np.int64(1) << (shift - 1)
    if rest > half or (rest == half and (r != 0 or (top & 1) == 1)):
        top += 1
    return math.ldexp(float(top), shift - s - q)


@njit(cache=True, inline="always")
def _piece_ends(buf, pos, sep, c, width, r, nrows):
    """Whether the piece of column ``c`` of row ``r`` ends at ``pos`` as the layout wants:
    at the separator (not the last column), at ``\\n`` (the last column of every row but
    the last), at the end of ``buf`` (the last row's last column)."""
    n = buf.shape[0]
    if c < width - 1:
        return pos < n and buf[pos] == sep
    if r < nrows - 1:
        return pos < n and buf[pos] == 10
    return pos == n


@njit(cache=True)
def row_start(buf, r):
    """Byte offset in ``buf`` (rows joined by ``\\n``) of row ``r``'s first byte: just past
    the ``r``-th newline (0 for row 0), or -1 if ``buf`` has fewer. Where a block is cut in
    two for two threads (:func:`curvefair.io._text._row_halves`)."""
    if r == 0:
        return 0
    cnt = 0
    for i in range(buf.shape[0]):
        if buf[i] == 10:
            cnt += 1
            if cnt == r:
                return i + 1
    return -1


@njit(cache=True, nogil=True)
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
            if not _piece_ends(buf, pos, sep, c, width, r, nrows):
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


_MASK26 = (1 << 26) - 1
# 10**p as integers, p = 0..18
IPOW10 = np.array([10 ** p for p in range(19)], dtype=np.int64)


@njit(cache=True, inline="always")
def _limb(j, l0, l1, l2, l3, l4, l5):
    if j == 0:
        return l0
    if j == 1:
        return l1
    if j == 2:
        return l2
    if j == 3:
        return l3
    if j == 4:
        return l4
    return l5


@njit(cache=True)
def _scaled_floor(mant, s, k):
    """``floor(mant 5**s / 2**k)`` for ``mant < 2**53``, ``0 <= s <= 22``, ``k >= 0``, with
    the bit just below it (``half``) and whether any bit below that is set (``sticky``):
    the product held exactly in six 26-bit limbs (each partial product below 2**54).
    ``ok`` is False when the floor would not fit in 60 bits."""
    f = POW5[s]
    a0 = mant & _MASK26
    a1 = (mant >> 26) & _MASK26
    a2 = mant >> 52
    b0 = f & _MASK26
    b1 = f >> 26
    c = a0 * b0
    l0 = c & _MASK26
    c = (c >> 26) + a0 * b1 + a1 * b0
    l1 = c & _MASK26
    c = (c >> 26) + a1 * b1 + a2 * b0
    l2 = c & _MASK26
    c = (c >> 26) + a2 * b1
    l3 = c & _MASK26
    c = c >> 26
    l4 = c & _MASK26
    l5 = c >> 26
    q = k // 26
    r = k - 26 * q
    if q > 5:
        return False, np.int64(0), np.int64(0), False
    out = _limb(q, l0, l1, l2, l3, l4, l5) >> r
    for j in range(q + 1, 6):
        lj = _limb(j, l0, l1, l2, l3, l4, l5)
        if lj != 0:
            sh = 26 * (j - q) - r
            if sh >= 60 or (lj >> (60 - sh)) != 0:
                return False, np.int64(0), np.int64(0), False
            out += lj << sh
    if k == 0:
        return True, out, np.int64(0), False
    hq = (k - 1) // 26
    hr = k - 1 - 26 * hq
    lh = _limb(hq, l0, l1, l2, l3, l4, l5)
    half = (lh >> hr) & 1
    sticky = (lh & ((np.int64(1) << hr) - 1)) != 0
    for j in range(hq):
        if _limb(j, l0, l1, l2, l3, l4, l5) != 0:
            sticky = True
    return True, out, half, sticky


@njit(cache=True)
def shortest_decimal(v):
    """The digits ``D`` (an integer of ``nd`` digits, no trailing zero) and the decimal
    exponent ``K`` (``|v|`` is about ``D 10**(K - nd + 1)``) of Python's ``repr(v)``, the
    shortest decimal that reads back as ``v`` (the nearest of that length), for ``1e-4 <=
    |v| < 1e15`` (where ``repr`` writes positional notation); ``ok`` False where this does
    not decide it (out of range, a power-of-two significand, whose rounding interval is
    lopsided, a tie at some length): Python's ``repr`` then.

    ``v = M 2**E`` (``M`` the 53-bit significand). For ``p`` = 15, 16, 17 the nearest
    ``p``-digit decimal is ``round(M 5**s 2**(E + s))``, ``s = p - 1 - K``, computed exactly
    (:func:`_scaled_floor`); it reads back as ``v`` -- checked exactly, by the reader's own
    exact conversions -- for some ``p <= 17``. Every decimal of at most 15 digits reads back
    as a float that rounds back to it at 15 digits, so a shorter decimal that reads back as
    ``v`` is the 15-digit one without its trailing zeros; a 16- or 17-digit one that reads
    back is the nearest of its length."""
    a = abs(v)
    if not (1e-4 <= a < 1e15):
        return False, 0, 0, 0
    mant_f, ex = math.frexp(a)  # a = mant_f 2**ex, 0.5 <= mant_f < 1
    mant = np.int64(math.ldexp(mant_f, 53))
    e2 = ex - 53
    if mant == (np.int64(1) << 52):
        return False, 0, 0, 0
    k10 = np.int64(math.floor(math.log10(a)))
    for p in range(15, 18):
        d = np.int64(0)
        half = 0
        sticky = False
        found = False
        for _ in range(3):  # the estimate of K is off by one at most
            s = p - 1 - k10
            if s < 0 or s > 22 or e2 + s > 0:
                return False, 0, 0, 0
            ok, d, half, sticky = _scaled_floor(mant, s, -(e2 + s))
            if not ok:
                return False, 0, 0, 0
            if d >= IPOW10[p]:
                k10 += 1
            elif d < IPOW10[p - 1]:
                k10 -= 1
            else:
                found = True
                break
        if not found:
            return False, 0, 0, 0
        if half == 1 and not sticky:
            return False, 0, 0, 0  # a tie: repr's own rule
        if half == 1:
            d += 1
        kk = k10
        s = p - 1 - kk
        if d == IPOW10[p]:
            d = IPOW10[p - 1]
            kk += 1
            s -= 1
            if s < 0:
                return False, 0, 0, 0
        if d <= _TWO53:
            back = float(d) / POW10[s]
        else:
            back = _long_quotient(d, s)
        if back == a:
            nd = p
            while d % 10 == 0:
                d //= 10
                nd -= 1
            return True, d, kk, nd
    return False, 0, 0, 0


@njit(cache=True)
def shortest_length(v, d, kk, nd):
    """Length of the text :func:`write_shortest` writes."""
    n = 1 if v < 0 else 0
    if kk >= 0:  # kk + 1 digits before the point; a point and the rest if any
        n += nd + 1 if nd > kk + 1 else kk + 1
    else:
        n += 2 + (-kk - 1) + nd
    return n


@njit(cache=True, inline="always")
def _digits_back(out, j, q, count):
    """The last ``count`` decimal digits of ``q`` written backwards from ``out[j]``; returns
    the position before them and ``q`` without them."""
    for _ in range(count):
        out[j] = 48 + q % 10
        q //= 10
        j -= 1
    return j, q


@njit(cache=True)
def write_shortest(out, w, v, d, kk, nd):
    """Write ``v`` as :func:`curvefair.io._text._shortest` does (``repr`` without a ``.0``
    ending) from :func:`shortest_decimal`'s digits at ``out[w:]``; returns the end."""
    if v < 0:
        out[w] = 45
        w += 1
    n = shortest_length(abs(v), d, kk, nd)
    end = w + n
    j = end - 1
    q = d
    if kk >= 0:
        # digits after the point: nd - (kk + 1) of them; zeros to pad the integer part
        j, q = _digits_back(out, j, q, nd - (kk + 1))
        if nd > kk + 1:
            out[j] = 46
            j -= 1
        for _ in range(kk + 1 - nd):
            out[j] = 48
            j -= 1
        _digits_back(out, j, q, j - w + 1)
    else:
        j, q = _digits_back(out, j, q, nd)
        while j > w + 1:
            out[j] = 48
            j -= 1
        out[w + 1] = 46
        out[w] = 48
    return end


# decimals of the changed numbers of a block (:func:`plain_block_plan`)
KEEP = 0      # unchanged: the token's text
FIXED = 1     # exact at the decimals in ``dec_out``: written by :func:`plain_block_write`
PYTHON = 2    # outside the fast path's range: Python decides (the row renderer's rule)
SHORTEST = 3  # exact at neither the token's nor the column's decimals: Python's shortest form
ODD_ROW = 4   # a row not of the plain layout (or a non-finite value): left as it is
SHORT = 5     # the shortest form, its digits from :func:`shortest_decimal` (in ``digits``)
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


@njit(cache=True, nogil=True)
def plain_block_plan(buf, sep, k, m, new, old, col_dec, status, dec_out, tok_start,
                     tok_len, new_len, row_ok, digits):
    """Plan the rewrite of ``m`` rows of ``k`` plain fixed-point numbers (``buf``: the rows
    joined by ``\\n``; only digits, ``.``, ``-`` and ``sep``) with the values ``new`` (``old``:
    the values read), the rule of :func:`curvefair.io._text._render_plain_block`: a value
    equal to the one read keeps its text; a changed one is written with its token's decimals,
    else the column's (``col_dec``, when positive and not the token's), where that reads back
    as exactly the value, else in the shortest exact form. A row with a token that is not
    plain (digits before and after one point, no ``+``) or a non-finite new value is left.

    Fills per token ``status`` (:data:`KEEP` ... :data:`SHORT`), ``dec_out`` (the decimals of
    :data:`FIXED`, the decimal exponent of :data:`SHORT`), ``digits`` (of :data:`SHORT`),
    ``tok_start``, ``tok_len`` and ``new_len`` (the written length without padding; -1 for
    :data:`PYTHON` and :data:`SHORTEST`), and ``row_ok``. Returns the number of tokens
    Python must write (:data:`PYTHON` and :data:`SHORTEST`), or -1 when ``buf`` is not ``m``
    rows of ``k`` pieces of those characters (then the caller leaves every row to the row
    renderer).
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
            if not _piece_ends(buf, pos, sep, c, k, r, m):
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
                ndig = 1
                while q >= 10:
                    ndig += 1
                    q //= 10
                if ndig < d + 1:
                    ndig = d + 1
                status[j] = FIXED
                dec_out[j] = d
                new_len[j] = ndig + 1 + (1 if neg else 0)
            elif res == -1:
                status[j] = PYTHON
                new_len[j] = -1
                npy += 1
            else:
                done, dd, kk, nd = shortest_decimal(v)
                if done:
                    status[j] = SHORT
                    digits[j] = dd
                    dec_out[j] = kk
                    new_len[j] = shortest_length(v, dd, kk, nd)
                else:
                    status[j] = SHORTEST
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


@njit(cache=True, nogil=True)
def plain_block_write(buf, sep, k, m, new, status, dec_out, tok_start, tok_len, new_len,
                      short_buf, nshort, py_buf, py_start, digits):
    """The rows planned by :func:`plain_block_plan`, as bytes joined by ``\\n``: kept tokens
    and odd rows copied (``new_len`` is overwritten with every token's written length),
    :data:`FIXED` ones written digit by digit (the decimal ``k 10**-d``
    of :func:`_exact_at`, a minus where the value is negative and not a zero the token wrote
    without one), the :data:`SHORT` ones from their digits (:func:`write_shortest`), the
    :data:`SHORTEST` ones from ``short_buf`` (Python's ``repr`` of their
    list, :func:`_shortest_pieces`), the :data:`PYTHON` ones from ``py_buf`` (number ``i`` of
    them at ``py_start[i]:py_start[i + 1]``), both in token order; with a blank or tab
    separator a changed number shorter than the text it replaces gets the blanks it gave up
    in front (not the first of a row), so right-aligned columns stay aligned."""
    blank = sep == 32 or sep == 9
    s_start, s_len = _shortest_pieces(short_buf, nshort)
    # every token's written length into new_len (Python's texts' lengths too), then the size
    total = 0
    ip = 0
    js = 0
    for t in range(m * k):
        st = status[t]
        if st == PYTHON:
            new_len[t] = py_start[ip + 1] - py_start[ip]
            ip += 1
        elif st == SHORTEST:
            new_len[t] = s_len[js]
            js += 1
        ln = new_len[t]
        if blank and t % k > 0 and st != KEEP and st != ODD_ROW and ln < tok_len[t]:
            ln = tok_len[t]  # the blanks a shorter number gave up
        total += ln + 1
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
                ln = new_len[t]
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
                elif st == SHORT:
                    dd = digits[t]
                    nd = 1
                    while dd >= IPOW10[nd] and nd < 18:
                        nd += 1
                    w = write_shortest(out, w, new[t], dd, dec_out[t], nd)
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

"""numpy's pairwise summation, compiled, whole or streamed.

``np.sum`` of a float64 array (contiguous or a strided column) is ``0.0 + PW(a, n)`` with
numpy's pairwise recursion ``PW`` (``numpy/_core/src/umath/loops_utils.h.src``): up to 8
values summed in turn; up to 128 values ("a leaf") in eight interleaved accumulators combined
as ``((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))``, then the rest in turn; above 128
the two halves ``n2 = n // 2 - (n // 2) % 8`` and ``n - n2``, summed recursively and added.
The leaves are therefore fixed runs of consecutive values, known from ``n`` alone
(:func:`leaf_bounds`): a pass that produces the values in order can sum each leaf when it is
complete (:func:`fold_block`) and keep only the leaf sums, which :func:`tree_sum` combines in
numpy's order: the same bits as ``np.sum`` of the whole array, without the array. Compiled
without fast-math (no reassociation).
"""

from __future__ import annotations

import numpy as np

from .._jit import njit

LEAF = 128  # numpy's PW_BLOCKSIZE


@njit(cache=True, inline="always")
def _half(n):
    """The size of the left half of numpy's pairwise recursion over ``n > 128`` values: half,
    rounded down to a multiple of 8 (its unroll factor)."""
    n2 = n // 2
    return n2 - n2 % 8


@njit(cache=True)
def pw_sum_long(v, m):
    """numpy's pairwise summation above 128 values (recursive halves, multiples of 8)."""
    if m <= LEAF:
        return pw_sum(v, m)
    m2 = _half(m)
    return pw_sum_long(v[:m2], m2) + pw_sum_long(v[m2:], m - m2)


@njit(cache=True, inline="always")
def pw_sum(v, m):
    """``v[:m].sum()`` in numpy's order (pairwise summation: sequential below 8 values, eight
    accumulators up to 128), so that a compiled sum is bitwise the vectorised one."""
    if m < 8:
        res = 0.0
        for i in range(m):
            res += v[i]
        return res
    if m > LEAF:
        return pw_sum_long(v, m)
    r0, r1, r2, r3 = v[0], v[1], v[2], v[3]
    r4, r5, r6, r7 = v[4], v[5], v[6], v[7]
    i = 8
    while i < m - (m % 8):
        r0 += v[i]
        r1 += v[i + 1]
        r2 += v[i + 2]
        r3 += v[i + 3]
        r4 += v[i + 4]
        r5 += v[i + 5]
        r6 += v[i + 6]
        r7 += v[i + 7]
        i += 8
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < m:
        res += v[i]
        i += 1
    return res


@njit(cache=True)
def leaf_bounds(n):
    """The leaves of numpy's pairwise summation of ``n`` values, in order: ``out[k] ..
    out[k+1] - 1`` is leaf ``k`` (``out[0] = 0``, ``out[-1] = n``; one leaf for ``n <=
    128``, none for ``n = 0``)."""
    if n == 0:
        return np.zeros(1, dtype=np.int64)
    cap = 2 * (n // 64) + 2  # leaves hold more than 60 values when n > 128
    out = np.empty(cap + 1, dtype=np.int64)
    stack_lo = np.empty(128, dtype=np.int64)
    stack_n = np.empty(128, dtype=np.int64)
    stack_lo[0] = 0
    stack_n[0] = n
    top = 1
    k = 0
    while top > 0:  # depth first, left half first: the leaves in order
        top -= 1
        lo = stack_lo[top]
        c = stack_n[top]
        if c <= LEAF:
            out[k] = lo
            k += 1
            continue
        c2 = _half(c)
        stack_lo[top] = lo + c2  # right half below the left one
        stack_n[top] = c - c2
        stack_lo[top + 1] = lo
        stack_n[top + 1] = c2
        top += 2
    out[k] = n
    return out[:k + 1].copy()


@njit(cache=True)
def _tree(ls, k, n):
    """PW of ``n`` values whose leaves' sums start at ``ls[k[0]]`` (``k[0]`` advanced past
    them: the leaves are consumed left to right, as numpy's recursion reaches them)."""
    if n <= LEAF:
        v = ls[k[0]]
        k[0] += 1
        return v
    n2 = _half(n)
    a = _tree(ls, k, n2)
    return a + _tree(ls, k, n - n2)


@njit(cache=True)
def tree_sum(ls, n):
    """``np.sum`` of ``n`` values from the sums of their leaves (``ls[k]``: leaf ``k`` of
    :func:`leaf_bounds`, each as :func:`pw_sum`): ``0.0 + PW``, numpy's order."""
    if n == 0:
        return 0.0
    k = np.zeros(1, dtype=np.int64)
    return 0.0 + _tree(ls, k, n)


@njit(cache=True, nogil=True)
def _fold_tree(v, n, e0, lb, ls, head, cur, st, first):
    """Values ``v[:n]`` of elements ``e0 .. e0 + n - 1`` into one tree's state (see
    :func:`fold_block`): ``head``/``cur`` the two value buffers, ``st = (head count, current
    count, current leaf)`` (kept in locals through the loop), ``first`` the range's first
    element."""
    nh = st[0]
    nc = st[1]
    L = st[2]
    end = lb[L + 1]
    for r in range(n):
        e = e0 + r
        while end <= e:
            L += 1
            end = lb[L + 1]
        x = v[r]
        if lb[L] < first:  # the leaf began before this range: its head, finished later
            head[nh] = x
            nh += 1
        else:
            cur[nc] = x
            nc += 1
            if e == end - 1:  # the leaf is complete
                ls[L] = pw_sum(cur, nc)
                nc = 0
    st[0] = nh
    st[1] = nc
    st[2] = L


@njit(cache=True, nogil=True)
def fold_block(kb, eb, count, s0, lbe, lbs, ls2, ls3, lss, bufs, ints, first, mx):
    """The figures a summary analysis keeps of one block of segments ``s0 .. s0 + count - 1``
    of an open curve, whose jumps and energies the sampling pass wrote to the block's own
    rows (``kb[r]``, ``eb[r]`` for segment ``s0 + r``): the energies (trees 0 and 1, one
    element a segment, leaves ``lbe``) and the Sapidis measure at breakpoints ``1 .. m-1``
    (tree 2, element ``i - 1`` for segment ``i >= 1``, leaves ``lbs``) into their leaf sums
    ``ls2``/``ls3``/``lss``; the largest jump of the third and of the top derivative at
    those breakpoints into ``mx`` (NaN sticks, as in ``np.max``).

    State of one range of segments, carried from block to block: ``bufs[t, 0]`` the values
    of the leaf that began before the range (its head), ``bufs[t, 1]`` those of the current
    leaf; ``ints[t] = (head count, current count, current leaf)``; ``first[t]`` the range's
    first element of tree ``t``. A leaf split between ranges is summed afterwards from the
    earlier range's unfinished values and the later one's head."""
    _fold_tree(eb[:, 0], count, s0, lbe, ls2, bufs[0, 0], bufs[0, 1], ints[0], first[0])
    _fold_tree(eb[:, 1], count, s0, lbe, ls3, bufs[1, 0], bufs[1, 1], ints[1], first[1])
    r0 = 1 if s0 == 0 else 0  # (segment 0 has no interior breakpoint)
    if count > r0:
        _fold_tree(kb[r0:, 2], count - r0, s0 + r0 - 1, lbs, lss, bufs[2, 0], bufs[2, 1],
                   ints[2], first[2])
    for q in range(2):
        m = mx[q]
        for r in range(r0, count):
            v = kb[r, q]
            if not (v <= m) and m == m:
                m = v
        mx[q] = m

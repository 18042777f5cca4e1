"""Small dense linear algebra with the same bits on every x86-64 CPU, for the Python-side
set-up whose numbers enter a simulation (a walker's start state from its gait coordinates, a
velocity projected onto its joints).

numpy's `@`, `np.linalg.solve` and `lstsq` run in BLAS and LAPACK kernels that OpenBLAS
chooses per CPU (AVX-512, AVX2, SSE), and their last bits differ: the compass gait's
trajectory and a corpus scene's start state had other fingerprints under OpenBLAS's AVX2
kernels than under its AVX-512 ones. These loops are compiled without fast-math (no fused
multiply-add), summing in index order, so they give the same numbers everywhere, as the step
does. Sizes here are tens of rows: the plain loops cost microseconds."""
from __future__ import annotations

import numpy as np
from numba import njit

from .compile import options as _compile_options

# the engine's options (no fast-math: no fused multiply-add, sums in their written order),
# with numba's runtime on: these return new arrays
_jit = njit(**dict(_compile_options(), _nrt=True))


@_jit
def _dot(a, b):
    acc = 0.0
    for i in range(a.shape[0]):
        acc += a[i] * b[i]
    return acc


@_jit
def _matmul(A, B):
    n, k = A.shape
    p = B.shape[1]
    C = np.zeros((n, p))
    for i in range(n):
        for j in range(p):
            acc = 0.0
            for c in range(k):
                acc += A[i, c] * B[c, j]
            C[i, j] = acc
    return C


@_jit
def _solve_psd(A, b, rtol):
    """x with A x = b for symmetric positive semidefinite A (n, n) and b in its range: L D L^T
    with symmetric pivoting on the largest remaining diagonal; a pivot at or below rtol times
    the largest diagonal ends the elimination (the rows left depend on the others: their
    unknowns are 0). Returns x."""
    n = A.shape[0]
    W = A.copy()
    perm = np.arange(n)
    big = 0.0
    for i in range(n):
        big = max(big, W[i, i])
    tol = rtol * big
    rank = 0
    for k in range(n):
        p = k
        for i in range(k + 1, n):
            if W[i, i] > W[p, p]:
                p = i
        if not W[p, p] > tol:
            break
        if p != k:
            for j in range(n):
                W[k, j], W[p, j] = W[p, j], W[k, j]
            for i in range(n):
                W[i, k], W[i, p] = W[i, p], W[i, k]
            perm[k], perm[p] = perm[p], perm[k]
        for i in range(k + 1, n):
            f = W[i, k] / W[k, k]
            for j in range(k + 1, n):
                W[i, j] -= f * W[k, j]
            W[i, k] = f
        rank = k + 1
    y = np.zeros(n)
    for i in range(rank):
        acc = b[perm[i]]
        for j in range(i):
            acc -= W[i, j] * y[j]
        y[i] = acc
    for i in range(rank):
        y[i] /= W[i, i]
    for i in range(rank - 1, -1, -1):
        acc = y[i]
        for j in range(i + 1, rank):
            acc -= W[j, i] * y[j]
        y[i] = acc
    x = np.zeros(n)
    for i in range(rank):
        x[perm[i]] = y[i]
    return x


@_jit
def _solve(A, b):
    """x with A x = b (n, n) by Gaussian elimination with partial pivoting; NaNs if singular."""
    n = A.shape[0]
    W = A.copy()
    x = b.copy()
    for c in range(n):
        p = c
        for i in range(c + 1, n):
            if abs(W[i, c]) > abs(W[p, c]):
                p = i
        if W[p, c] == 0.0:
            return np.full(n, np.nan)
        if p != c:
            for j in range(n):
                W[c, j], W[p, j] = W[p, j], W[c, j]
            x[c], x[p] = x[p], x[c]
        for i in range(c + 1, n):
            f = W[i, c] / W[c, c]
            for j in range(c + 1, n):
                W[i, j] -= f * W[c, j]
            x[i] -= f * x[c]
    for i in range(n - 1, -1, -1):
        acc = x[i]
        for j in range(i + 1, n):
            acc -= W[i, j] * x[j]
        x[i] = acc / W[i, i]
    return x


def _floats(a) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=np.float64)


def dot(a, b) -> float:
    """a . b of two vectors (n,)."""
    return float(_dot(_floats(a), _floats(b)))


def matmul(A, B) -> np.ndarray:
    """A @ B for A (n, k) and B (k, p) or (k,) (a vector: the result is (n,))."""
    B = _floats(B)
    if B.ndim == 1:
        return _matmul(_floats(A), B[:, None])[:, 0]
    return _matmul(_floats(A), B)


def solve(A, b) -> np.ndarray:
    """x with A x = b, A (n, n) regular (Gaussian elimination, partial pivoting).
    Raises numpy.linalg.LinAlgError if A is singular."""
    x = _solve(_floats(A), _floats(b))
    if np.isnan(x).any():
        raise np.linalg.LinAlgError("singular matrix")
    return x


def solve_psd(A, b, rtol: float = 1e-12) -> np.ndarray:
    """A solution of A x = b for symmetric positive semidefinite A (n, n) with b in its range
    (J W J^T of dependent joint rows, say): rows whose pivot falls to rtol of the largest
    diagonal are left out with x = 0 there. Any solution gives the same J^T x."""
    return _solve_psd(_floats(A), _floats(b), float(rtol))

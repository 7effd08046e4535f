"""Largest Lyapunov exponent of a scalar signal (Rosenstein, Collins & De Luca, 1993).

The signal is delay-embedded, every embedded point is paired with its nearest neighbour that is not a temporal
neighbour, and the mean logarithm of the pairs' distance is followed as the pairs evolve. For a chaotic signal
this *divergence curve* rises linearly (exponential separation) and then saturates at the size of the attractor;
the slope of the linear part is the largest Lyapunov exponent, and its reciprocal the Lyapunov time, the
horizon over which a small error grows by a factor e.

When the embedding is not given it is chosen from the data:

- lag: first minimum of the average mutual information (Fraser & Swinney 1986), or the first drop of the
  autocorrelation below 1/e if the mutual information has no minimum (:func:`delay_embedding_lag`);
- dimension: false nearest neighbours (Kennel, Brown & Abarbanel 1992) (:func:`embedding_dimension`);
- Theiler window (neighbours closer in time are excluded): the mean period, the reciprocal of the mean
  frequency of the power spectrum, as Rosenstein et al. recommend.

Integer arguments (``lag``, ``min_separation``, ``max_steps``) count samples; times and exponents are in
seconds and 1/s (``dt`` sets the scale: with ``dt=1`` a map's exponent comes out per iteration).

A positive number is not proof of chaos. Noise, or a linear system driven by random forcing, also separates
nearby states, and the fitted slope then measures how fast the forcing makes two records forget that they were
once close (a predictability horizon), not a property of deterministic dynamics. Read the divergence curve
(``return_details=True``) before reading the number, and compare with phase-randomised copies of the signal
(same power spectrum, no nonlinear structure): if they give the same exponent, the number is a property of the
spectrum, i.e. of linear dynamics under random forcing. Records dominated by slow motions (platform surge and
pitch under tower vibration) embed the slow motion; band-pass them first to study the faster one.

References
----------
M. T. Rosenstein, J. J. Collins, C. J. De Luca, "A practical method for calculating largest Lyapunov exponents
from small data sets", Physica D 65 (1993) 117-134.
M. B. Kennel, R. Brown, H. D. I. Abarbanel, "Determining embedding dimension for phase-space reconstruction using
a geometrical construction", Phys. Rev. A 45 (1992) 3403-3411.
A. M. Fraser, H. L. Swinney, "Independent coordinates for strange attractors from mutual information",
Phys. Rev. A 33 (1986) 1134-1140.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Literal, overload

import numpy as np
from numpy.typing import ArrayLike
from scipy.interpolate import BSpline
from scipy.spatial import cKDTree

from .validation import MAX_ABS, as_2d_float, check_int, check_number, constant_channels

__all__ = [
    "LyapunovResult",
    "delay_embedding",
    "delay_embedding_lag",
    "embedding_dimension",
    "false_nearest_neighbours",
    "lyapunov_exponent",
    "lyapunov_time",
    "mean_period",
]

_AMI_RISE = 0.02  # a mutual-information minimum counts once the curve climbs back by this fraction of its drop
_MAX_CURVE_WORK = 60_000_000  # pair-steps of the divergence curve (~1 s); more pairs are thinned evenly
_MIN_REFERENCE_POINTS = 50  # fewest embedded points whose divergence is averaged
_FIT_SATURATION_FRACTION = 0.7  # the fit ends where the curve has covered this fraction of its rise
_FIT_MIN_LENGTH_FRACTION = 0.5  # a fit window spans at least this fraction of the growth region
_MIN_FIT_STEPS = 5  # a linear region spans at least this many steps (a faster rise is a jump)
_MIN_RISE = 0.5  # a divergence curve rising less than this (natural log, a factor 1.65) shows no divergence


# ----------------------------------------------------------------------------------------------- input checks


def _as_signal(x: object, name: str = "x", *, min_samples: int = 1, allow_constant: bool = False) -> np.ndarray:
    """Check a scalar signal (1-D or one column) and return it as a 1-D float64 array."""
    try:
        shape = np.shape(x)
    except ValueError as exc:  # ragged nested lists
        raise ValueError(f"{name} must be a numeric 1-D array: {exc}") from None
    if len(shape) == 2 and shape[1] == 1:
        arr = x
    elif len(shape) == 1:
        arr = np.asarray(x)[:, None]
    else:
        raise ValueError(f"{name} must be a 1-D signal (or shape (n_samples, 1)), got shape {shape}")
    try:
        Y = as_2d_float(arr, name, min_samples=min_samples, max_abs=MAX_ABS)
    except ValueError as exc:
        raise ValueError(str(exc).replace("channel 0: ", "").replace(" (n_samples, n_channels)", "")) from None
    if not allow_constant and constant_channels(Y).size:
        raise ValueError(f"{name} is constant (value {Y[0, 0]!r}): a constant signal has no dynamics to embed")
    return Y[:, 0]


def _check_dt(dt: object) -> float:
    return check_number("dt (sampling interval, s)", dt, positive=True)


# ------------------------------------------------------------------------------------------ embedding helpers


def delay_embedding(x: ArrayLike, dim: int, lag: int) -> np.ndarray:
    """Delay vectors ``[x[i], x[i + lag], ..., x[i + (dim - 1) lag]]`` of a scalar signal.

    Parameters
    ----------
    x : array_like (n_samples,)
        Scalar signal.
    dim : int
        Embedding dimension (>= 1).
    lag : int
        Delay between coordinates, in samples (>= 1).

    Returns
    -------
    ndarray (n_samples - (dim - 1) * lag, dim)
        A read-only strided view when possible (no copy).

    Examples
    --------
    >>> delay_embedding([0.0, 1.0, 2.0, 3.0, 4.0], dim=2, lag=2)
    array([[0., 2.],
           [1., 3.],
           [2., 4.]])
    """
    dim = check_int("dim", dim, minimum=1)
    lag = check_int("lag (samples)", lag, minimum=1)
    x = _as_signal(x, allow_constant=True)
    n_vectors = x.size - (dim - 1) * lag
    if n_vectors < 1:
        raise ValueError(
            f"x has {x.size} samples, too short to embed in dim={dim} with lag={lag} "
            f"(needs at least (dim - 1) * lag + 1 = {(dim - 1) * lag + 1})"
        )
    return _embed(x, dim, lag, n_vectors)


def _embed(x: np.ndarray, dim: int, lag: int, n_vectors: int) -> np.ndarray:
    """Unchecked delay embedding: the first ``n_vectors`` delay vectors as a strided view."""
    s = x.strides[0]
    return np.lib.stride_tricks.as_strided(x, shape=(n_vectors, dim), strides=(s, lag * s), writeable=False)


def mean_period(x: ArrayLike, dt: float = 1.0) -> float:
    """Mean period of a signal: the reciprocal of the power-weighted mean frequency of its periodogram.

    Rosenstein et al. (1993) use it as the Theiler window of the nearest-neighbour search: points closer in time
    than one mean period are not taken as neighbours.

    Parameters
    ----------
    x : array_like (n_samples,)
        Scalar signal; its mean is removed.
    dt : float
        Sampling interval (s).

    Returns
    -------
    float
        Mean period (s).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(4000) * 0.01
    >>> round(mean_period(np.sin(2 * np.pi * 0.5 * t), dt=0.01), 3)
    2.0
    """
    dt = _check_dt(dt)
    x = _as_signal(x, min_samples=3)
    return _mean_period_samples(x) * dt


def _mean_period_samples(x: np.ndarray) -> float:
    power = np.abs(np.fft.rfft(x - x.mean())) ** 2
    freq = np.fft.rfftfreq(x.size)  # cycles per sample
    f_mean = float(np.sum(freq[1:] * power[1:]) / np.sum(power[1:]))
    return 1.0 / f_mean


def _bspline_weights(x: np.ndarray, n_bins: int) -> np.ndarray:
    """Quadratic B-spline bin weights ``(n_samples, n_bins)`` of the ranks of ``x`` (rows sum to 1).

    Each sample is spread over three neighbouring bins instead of falling in one (Daub et al. 2004), which
    removes the comb-like artefacts that sharp bins give for smooth, oversampled signals. The rank transform
    (empirical copula) makes the marginals uniform; mutual information does not change under it.
    """
    position = np.empty(x.size)
    position[np.argsort(x, kind="stable")] = (np.arange(x.size) + 0.5) / x.size
    degree = 2
    knots = np.concatenate((np.zeros(degree), np.linspace(0.0, 1.0, n_bins - degree + 1), np.ones(degree)))
    return BSpline.design_matrix(position, knots, degree).toarray()


def _mutual_information(weights: np.ndarray, lag: int) -> float:
    """Mutual information (nats) between ``x[t]`` and ``x[t + lag]`` from B-spline bin weights."""
    joint = weights[:-lag].T @ weights[lag:] / (weights.shape[0] - lag)
    pa, pb = joint.sum(axis=1), joint.sum(axis=0)
    nz = joint > 0
    return float(np.sum(joint[nz] * np.log(joint[nz] / np.outer(pa, pb)[nz])))


def _autocorrelation(x: np.ndarray, max_lag: int) -> np.ndarray:
    xc = x - x.mean()
    n_fft = 1 << int(np.ceil(np.log2(2 * x.size)))
    spec = np.fft.rfft(xc, n_fft)
    acf = np.fft.irfft(spec * np.conj(spec), n_fft)[: max_lag + 1]
    return acf / acf[0]


def delay_embedding_lag(
    x: ArrayLike,
    *,
    method: Literal["ami", "acf"] = "ami",
    max_lag: int | None = None,
    n_bins: int = 16,
) -> int:
    """Embedding delay of a scalar signal, in samples.

    With ``method="ami"`` (default) the delay is the first minimum of the average mutual information between
    ``x[t]`` and ``x[t + lag]`` (Fraser & Swinney 1986). The mutual information is estimated on the ranks of
    ``x`` (so outliers do not squeeze the bins) with ``n_bins`` quadratic B-spline bins per axis (Daub et al.
    2004; sharp bins give comb-like artefacts on smooth oversampled signals). A minimum counts once the curve has
    climbed back by 2 % of its drop from lag 1 plus four standard deviations of the estimate for independent
    samples (shuffled copies), so that wiggles of the estimate are not taken for minima. If the mutual
    information has no such minimum up to ``max_lag`` (it just decays to its floor, as for maps and noise) the
    delay falls back to the first lag where the autocorrelation drops below 1/e, which is what ``method="acf"``
    returns directly.

    Parameters
    ----------
    x : array_like (n_samples,)
        Scalar signal.
    method : {"ami", "acf"}
        Mutual-information minimum (with autocorrelation fallback) or autocorrelation 1/e only.
    max_lag : int, optional
        Largest delay searched (samples); default ``n_samples // 10`` (at least 1).
    n_bins : int
        B-spline bins per axis of the mutual-information estimate (>= 3).

    Returns
    -------
    int
        Delay in samples (multiply by the sampling interval for seconds).

    Raises
    ------
    ValueError
        Non-finite or constant ``x``, fewer than 16 samples, bad ``method``/``max_lag``/``n_bins``, or neither the
        mutual information nor the autocorrelation gives a delay up to ``max_lag`` (the signal is dominated by a
        trend or by periods longer than ``max_lag``: detrend or high-pass it, or give a larger ``max_lag``).

    Examples
    --------
    The Hénon map decorrelates within one step: its mutual information has no minimum, the autocorrelation
    gives a delay of one sample. A noisy sine gets about a quarter period (50 samples per period here):

    >>> import numpy as np
    >>> x = np.zeros(3000)
    >>> for i in range(2, x.size):
    ...     x[i] = 1.0 - 1.4 * x[i - 1] ** 2 + 0.3 * x[i - 2]
    >>> delay_embedding_lag(x[100:])
    1
    >>> rng = np.random.default_rng(0)
    >>> y = np.sin(2 * np.pi * np.arange(5000) / 50) + 0.1 * rng.standard_normal(5000)
    >>> delay_embedding_lag(y, method="acf"), 8 <= delay_embedding_lag(y) <= 16
    (10, True)
    """
    if method not in ("ami", "acf"):
        raise ValueError(f"method must be 'ami' or 'acf', got {method!r}")
    x = _as_signal(x, min_samples=16)
    max_lag = max(1, x.size // 10) if max_lag is None else check_int("max_lag (samples)", max_lag, minimum=1)
    if max_lag > x.size - 8:
        raise ValueError(f"max_lag = {max_lag} must leave at least 8 samples of x ({x.size} samples)")
    n_bins = check_int("n_bins", n_bins, minimum=3)
    if method == "ami":
        lag = _first_ami_minimum(x, max_lag, n_bins)
        if lag is not None:
            return lag
    acf = _autocorrelation(x, max_lag)
    below = np.flatnonzero(acf[1:] < 1.0 / np.e)
    if below.size:
        return int(below[0]) + 1
    raise ValueError(
        f"no embedding delay found up to max_lag = {max_lag} samples: the mutual information has no minimum and "
        f"the autocorrelation stays above 1/e (lowest {acf[1:].min():.3f}); the signal is dominated by a trend or "
        "by periods longer than max_lag: detrend or high-pass it, or give a larger max_lag"
    )


def _first_ami_minimum(x: np.ndarray, max_lag: int, n_bins: int) -> int | None:
    """First significant minimum of the mutual information, or ``None``.

    The minimum is the lowest value reached before the curve climbs back by ``_AMI_RISE`` of its drop from lag 1
    plus four standard deviations of the estimate for independent samples (from shuffled copies, fixed
    permutations): wiggles of the estimate, as where the information of a map or of noise has decayed to its
    floor, are not minima.
    """
    weights = _bspline_weights(x, n_bins)
    rng = np.random.default_rng(0)
    noise = float(np.std([_mutual_information(weights[rng.permutation(x.size)], 1) for _ in range(5)], ddof=1))
    first = _mutual_information(weights, 1)
    best, best_lag = first, 1
    for lag in range(2, max_lag + 1):
        mi = _mutual_information(weights, lag)
        if mi < best:
            best, best_lag = mi, lag
        elif mi > best + _AMI_RISE * (first - best) + 4.0 * noise:
            return best_lag
    return None


def _nearest_neighbours(
    points: np.ndarray, queries: np.ndarray, min_separation: int, min_distance: float
) -> tuple[np.ndarray, np.ndarray]:
    """Nearest neighbour of every query index among ``points``, excluding temporal neighbours and exact repeats.

    Candidates with ``|i - j| <= min_separation`` (Theiler window) or at distance ``<= min_distance`` (the same
    point up to rounding: an exactly periodic signal repeats its samples, and a zero distance has no logarithm)
    are skipped. One k-d tree over all points answers most queries from its 8, then 32 nearest candidates. On
    an oversampled trajectory the nearest candidates of some points all lie on their own stretch of trajectory;
    those go to :func:`_windowed_search`, which searches the points outside the window directly. Returns the
    neighbour indices (-1 where no valid neighbour exists) and distances.
    """
    tree = cKDTree(points)
    n_points = points.shape[0]
    nn = np.full(queries.size, -1, dtype=np.int64)
    dist = np.full(queries.size, np.inf)
    todo = np.arange(queries.size)
    for k in (8, 32):
        k = min(k, n_points)
        for chunk in np.array_split(todo, max(1, todo.size * k // 1_000_000)):
            q = queries[chunk]
            d, j = tree.query(points[q], k=k)
            d, j = d.reshape(q.size, k), j.reshape(q.size, k)
            ok = (np.abs(j - q[:, None]) > min_separation) & (d > min_distance) & (j < n_points)
            rows = np.flatnonzero(ok.any(axis=1))
            first = np.argmax(ok[rows], axis=1)
            nn[chunk[rows]] = j[rows, first]
            dist[chunk[rows]] = d[rows, first]
        todo = todo[nn[todo] < 0]
        if not todo.size or k == n_points:
            return nn, dist
    nn[todo], dist[todo] = _windowed_search(points, queries[todo], min_separation, min_distance)
    return nn, dist


def _windowed_search(
    points: np.ndarray, queries: np.ndarray, min_separation: int, min_distance: float, leaf: int | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Exact nearest neighbour outside ``[i - min_separation, i + min_separation]`` for every query index ``i``.

    The valid points ``[0, i - w) U (i + w, n)`` are split into whole blocks of ``leaf`` samples (default a
    quarter of the window, within [32, 256]) and two partial blocks at the window edges. The whole blocks are
    covered by O(log n) nodes of a segment tree over time, each node holding a k-d tree of its points; the
    partial blocks are searched by brute force. A node's nearest
    candidate closer than ``min_distance`` (an exact repeat) is skipped among its 4 nearest.
    """
    n_points, n_q = points.shape[0], queries.size
    if leaf is None:
        leaf = int(np.clip(min_separation // 4, 32, 256))
    best_d = np.full(n_q, np.inf)
    best_j = np.full(n_q, -1, dtype=np.int64)

    def offer(rows: np.ndarray, d: np.ndarray, j: np.ndarray) -> None:
        """Keep candidate ``j`` at distance ``d`` for query ``rows`` if it beats the best so far."""
        better = (d < best_d[rows]) & (d > min_distance)
        # several candidates may concern the same query: process the best first so the last write wins correctly
        order = np.argsort(-d[better], kind="stable")
        r, dd, jj = rows[better][order], d[better][order], j[better][order]
        best_d[r], best_j[r] = dd, jj

    # partial blocks at both window edges: at most leaf - 1 points each, brute force
    left_end = queries - min_separation  # valid: [0, left_end)
    right_start = queries + min_separation + 1  # valid: [right_start, n)
    offsets = np.arange(leaf)
    for lo, hi in (
        ((np.maximum(left_end, 0) // leaf) * leaf, np.maximum(left_end, 0)),
        (np.minimum(right_start, n_points), np.minimum(-(-right_start // leaf) * leaf, n_points)),
    ):
        cand = lo[:, None] + offsets
        valid = cand < hi[:, None]
        rows, cols = np.nonzero(valid)
        j = cand[rows, cols]
        d = np.sqrt(np.sum((points[queries[rows]] - points[j]) ** 2, axis=1))
        offer(rows, d, j)

    # whole blocks: iterative segment tree over blocks [lo_block, hi_block)
    n_blocks = -(-n_points // leaf)
    size = 1 << max(0, int(np.ceil(np.log2(max(n_blocks, 1)))))
    trees: dict[int, tuple[cKDTree, int]] = {}

    def node_tree(node: int) -> tuple[cKDTree, int]:
        if node not in trees:
            level = int(np.log2(node))  # node at depth `level` covers size >> level blocks
            span = size >> level
            first_block = (node - (1 << level)) * span
            start, stop = first_block * leaf, min((first_block + span) * leaf, n_points)
            trees[node] = (cKDTree(points[start:stop]), start)
        return trees[node]

    ranges = (
        (np.zeros(n_q, dtype=np.int64), np.maximum(left_end, 0) // leaf),
        (-(-np.minimum(right_start, n_points) // leaf), np.full(n_q, n_blocks, dtype=np.int64)),
    )
    for lo_block, hi_block in ranges:
        lo, hi = lo_block + size, hi_block + size
        while True:
            active = lo < hi
            if not active.any():
                break
            take_lo = active & (lo & 1 == 1)
            take_hi = active & (hi & 1 == 1)
            for rows, nodes in ((np.flatnonzero(take_lo), lo[take_lo]), (np.flatnonzero(take_hi), hi[take_hi] - 1)):
                if not rows.size:
                    continue
                order = np.argsort(nodes, kind="stable")
                rows, nodes = rows[order], nodes[order]
                cuts = np.flatnonzero(np.diff(nodes)) + 1
                for sel, node in zip(np.split(rows, cuts), nodes[np.r_[0, cuts]], strict=True):
                    tree, start = node_tree(int(node))
                    k = min(4, tree.n)
                    d, j = tree.query(points[queries[sel]], k=k)
                    d, j = d.reshape(sel.size, k), j.reshape(sel.size, k)
                    ok = d > min_distance
                    has = ok.any(axis=1)
                    first = np.argmax(ok, axis=1)
                    r = np.flatnonzero(has)
                    offer(sel[r], d[r, first[r]], j[r, first[r]] + start)
            lo = np.where(take_lo, lo + 1, lo)
            hi = np.where(take_hi, hi - 1, hi)
            lo, hi = lo >> 1, hi >> 1
    return best_j, best_d


def _repeat_distance(x: np.ndarray) -> float:
    """Distances up to this are rounding errors: the two delay vectors are the same point."""
    return 1e-9 * float(np.std(x))


def _theiler(x: np.ndarray, min_separation: int | None) -> int:
    if min_separation is None:
        return int(np.ceil(_mean_period_samples(x)))
    return check_int("min_separation (samples)", min_separation, minimum=0)


def false_nearest_neighbours(
    x: ArrayLike,
    lag: int,
    *,
    max_dim: int = 10,
    rtol: float = 15.0,
    atol: float = 2.0,
    min_separation: int | None = None,
    max_points: int = 5000,
) -> np.ndarray:
    """Fraction of false nearest neighbours for embedding dimensions 1 to ``max_dim`` (Kennel et al. 1992).

    The nearest neighbour ``j`` of a delay vector ``i`` in ``d`` dimensions is *false* if adding the next
    coordinate moves them apart: ``|x[i + d lag] - x[j + d lag]| / R_d > rtol`` (Kennel's first criterion,
    ``R_d`` their distance in ``d`` dimensions) or their distance in ``d + 1`` dimensions exceeds
    ``atol`` times the standard deviation of ``x`` (the second criterion, which catches noise). Neighbours
    closer in time than ``min_separation`` samples are excluded (a Theiler window).

    Parameters
    ----------
    x : array_like (n_samples,)
        Scalar signal.
    lag : int
        Embedding delay (samples), e.g. from :func:`delay_embedding_lag`.
    max_dim : int
        Largest dimension tested.
    rtol, atol : float
        Kennel's thresholds R_tol (10-15 in the paper) and A_tol (2).
    min_separation : int, optional
        Theiler window (samples); default the mean period (:func:`mean_period`).
    max_points : int
        Test at most this many delay vectors (evenly spaced); their neighbours are searched among all.

    Returns
    -------
    ndarray (max_dim,)
        Entry ``d - 1`` is the fraction of false neighbours when going from ``d`` to ``d + 1`` dimensions.

    Examples
    --------
    A sine needs two coordinates: its one-dimensional neighbours are mostly false, its 2-D ones are not.

    >>> import numpy as np
    >>> x = np.sin(2 * np.pi * np.arange(5000) / 50 + 0.1)
    >>> fnn = false_nearest_neighbours(x, lag=12, max_dim=3)
    >>> bool(fnn[0] > 0.3), bool(fnn[1] < 0.01)
    (True, True)
    """
    return _false_nearest_neighbours(
        x, lag, max_dim=max_dim, rtol=rtol, atol=atol, min_separation=min_separation, max_points=max_points
    )


def _false_nearest_neighbours(
    x: ArrayLike,
    lag: int,
    *,
    max_dim: int,
    rtol: float,
    atol: float,
    min_separation: int | None,
    max_points: int,
    stop_at: float | None = None,
) -> np.ndarray:
    """:func:`false_nearest_neighbours`, stopping once the fraction is ``<= stop_at``, or has been above its
    minimum so far plus ``stop_at`` for two dimensions in a row (noise makes it rise again past its minimum)."""
    x = _as_signal(x, min_samples=4)
    lag = check_int("lag (samples)", lag, minimum=1)
    max_dim = check_int("max_dim", max_dim, minimum=1)
    rtol = check_number("rtol", rtol, positive=True)
    atol = check_number("atol", atol, positive=True)
    max_points = check_int("max_points", max_points, minimum=1)
    theiler = _theiler(x, min_separation)
    n_needed = max_dim * lag + 2 * theiler + 3
    if x.size < n_needed:
        raise ValueError(
            f"x has {x.size} samples, too short for false nearest neighbours up to max_dim={max_dim} with "
            f"lag={lag} and min_separation={theiler} (needs more than max_dim * lag + 2 * min_separation + 2 = "
            f"{n_needed - 1}); give a smaller max_dim or lag, or a longer signal"
        )
    scale = float(np.std(x))
    fractions: list[float] = []
    for d in range(1, max_dim + 1):
        n_vectors = x.size - d * lag  # the (d+1)-th coordinate must exist
        emb = _embed(x, d, lag, n_vectors)
        step = max(1, int(np.ceil(n_vectors / max_points)))
        queries = np.arange(0, n_vectors, step)
        nn, dist = _nearest_neighbours(emb, queries, theiler, _repeat_distance(x))
        queries, nn, dist = queries[nn >= 0], nn[nn >= 0], dist[nn >= 0]
        if queries.size == 0:
            raise ValueError(
                f"no delay vector of x has a neighbour outside the Theiler window min_separation={theiler} in "
                f"dimension {d}: give a longer signal or a smaller min_separation"
            )
        extra = np.abs(x[queries + d * lag] - x[nn + d * lag])
        first = extra > rtol * dist
        second = np.sqrt(dist**2 + extra**2) / scale > atol
        fractions.append(float(np.mean(first | second)))
        if stop_at is not None:
            level = min(fractions) + stop_at
            if fractions[-1] <= stop_at or (len(fractions) >= 3 and min(fractions[-2:]) > level):
                break
    return np.asarray(fractions)


def embedding_dimension(
    x: ArrayLike,
    lag: int,
    *,
    max_dim: int = 10,
    threshold: float = 0.01,
    rtol: float = 15.0,
    atol: float = 2.0,
    min_separation: int | None = None,
    max_points: int = 5000,
) -> int:
    """Embedding dimension by false nearest neighbours (Kennel, Brown & Abarbanel 1992).

    The smallest dimension whose fraction of false nearest neighbours (:func:`false_nearest_neighbours`) is at
    most ``threshold``. Noise keeps the fraction from reaching zero (and makes it rise again at high dimension);
    if it never gets below ``threshold`` the answer is the smallest dimension within ``threshold`` of the lowest
    fraction (where the curve levels off), with a ``RuntimeWarning``. Dimensions stop being tried once the
    fraction reaches ``threshold`` or has stayed above its minimum plus ``threshold`` for two dimensions.

    Parameters
    ----------
    x : array_like (n_samples,)
        Scalar signal.
    lag : int
        Embedding delay (samples), e.g. from :func:`delay_embedding_lag`.
    max_dim : int
        Largest dimension tested.
    threshold : float
        Acceptable fraction of false neighbours (0 < threshold < 1).
    rtol, atol, min_separation, max_points
        As in :func:`false_nearest_neighbours`.

    Returns
    -------
    int
        Embedding dimension, between 1 and ``max_dim``.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.sin(2 * np.pi * np.arange(5000) / 50 + 0.1)
    >>> embedding_dimension(x, lag=12)
    2
    """
    threshold = check_number("threshold", threshold, low=0.0, high=1.0)
    fractions = _false_nearest_neighbours(
        x,
        lag,
        max_dim=max_dim,
        rtol=rtol,
        atol=atol,
        min_separation=min_separation,
        max_points=max_points,
        stop_at=threshold,
    )
    good = np.flatnonzero(fractions <= threshold)
    if good.size:
        return int(good[0]) + 1
    dim = int(np.flatnonzero(fractions <= fractions.min() + threshold)[0]) + 1
    warnings.warn(
        f"the fraction of false nearest neighbours never fell to threshold = {threshold} (lowest "
        f"{fractions.min():.3f} over dimensions 1-{fractions.size}: {np.round(fractions, 3).tolist()}); the signal "
        f"is noisy or not low-dimensional; using dim = {dim}, where the fraction levels off",
        RuntimeWarning,
        stacklevel=2,
    )
    return dim


# ------------------------------------------------------------------------------------------ Lyapunov exponent


@dataclass(frozen=True, eq=False)
class LyapunovResult:
    """Largest Lyapunov exponent with the divergence curve it was fitted on (from :func:`lyapunov_exponent`).

    Attributes
    ----------
    exponent : float
        Largest Lyapunov exponent (1/s; per iteration when ``dt = 1``).
    times : ndarray (max_steps + 1,)
        Divergence times ``k * dt`` (s).
    divergence : ndarray (max_steps + 1,)
        Mean natural log of the distance between the neighbour pairs after ``k`` steps (ln of the signal's unit).
    fit_range : (float, float)
        First and last time (s) of the fitted straight line.
    intercept : float
        Intercept of the fitted line at time 0 (same unit as ``divergence``).
    r2 : float
        Coefficient of determination of the straight-line fit over ``fit_range`` (close to 1: a clean linear
        region; a low value says there is none, as for periodic or noise-like signals).
    lag : int
        Embedding delay (samples).
    dim : int
        Embedding dimension.
    min_separation : int
        Theiler window (samples).
    max_steps : int
        Length of the divergence curve (steps).
    n_pairs : int
        Number of neighbour pairs averaged.
    dt : float
        Sampling interval (s).
    diagnostic : str
        Empty when the automatic fit found a linear region; otherwise why it did not (also issued as a
        ``RuntimeWarning``).
    """

    exponent: float
    times: np.ndarray = field(repr=False)
    divergence: np.ndarray = field(repr=False)
    fit_range: tuple[float, float]
    intercept: float
    r2: float
    lag: int
    dim: int
    min_separation: int
    max_steps: int
    n_pairs: int
    dt: float
    diagnostic: str = ""

    @property
    def lyapunov_time(self) -> float:
        """Lyapunov time ``1 / exponent`` (s); infinite when the exponent is not positive."""
        return lyapunov_time(self.exponent)

    @property
    def fit_line(self) -> np.ndarray:
        """The fitted straight line evaluated at :attr:`times` (for plotting over :attr:`divergence`)."""
        return self.intercept + self.exponent * self.times


def lyapunov_time(exponent: float) -> float:
    """Lyapunov time ``1 / exponent`` (s): how long a small error takes to grow by a factor e.

    Parameters
    ----------
    exponent : float
        Largest Lyapunov exponent (1/s).

    Returns
    -------
    float
        ``1 / exponent``, or ``inf`` when ``exponent <= 0`` (no exponential divergence, unlimited horizon).

    Examples
    --------
    >>> lyapunov_time(0.9056)  # Lorenz system
    1.1042402826855124
    >>> lyapunov_time(-0.1)
    inf
    """
    lam = check_number("exponent (1/s)", exponent)
    return 1.0 / lam if lam > 0 else float("inf")


def _divergence_curve(x: np.ndarray, dim: int, lag: int, max_steps: int, min_separation: int) -> tuple[np.ndarray, int]:
    """Mean log distance of nearest-neighbour pairs after 0..max_steps steps (Rosenstein's <ln d_j(i)>).

    Only the first ``n_vectors - max_steps`` delay vectors are paired (with each other), so that every pair can
    be followed for all ``max_steps`` steps and each point of the curve averages the same pairs. Beyond
    ``_MAX_CURVE_WORK`` pair-steps, only every ``stride``-th delay vector gets a pair (its neighbour is still
    searched among all). Returns the curve and the number of pairs.
    """
    n_vectors = x.size - (dim - 1) * lag
    n_ref = n_vectors - max_steps
    ref = np.ascontiguousarray(_embed(x, dim, lag, n_ref))
    repeat = _repeat_distance(x)
    stride = max(1, int(np.ceil(n_ref * (max_steps + 1) / _MAX_CURVE_WORK)))  # bounded work: every stride-th pair
    i = np.arange(0, n_ref, stride)
    nn, _ = _nearest_neighbours(ref, i, min_separation, repeat)
    i, nn = i[nn >= 0], nn[nn >= 0]
    if i.size == 0:
        raise ValueError(
            "x repeats itself exactly: every delay vector's only neighbours outside the Theiler window are exact "
            "copies of it, so there is no divergence to measure (an exactly periodic or quantized signal: its "
            "exponent is 0)"
        )
    block = int(min(max_steps + 1, max(1, 2_000_000 // i.size)))  # steps per block: bounded memory
    divergence = np.empty(max_steps + 1)
    for k0 in range(0, max_steps + 1, block):
        n_k = min(block, max_steps + 1 - k0)
        d2 = np.zeros((i.size, n_k))
        for m in range(dim):
            rows = _embed(x[k0 + m * lag :], n_k, 1, n_ref)  # rows[r, k] = x[k0 + m * lag + r + k] (a view)
            diff = rows[i] - rows[nn]
            diff *= diff
            d2 += diff
        distinct = d2 > repeat**2  # a pair that lands on an exact repeat has no logarithm: left out of that step
        logs = np.log(d2, out=np.zeros_like(d2), where=distinct)
        with np.errstate(invalid="ignore", divide="ignore"):
            divergence[k0 : k0 + n_k] = 0.5 * logs.sum(axis=0) / distinct.sum(axis=0)
    return divergence, int(i.size)


def _line_fit(t: np.ndarray, y: np.ndarray) -> tuple[float, float, float]:
    """Least-squares slope, intercept and R² of ``y`` against ``t``."""
    tc = t - t.mean()
    slope = float(np.dot(tc, y - y.mean()) / np.dot(tc, tc))
    intercept = float(y.mean() - slope * t.mean())
    ss_tot = float(np.sum((y - y.mean()) ** 2))
    ss_res = float(np.sum((y - intercept - slope * t) ** 2))
    r2 = 1.0 - ss_res / ss_tot if ss_tot > 0 else 1.0
    return slope, intercept, r2


def _auto_fit_window(y: np.ndarray) -> tuple[int, int, str]:
    """Inclusive indices ``[a, b]`` of the automatic fit window on the divergence curve ``y``, and a diagnostic.

    1. Plateau: level = median of the last quarter of the curve, spread = 1.4826 x its median absolute
       deviation. The rise is the plateau level minus the lowest point of the first three quarters.
    2. No rise above ``max(3 x spread, _MIN_RISE)``: no exponential divergence; the whole curve is fitted
       (slope ~ 0) and the diagnostic says so.
    3. Growth region: from the lowest point to where the curve has covered ``_FIT_SATURATION_FRACTION`` of the
       rise. If that takes fewer than ``_MIN_FIT_STEPS`` steps, neighbours separate within a few samples (noise,
       or dynamics too fast for the sampling): no linear region is resolved; the curve after that point is
       fitted (slope ~ 0) and the diagnostic says so.
    4. Otherwise, among windows inside the growth region that span at least ``_FIT_MIN_LENGTH_FRACTION`` of it
       (and at least ``_MIN_FIT_STEPS`` steps), the one with the highest R² of a straight line. Window ends lie
       on a grid of at most 60 points; the R² of all windows come from cumulative sums at once.
    """
    n = y.size
    tail = y[-max(4, n // 4) :]
    plateau = float(np.median(tail))
    spread = 1.4826 * float(np.median(np.abs(tail - plateau)))
    low = int(np.argmin(y[: max(2, n - tail.size)]))
    rise = plateau - float(y[low])
    if rise <= max(3.0 * spread, _MIN_RISE):
        message = (
            f"no exponential divergence: the divergence curve rises {rise:.2f} (natural log) from its lowest point "
            f"to its plateau, within max(3 x its fluctuation {spread:.2f}, {_MIN_RISE}); the whole curve is fitted"
        )
        return 0, n - 1, message
    end = low + int(np.flatnonzero(y[low:] >= y[low] + _FIT_SATURATION_FRACTION * rise)[0])
    if end - low < _MIN_FIT_STEPS:
        message = (
            f"no linear region resolved: the divergence curve covers {100 * _FIT_SATURATION_FRACTION:.0f} % of its "
            f"rise within {end - low} step(s) (a jump: noise, or divergence faster than the sampling resolves); "
            "the curve after the jump is fitted, so the exponent says whether the dynamics above the noise "
            "level diverge"
        )
        return end, n - 1, message
    length = max(_MIN_FIT_STEPS, int(np.ceil(_FIT_MIN_LENGTH_FRACTION * (end - low))))
    grid = np.unique(np.linspace(low, end, min(end - low + 1, 60)).round().astype(np.int64))
    a, b = np.meshgrid(grid, grid, indexing="ij")
    keep = b - a >= length
    a, b = a[keep], b[keep]
    t = np.arange(n, dtype=float)
    yc = y - y[low : end + 1].mean()  # centred for accuracy of the sums
    cs = [np.concatenate(([0.0], np.cumsum(v))) for v in (np.ones(n), t, yc, t * t, yc * yc, t * yc)]
    s0, st, sy, stt, syy, sty = (c[b + 1] - c[a] for c in cs)
    var_t = stt - st * st / s0
    var_y = syy - sy * sy / s0
    cov = sty - st * sy / s0
    with np.errstate(invalid="ignore", divide="ignore"):
        r2 = np.where(var_y > 0, cov * cov / (var_t * var_y), 1.0)
    best = int(np.argmax(np.nan_to_num(r2, nan=-np.inf)))
    return int(a[best]), int(b[best]), ""


@overload
def lyapunov_exponent(
    x: ArrayLike,
    dt: float,
    *,
    dim: int | None = ...,
    lag: int | None = ...,
    min_separation: int | None = ...,
    fit_range: tuple[float, float] | None = ...,
    max_steps: int | None = ...,
    return_details: Literal[False] = ...,
    max_dim: int = ...,
    fnn_threshold: float = ...,
) -> float: ...


@overload
def lyapunov_exponent(
    x: ArrayLike,
    dt: float,
    *,
    dim: int | None = ...,
    lag: int | None = ...,
    min_separation: int | None = ...,
    fit_range: tuple[float, float] | None = ...,
    max_steps: int | None = ...,
    return_details: Literal[True],
    max_dim: int = ...,
    fnn_threshold: float = ...,
) -> LyapunovResult: ...


def lyapunov_exponent(
    x: ArrayLike,
    dt: float,
    *,
    dim: int | None = None,
    lag: int | None = None,
    min_separation: int | None = None,
    fit_range: tuple[float, float] | None = None,
    max_steps: int | None = None,
    return_details: bool = False,
    max_dim: int = 10,
    fnn_threshold: float = 0.01,
) -> float | LyapunovResult:
    """Largest Lyapunov exponent of a scalar signal by the method of Rosenstein, Collins & De Luca (1993).

    1. Delay-embed ``x`` with delay ``lag`` (samples) in ``dim`` dimensions.
    2. Pair every delay vector with its nearest neighbour (Euclidean, ``scipy.spatial.cKDTree``) among those at
       least ``min_separation + 1`` samples away in time (Theiler window).
    3. Follow each pair for ``max_steps`` steps and average the natural log of their distance over all pairs:
       the divergence curve ``y(k dt)``.
    4. Fit a straight line to its linear region; the slope is the exponent (1/s).

    The automatic linear region (``fit_range=None``) is taken from the shape of the curve:

    - *plateau*: the median of the last quarter of the curve (``max_steps`` should reach saturation), and its
      fluctuation (1.4826 x the median absolute deviation);
    - *rise*: from the lowest point of the first three quarters to the plateau. A rise within
      ``max(3 x fluctuation, 0.5)`` (natural log, a factor 1.65) is no exponential divergence: the whole curve is
      fitted, giving ~0 (periodic and quasi-periodic signals);
    - *growth region*: from the lowest point to where the curve has covered 70 % of the rise (the bend into
      saturation comes later). If that takes fewer than 5 steps the rise is a jump (noise separates the
      neighbours within a sample or two): no linear region is resolved, the curve after the jump is fitted
      (~0 for a periodic signal plus noise) and a ``RuntimeWarning`` says so;
    - *fit*: among windows in the growth region spanning at least half of it (and at least 5 steps), the one
      whose straight line has the highest R². This drops an initial transient (pairs first turning into the
      most unstable direction) or the start of the bend, whichever spoils linearity more.

    Inspect the result with ``return_details=True`` (:attr:`LyapunovResult.diagnostic` says when no linear
    region was found) and override it with ``fit_range``.

    Parameters
    ----------
    x : array_like (n_samples,) or (n_samples, 1)
        Scalar signal, uniformly sampled, finite (any unit: the exponent does not depend on it). For a
        multichannel record, call once per channel.
    dt : float
        Sampling interval (s). ``dt=1`` gives the exponent per sample (e.g. per iteration of a map).
    dim : int, optional
        Embedding dimension; default from false nearest neighbours (:func:`embedding_dimension`, up to
        ``max_dim``, with ``fnn_threshold``).
    lag : int, optional
        Embedding delay (samples); default from the mutual information (:func:`delay_embedding_lag`).
    min_separation : int, optional
        Theiler window (samples): neighbours at most this far apart in time are excluded. Default the mean
        period (:func:`mean_period`), rounded up.
    fit_range : (float, float), optional
        Times (s) ``(t_start, t_end)`` on the divergence curve to fit the line over, ``0 <= t_start < t_end <=
        max_steps * dt``; default automatic (above).
    max_steps : int, optional
        Number of steps the pairs are followed. Default ten mean periods, at least 50 steps, and at most a
        quarter of the embedded points. It should reach the saturation plateau for the automatic fit to find the
        linear region.
    return_details : bool
        Return a :class:`LyapunovResult` (curve, fit, embedding) instead of the bare exponent.
    max_dim : int
        Largest dimension tried by false nearest neighbours when ``dim`` is not given.
    fnn_threshold : float
        Acceptable fraction of false nearest neighbours when ``dim`` is not given.

    Returns
    -------
    float or LyapunovResult
        The largest Lyapunov exponent (1/s), or the full result when ``return_details=True``. The Lyapunov time
        is ``1 / exponent`` (s) when positive (:func:`lyapunov_time`, :attr:`LyapunovResult.lyapunov_time`).

    Raises
    ------
    ValueError
        NaN or inf in ``x`` (the message lists the samples), a constant ``x``, ``dt`` not a positive number, bad
        ``dim``/``lag``/``min_separation``/``max_steps``/``fit_range``, or ``x`` too short for the embedding,
        the Theiler window and ``max_steps`` together.

    Warns
    -----
    RuntimeWarning
        When the divergence curve jumps to its plateau within a few steps (no linear region resolved), and from
        :func:`embedding_dimension` when the false-neighbour fraction never reaches ``fnn_threshold``.

    Notes
    -----
    Cost: one k-d tree search per delay vector (oversampled trajectories, whose nearest candidates lie inside the
    Theiler window, go through an exact segment-tree search instead of ever larger candidate lists), then
    ``n_pairs x (max_steps + 1)`` distances. Beyond 6e7 pair-steps every ``s``-th delay vector is followed
    (evenly thinned; :attr:`LyapunovResult.n_pairs` says how many), so 50,000 samples take a second or two.

    Noise and random forcing also separate neighbours, so a positive exponent does not by itself prove chaos: for
    a linear structure driven by random loads the slope says how quickly the forcing decorrelates two nearby
    states. Look at the curve: a clean straight segment over several e-folds followed by a plateau is the mark of
    deterministic chaos; a jump in the first steps followed by a slow bend is the mark of noise.

    Examples
    --------
    A sine is not chaotic; its exponent is close to zero (1/s):

    >>> import numpy as np
    >>> t = np.arange(6000) * 0.01
    >>> lam = lyapunov_exponent(np.sin(2 * np.pi * 0.5 * t), dt=0.01)
    >>> abs(lam) < 0.05
    True

    The logistic map at r = 4 has exponent ln 2 per iteration:

    >>> x = np.empty(3000)
    >>> x[0] = 0.3
    >>> for i in range(x.size - 1):
    ...     x[i + 1] = 4.0 * x[i] * (1.0 - x[i])
    >>> res = lyapunov_exponent(x, dt=1.0, dim=1, lag=1, return_details=True)
    >>> bool(abs(res.exponent - np.log(2)) < 0.1)
    True
    """
    dt = _check_dt(dt)
    x = _as_signal(x, min_samples=16)
    # the exponent does not depend on the unit or the offset: work on a standardised copy, so that squared
    # distances of 1e-160-sized (or 1e+150-sized) data neither underflow to 0 nor overflow
    x = x / np.max(np.abs(x))
    x = (x - x.mean()) / x.std()
    # cheap checks first, before any embedding search
    lag = None if lag is None else check_int("lag (samples)", lag, minimum=1)
    dim = None if dim is None else check_int("dim", dim, minimum=1)
    max_steps = None if max_steps is None else check_int("max_steps", max_steps, minimum=2)
    max_dim = check_int("max_dim", max_dim, minimum=1)
    fnn_threshold = check_number("fnn_threshold", fnn_threshold, low=0.0, high=1.0)
    if fit_range is not None:
        _check_fit_range(fit_range, None, dt)
    theiler = _theiler(x, min_separation)
    if lag is None:
        lag = delay_embedding_lag(x)
    if dim is None:
        dim = embedding_dimension(x, lag, max_dim=max_dim, threshold=fnn_threshold, min_separation=theiler)
    n_vectors = x.size - (dim - 1) * lag
    if max_steps is None:
        max_steps = int(min(max(50, round(10 * _mean_period_samples(x))), max(2, n_vectors // 4)))
    n_ref = n_vectors - max_steps
    if n_ref < max(_MIN_REFERENCE_POINTS, 2 * theiler + 2):
        needed = (dim - 1) * lag + max_steps + max(_MIN_REFERENCE_POINTS, 2 * theiler + 2)
        raise ValueError(
            f"x has {x.size} samples, too short for dim={dim}, lag={lag}, max_steps={max_steps} and "
            f"min_separation={theiler}: needs at least (dim - 1) * lag + max_steps + "
            f"max({_MIN_REFERENCE_POINTS}, 2 * min_separation + 2) = {needed} samples; give a longer signal or "
            "smaller dim, lag, max_steps or min_separation"
        )
    if fit_range is not None:
        a, b = _check_fit_range(fit_range, max_steps, dt)
    divergence, n_pairs = _divergence_curve(x, dim, lag, max_steps, theiler)
    lost = np.flatnonzero(~np.isfinite(divergence))
    if lost.size:
        raise ValueError(
            f"x repeats itself exactly: after {int(lost[0])} step(s) every followed pair of neighbours lands on an "
            "exact repeat (zero distance), so the divergence curve is undefined there (a signal that is constant "
            "but for a few samples, or quantized to a few levels)"
        )
    diagnostic = ""
    if fit_range is None:
        a, b, diagnostic = _auto_fit_window(divergence)
        if diagnostic.startswith("no linear region"):
            warnings.warn(diagnostic, RuntimeWarning, stacklevel=2)
    times = np.arange(max_steps + 1) * dt
    slope, intercept, r2 = _line_fit(times[a : b + 1], divergence[a : b + 1])
    if not return_details:
        return slope
    return LyapunovResult(
        exponent=slope,
        times=times,
        divergence=divergence,
        fit_range=(float(times[a]), float(times[b])),
        intercept=intercept,
        r2=r2,
        lag=lag,
        dim=dim,
        min_separation=theiler,
        max_steps=max_steps,
        n_pairs=n_pairs,
        dt=dt,
        diagnostic=diagnostic,
    )


def _check_fit_range(fit_range: object, max_steps: int | None, dt: float) -> tuple[int, int]:
    """Fit-range times (s) -> inclusive step indices, with at least two steps (range unchecked if no max_steps)."""
    if not isinstance(fit_range, (tuple, list)) or len(fit_range) != 2:
        raise ValueError(f"fit_range must be a pair (t_start, t_end) in seconds, got {fit_range!r}")
    t0 = check_number("fit_range[0] (s)", fit_range[0], nonneg=True)
    t1 = check_number("fit_range[1] (s)", fit_range[1], nonneg=True)
    if not t0 < t1:
        raise ValueError(f"fit_range must have t_start < t_end (seconds), got {fit_range!r}")
    a = int(np.ceil(t0 / dt - 1e-9))
    b = int(np.floor(t1 / dt + 1e-9))
    if max_steps is not None and b > max_steps:
        raise ValueError(
            f"fit_range end {t1:g} s lies beyond the divergence curve, which ends at max_steps * dt = "
            f"{max_steps * dt:g} s (max_steps = {max_steps}); give a larger max_steps or a shorter fit_range"
        )
    if b - a < 1:
        raise ValueError(f"fit_range {fit_range!r} holds fewer than two steps of dt = {dt:g} s")
    return a, b

"""Tools to compare and summarise mode shapes across identification methods and records.

* :func:`mac` -- the modal assurance criterion (Allemang & Brown 1982), complex-aware.
* :func:`pair_modes` -- one-to-one pairing of two mode sets (e.g. a linearised model, SSI-COV, Hankel-DMD) by a
  cost that adds the relative frequency distance and ``1 - MAC``, solved as a linear assignment problem.
* :func:`real_mode_shape` -- a complex shape rotated to be as real as possible, scaled to unit max modulus.
* :func:`probabilistic_mode_shapes` -- the seed paper's probabilistic mode shapes (its Fig. 8): Hankel-DMD over an
  ensemble of records and a range of delays, the mode nearest each target frequency, and the mean shape with a
  95 % band.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from numbers import Integral

import numpy as np
from scipy.optimize import linear_sum_assignment

from .hankel_dmd import HankelDMD
from .validation import MAX_ABS, as_records, check_int, check_number

__all__ = ["ModeShapeDistribution", "mac", "pair_modes", "probabilistic_mode_shapes", "real_mode_shape"]

_FORBIDDEN = 1e6  # assignment cost of a pair outside the tolerances


def _as_shapes(x: object, name: str) -> np.ndarray:
    """Validate mode shapes: 1-D (one mode) or 2-D (p x n_modes, columns = modes), finite, real or complex."""
    try:
        arr = np.asarray(x)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be a numeric array, got {type(x).__name__}: {exc}") from exc
    if arr.dtype == object or not np.issubdtype(arr.dtype, np.number):
        raise ValueError(f"{name} must be a numeric array, got dtype {arr.dtype}")
    if arr.ndim not in (1, 2) or arr.size == 0:
        raise ValueError(f"{name} must be a non-empty vector (p,) or a matrix (p, n_modes), got shape {arr.shape}")
    arr = arr.astype(complex) if np.iscomplexobj(arr) else arr.astype(float)
    if not np.isfinite(arr).all():
        bad = np.flatnonzero(~np.isfinite(arr).all(axis=0)) if arr.ndim == 2 else np.flatnonzero(~np.isfinite(arr))
        what = "columns (modes)" if arr.ndim == 2 else "entries"
        raise ValueError(f"{name} must be finite: NaN/inf in {what} {bad[:5].tolist()}")
    return arr


def mac(a: object, b: object) -> float | np.ndarray:
    """Modal assurance criterion ``|a^H b|^2 / ((a^H a)(b^H b))`` between mode shapes.

    Parameters
    ----------
    a, b : array_like (p,) or (p, n_modes), real or complex
        Mode shapes; in a matrix each column is one mode. Both must have the same number ``p`` of rows (DOFs or
        channels).

    Returns
    -------
    float or ndarray
        In [0, 1] (dimensionless): a float for two vectors; otherwise ``MAC[i, j]`` between column ``i`` of ``a``
        and column ``j`` of ``b``, of shape ``(n_a, n_b)``, ``(n_b,)`` for a vector ``a``, ``(n_a,)`` for a vector
        ``b``. Insensitive to the (complex) scaling of either shape.

    Raises
    ------
    ValueError
        Non-numeric, non-finite or empty input, more than 2 dimensions, different ``p``, or a zero shape.

    Examples
    --------
    >>> import numpy as np
    >>> mac([1.0, 2.0, 3.0], [2.0, 4.0, 6.0])
    1.0
    >>> mac([1.0, 0.0], [0.0, 1.0])
    0.0
    >>> phi = np.array([1.0, 0.5 + 0.1j, -0.3j])
    >>> round(mac(phi, (2.0 - 1.0j) * phi), 12)
    1.0
    >>> mac(np.eye(3), np.eye(3)[:, :2]).shape
    (3, 2)
    """
    A = _as_shapes(a, "a")
    B = _as_shapes(b, "b")
    if A.shape[0] != B.shape[0]:
        raise ValueError(f"a and b must have the same number of rows (DOFs), got {A.shape[0]} and {B.shape[0]}")
    A2 = A[:, None] if A.ndim == 1 else A
    B2 = B[:, None] if B.ndim == 1 else B
    na = np.real(np.einsum("ij,ij->j", A2.conj(), A2))
    nb = np.real(np.einsum("ij,ij->j", B2.conj(), B2))
    for name, norms in (("a", na), ("b", nb)):
        if np.any(norms == 0):
            raise ValueError(f"{name} has zero mode shape(s) {np.flatnonzero(norms == 0).tolist()}: MAC is undefined")
    M = np.abs(A2.conj().T @ B2) ** 2 / (na[:, None] * nb[None, :])
    M = np.clip(M, 0.0, 1.0)
    if A.ndim == 1 and B.ndim == 1:
        return float(M[0, 0])
    if A.ndim == 1:
        return M[0]
    if B.ndim == 1:
        return M[:, 0]
    return M


def _as_freqs(x: object, name: str) -> np.ndarray:
    try:
        f = np.asarray(x, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be a 1-D array of frequencies (Hz), got {x!r}") from exc
    if f.ndim == 0:
        f = f[None]
    if f.ndim != 1:
        raise ValueError(f"{name} must be a 1-D array of frequencies (Hz), got shape {f.shape}")
    if not (np.isfinite(f).all() and (f > 0).all()):
        raise ValueError(f"{name} must hold finite frequencies > 0 Hz, got {f.tolist()}")
    return f


def pair_modes(
    freq_a: object,
    shapes_a: object,
    freq_b: object,
    shapes_b: object,
    max_freq_rel: float = 0.1,
    min_mac: float | None = None,
    *,
    mac_weight: float = 1.0,
) -> list[dict]:
    """Pair the modes of two sets one-to-one (e.g. a linearised model against SSI-COV or Hankel-DMD).

    The cost of pairing mode ``i`` of ``a`` with mode ``j`` of ``b`` is
    ``|f_b[j] - f_a[i]| / f_a[i] + mac_weight * (1 - MAC[i, j])``; the assignment minimising the total cost
    (:func:`scipy.optimize.linear_sum_assignment`) is found over the admissible pairs (relative frequency distance
    at most ``max_freq_rel`` and, if given, MAC at least ``min_mac``). Modes left without an admissible partner
    are not reported.

    Parameters
    ----------
    freq_a, freq_b : array_like (n_a,), (n_b,)
        Frequencies (Hz, > 0). ``a`` is the reference of the relative error.
    shapes_a, shapes_b : array_like (p, n_a), (p, n_b) or None
        Mode shapes, columns = modes, same ``p`` (real or complex). ``None`` for either: pair by frequency only
        (``mac`` is then NaN and ``min_mac`` must be None).
    max_freq_rel : float
        Largest admissible ``|f_b - f_a| / f_a`` (default 10 %).
    min_mac : float, optional
        Smallest admissible MAC, in [0, 1].
    mac_weight : float
        Weight of ``1 - MAC`` against the relative frequency distance (default 1).

    Returns
    -------
    list of dict
        One per pair, in ascending ``index_a``: ``index_a``, ``index_b``, ``freq_a``, ``freq_b`` (Hz),
        ``freq_rel_error`` = ``(freq_b - freq_a) / freq_a`` and ``mac``.

    Examples
    --------
    >>> import numpy as np
    >>> shapes = np.array([[1.0, 1.0, 1.0], [1.0, 0.0, -1.0], [1.0, -1.0, 1.0]])
    >>> pairs = pair_modes([0.5, 1.2, 2.0], shapes, [2.02, 0.49, 1.25], shapes[:, [2, 0, 1]])
    >>> [(p["index_a"], p["index_b"]) for p in pairs]
    [(0, 1), (1, 2), (2, 0)]
    >>> round(pairs[0]["freq_rel_error"], 3), pairs[0]["mac"]
    (-0.02, 1.0)
    """
    fa = _as_freqs(freq_a, "freq_a")
    fb = _as_freqs(freq_b, "freq_b")
    tol = check_number("max_freq_rel", max_freq_rel, positive=True)
    w = check_number("mac_weight", mac_weight, nonneg=True)
    use_shapes = shapes_a is not None and shapes_b is not None
    if use_shapes:
        Sa = _as_shapes(shapes_a, "shapes_a")
        Sb = _as_shapes(shapes_b, "shapes_b")
        Sa = Sa[:, None] if Sa.ndim == 1 else Sa
        Sb = Sb[:, None] if Sb.ndim == 1 else Sb
        if Sa.shape[1] != fa.size:
            raise ValueError(f"shapes_a must have one column per frequency: {fa.size} frequencies, shape {Sa.shape}")
        if Sb.shape[1] != fb.size:
            raise ValueError(f"shapes_b must have one column per frequency: {fb.size} frequencies, shape {Sb.shape}")
        if Sa.shape[0] != Sb.shape[0]:
            raise ValueError(
                f"shapes_a and shapes_b must have the same number of rows (DOFs), got {Sa.shape[0]} and {Sb.shape[0]}"
            )
        M = np.atleast_2d(mac(Sa, Sb))
    else:
        if min_mac is not None:
            raise ValueError("min_mac needs both shapes_a and shapes_b")
        M = np.full((fa.size, fb.size), np.nan)
    rel = (fb[None, :] - fa[:, None]) / fa[:, None]
    ok = np.abs(rel) <= tol
    cost = np.abs(rel)
    if use_shapes:
        cost = cost + w * (1.0 - M)
        if min_mac is not None:
            mm = check_number("min_mac", min_mac, nonneg=True)
            if mm > 1:
                raise ValueError(f"min_mac must be in [0, 1], got {min_mac!r}")
            ok &= M >= mm
    cost = np.where(ok, cost, _FORBIDDEN)
    rows, cols = linear_sum_assignment(cost)
    out = []
    for i, j in zip(rows, cols, strict=True):
        if not ok[i, j]:
            continue
        out.append(
            {
                "index_a": int(i),
                "index_b": int(j),
                "freq_a": float(fa[i]),
                "freq_b": float(fb[j]),
                "freq_rel_error": float(rel[i, j]),
                "mac": float(M[i, j]),
            }
        )
    return out


def real_mode_shape(shape: object, ref: int | None = None) -> np.ndarray:
    """A (complex) mode shape as a real vector: rotated to be as real as possible, unit max modulus, sign fixed.

    The rotation ``e^{i theta}`` maximises ``||Re(e^{i theta} phi)||^2``: ``theta = -arg(sum phi_k^2) / 2``.
    The real part is divided by its largest modulus, and the sign chosen so that entry ``ref`` (default: the
    largest in modulus) is positive.

    Parameters
    ----------
    shape : array_like (p,), real or complex
    ref : int, optional
        Channel whose entry is made positive.

    Returns
    -------
    ndarray (p,) of float
        Max modulus 1 (dimensionless).

    Examples
    --------
    >>> import numpy as np
    >>> real_mode_shape(np.array([0.5, -1.0, 0.25]) * np.exp(0.7j))
    array([-0.5 ,  1.  , -0.25])
    """
    phi = _as_shapes(shape, "shape")
    if phi.ndim != 1:
        raise ValueError(f"shape must be one vector (p,), got shape {phi.shape}")
    phi = phi.astype(complex)
    if not np.any(phi):
        raise ValueError("shape is zero: it has no direction to normalise")
    theta = -0.5 * np.angle(np.sum(phi**2))
    v = np.real(phi * np.exp(1j * theta))
    if not np.any(v):  # pragma: no cover - sum(phi^2) = 0 only for degenerate shapes; any real part will do
        v = np.imag(phi)
    v = v / np.max(np.abs(v))
    k = int(np.argmax(np.abs(v))) if ref is None else check_int("ref", ref, minimum=0, maximum=v.size - 1)
    return -v if v[k] < 0 else v


@dataclass(frozen=True)
class ModeShapeDistribution:
    """The distribution of one mode's shape over an ensemble of Hankel-DMD fits.

    Attributes
    ----------
    target_frequency_hz : float
        The target frequency (Hz).
    mean : ndarray (p,)
        Mean normalised shape (NaN if no fit found the mode).
    lower, upper : ndarray (p,)
        Lower and upper percentiles per channel (default 2.5 % and 97.5 %: a 95 % band).
    shapes : ndarray (n_found, p)
        The normalised real shapes, one per fit that found the mode (unit max modulus).
    frequencies_hz : ndarray (n_found,)
        Identified (damped) frequency of each found mode (Hz).
    damping_ratios : ndarray (n_found,)
    record_index : ndarray (n_found,) of int
        Record each shape comes from.
    delays : ndarray (n_found,) of int
        Delay depth of each fit (samples).
    n_fits : int
        Number of fits (records x delays).
    ref_channel : int
        Channel whose entry is positive in every shape (sign convention).
    """

    target_frequency_hz: float
    mean: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    shapes: np.ndarray
    frequencies_hz: np.ndarray
    damping_ratios: np.ndarray
    record_index: np.ndarray
    delays: np.ndarray
    n_fits: int
    ref_channel: int

    @property
    def n_found(self) -> int:
        """Number of fits in which a mode was found near the target."""
        return int(self.shapes.shape[0])


def probabilistic_mode_shapes(
    records: object,
    dt: float,
    delays: Iterable[int] = range(45, 76, 5),
    rank: int | float | str = 24,
    *,
    target_frequencies_hz: Sequence[float],
    max_freq_rel: float = 0.1,
    kinds: Sequence[str] = ("structural",),
    percentiles: tuple[float, float] = (2.5, 97.5),
    **hankel_kwargs: object,
) -> list[ModeShapeDistribution]:
    """Probabilistic mode shapes from Hankel-DMD over an ensemble of records and delay depths (seed paper Fig. 8).

    For every record and every delay ``d`` a :class:`estimators.hankel_dmd.HankelDMD` is fitted; among its modes of
    the given ``kinds`` (see :meth:`HankelDMD.mode_table`) the targets are paired one-to-one with the nearest modes
    in frequency (within ``max_freq_rel``). Each found physical shape (first ``p`` rows of the DMD mode) is made
    real by :func:`real_mode_shape` (rotated to maximise realness, unit max modulus, largest entry positive); the
    sign is then aligned over the ensemble so that the reference channel -- the one with the largest mean
    modulus -- is positive in every shape (the same as "largest entry positive" whenever that entry is always on
    the same channel).

    Parameters
    ----------
    records : array_like (n_samples, p) or list of such arrays
        The ensemble; each record is fitted on its own (usually band-passed and z-scored).
    dt : float
        Sampling interval (s).
    delays : iterable of int
        Delay depths (samples); default 45, 50, ..., 75 as in the seed paper.
    rank : int, float or "auto"
        Hankel-DMD rank (default 24, the seed paper's value for identification).
    target_frequencies_hz : sequence of float
        Frequencies (Hz) of the modes to follow, e.g. the 1st and 2nd tower modes of a model.
    max_freq_rel : float
        Largest relative distance between a target and the mode taken for it (default 10 %).
    kinds : sequence of str
        Mode kinds eligible (default ``("structural",)``; add ``"harmonic"`` or ``"noise"`` to widen).
    percentiles : (float, float)
        Lower and upper percentiles (%) of the band (default 2.5 and 97.5).
    **hankel_kwargs
        Passed to :class:`HankelDMD` (``method``, ``missing``, ...).

    Returns
    -------
    list of ModeShapeDistribution
        One per target, in the order given.

    Raises
    ------
    ValueError
        Bad records (NaN, constant channels, too short for the largest delay), no delays, bad targets or band.

    Examples
    --------
    Two modes (0.5 Hz and 1.3 Hz, 2 % damping) seen by three sensors, three records of 150 s:

    >>> import numpy as np
    >>> from scipy import signal
    >>> rng = np.random.default_rng(1)
    >>> true = np.array([[1.0, 0.6, -0.8], [0.4, -1.0, 0.9]])  # rows: the two shapes over the 3 sensors
    >>> def record(n=3000, dt=0.05):
    ...     q = []
    ...     for f, z in [(0.5, 0.02), (1.3, 0.02)]:
    ...         w = 2 * np.pi * f
    ...         b, a = signal.cont2discrete(([1.0], [1.0, 2 * z * w, w * w]), dt, method="impulse")[:2]
    ...         q.append(signal.lfilter(np.ravel(b), a, rng.standard_normal(n)))
    ...     return np.c_[q[0] / q[0].std(), q[1] / q[1].std()] @ true
    >>> out = probabilistic_mode_shapes([record() for _ in range(3)], 0.05, delays=[20, 30], rank=8,
    ...                                 target_frequencies_hz=[0.5, 1.3])
    >>> [d.n_found for d in out], out[0].n_fits
    ([6, 6], 6)
    >>> np.round(out[0].mean, 1)
    array([ 1. ,  0.6, -0.8])
    >>> np.round(out[1].mean, 1)  # largest entry positive: the second shape times -1
    array([-0.4,  1. , -0.9])
    >>> bool(mac(out[1].mean, true[1]) > 0.999 and np.all(out[1].lower <= out[1].upper))
    True
    """
    dt = check_number("dt", dt, positive=True)
    targets = _as_freqs(target_frequencies_hz, "target_frequencies_hz")
    tol = check_number("max_freq_rel", max_freq_rel, positive=True)
    if isinstance(delays, (Integral, str, bytes)):
        raise ValueError(f"delays must be an iterable of ints (samples), got {delays!r}")
    delay_list = [check_int(f"delays[{k}]", d, minimum=1) for k, d in enumerate(delays)]
    if not delay_list:
        raise ValueError("delays must list at least one delay depth")
    if isinstance(kinds, str):
        kinds = (kinds,)
    kinds = tuple(kinds)
    allowed = {"structural", "harmonic", "noise"}
    if not kinds or not set(kinds) <= allowed:
        raise ValueError(f"kinds must be a non-empty subset of {sorted(allowed)}, got {kinds!r}")
    if not isinstance(percentiles, (tuple, list)) or len(percentiles) != 2:
        raise ValueError(f"percentiles must be a pair (lower, upper) in %, got {percentiles!r}")
    lo_pct = check_number("percentiles[0]", percentiles[0], nonneg=True)
    hi_pct = check_number("percentiles[1]", percentiles[1], nonneg=True)
    if not lo_pct < hi_pct <= 100:
        raise ValueError(f"percentiles must satisfy 0 <= lower < upper <= 100, got {percentiles!r}")
    recs = as_records(records, "records", allow_nan=hankel_kwargs.get("missing") == "split", max_abs=MAX_ABS)
    p = recs[0].shape[1]

    found: list[list[tuple]] = [[] for _ in targets]
    for r_idx, y in enumerate(recs):
        for d in delay_list:
            dmd = HankelDMD(delays=d, rank=rank, dt=dt, **hankel_kwargs).fit(y)
            rows = [row for row in dmd.mode_table() if row["kind"] in kinds and row["frequency_hz"] > 0]
            if not rows:
                continue
            freqs = np.array([row["frequency_hz"] for row in rows])
            for pair in pair_modes(targets, None, freqs, None, max_freq_rel=tol):
                row = rows[pair["index_b"]]
                shape = real_mode_shape(dmd.modes_[:, row["index"]])
                found[pair["index_a"]].append((shape, row["frequency_hz"], row["damping_ratio"], r_idx, d))

    out = []
    n_fits = len(recs) * len(delay_list)
    for t, items in zip(targets, found, strict=True):
        if not items:
            nan = np.full(p, np.nan)
            empty = np.zeros(0)
            out.append(
                ModeShapeDistribution(
                    float(t), nan, nan.copy(), nan.copy(), np.zeros((0, p)), empty, empty.copy(),
                    np.zeros(0, int), np.zeros(0, int), n_fits, -1,
                )
            )  # fmt: skip
            continue
        S = np.stack([it[0] for it in items])
        ref = int(np.argmax(np.mean(np.abs(S), axis=0)))
        S = S * np.where(S[:, ref] < 0, -1.0, 1.0)[:, None]
        lower, upper = np.percentile(S, [lo_pct, hi_pct], axis=0)
        out.append(
            ModeShapeDistribution(
                target_frequency_hz=float(t),
                mean=S.mean(axis=0),
                lower=lower,
                upper=upper,
                shapes=S,
                frequencies_hz=np.array([it[1] for it in items]),
                damping_ratios=np.array([it[2] for it in items]),
                record_index=np.array([it[3] for it in items], dtype=int),
                delays=np.array([it[4] for it in items], dtype=int),
                n_fits=n_fits,
                ref_channel=ref,
            )
        )
    return out

"""Hankel-DMD against independent truths: closed-form damped sinusoids, a textbook dense implementation written
here, PyDMD, Gavish-Donoho on known-rank data, and record boundaries."""

import doctest
import warnings

import numpy as np
import pytest
from scipy import signal

import estimators.hankel_dmd as hd
import estimators.validation as validation
from estimators.hankel_dmd import HankelDMD, harmonic_candidates, svht_omega, svht_rank
from estimators.validation import NotFittedError

DT = 0.0125
MODES = [(0.48, 0.02), (0.605, 0.0), (1.55, 0.01)]  # (frequency Hz, damping ratio)


def damped_sinusoids(n=2000, p=5, dt=DT, modes=MODES, seed=0, noise=0.0):
    """Noise-free (by default) sum of damped sinusoids mixed into p channels, and the true discrete eigenvalues."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * dt
    cols, mus = [], []
    for k, (f, z) in enumerate(modes):
        w = 2 * np.pi * f
        lam = -z * w + 1j * w * np.sqrt(1 - z * z)
        cols.append(np.exp(lam.real * t) * np.cos(lam.imag * t + 0.7 * k))
        mus += [np.exp(lam * dt), np.exp(np.conj(lam) * dt)]
    Y = np.stack(cols, 1) @ rng.standard_normal((len(modes), p))
    return Y + noise * rng.standard_normal(Y.shape), np.array(mus)


def textbook_eigs(records, d, r):
    """Exact DMD the textbook way: explicit Hankel matrices (per record, side by side), thin SVD, eig."""
    Xs, Xps = [], []
    for Y in records:
        H = np.vstack([Y[i : len(Y) - d + 1 + i].T for i in range(d)])  # row i*p + c = channel c at delay i
        Xs.append(H[:, :-1])
        Xps.append(H[:, 1:])
    X, Xp = np.hstack(Xs), np.hstack(Xps)
    U, s, Vt = np.linalg.svd(X, full_matrices=False)
    Atilde = U[:, :r].T @ Xp @ Vt[:r].T / s[:r]
    return np.linalg.eigvals(Atilde), s


def sort_eigs(mu):
    mu = np.asarray(mu)
    return mu[np.lexsort((mu.imag, mu.real))]


def rel_err(a, b):
    a, b = sort_eigs(a), sort_eigs(b)
    return np.max(np.abs(a - b)) / np.max(np.abs(b))


def random_vibration(n=12000, dt=0.05, seed=0, harmonic=0.5):
    """Two randomly excited modes (0.48 Hz 2 %, 1.5 Hz 1 %) and a forced line at 0.605 Hz, 6 channels + noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * dt
    comps = []
    for f, z in [(0.48, 0.02), (1.5, 0.01)]:
        w = 2 * np.pi * f
        pole = np.exp((-z * w + 1j * w * np.sqrt(1 - z * z)) * dt)
        x = signal.lfilter([1.0], [1.0, -2 * pole.real, abs(pole) ** 2], rng.standard_normal(n + 2000))[2000:]
        comps.append(x / x.std())
    comps.append(harmonic * np.sqrt(2) * np.cos(2 * np.pi * 0.605 * t + 0.3))
    return np.stack(comps, 1) @ rng.standard_normal((3, 6)) + 0.1 * rng.standard_normal((n, 6))


# ---------------------------------------------------------------------------------------------- known answers
@pytest.mark.parametrize("method", ["dense", "gram", "randomized"])
def test_identifies_damped_sinusoids_exactly(method):
    Y, mu_true = damped_sinusoids()
    dmd = HankelDMD(delays=20, rank=6, dt=DT, method=method).fit(Y)
    assert dmd.rank_ == 6 and dmd.method_ == method
    assert rel_err(dmd.eigenvalues_, mu_true) < 1e-6
    lam = np.log(mu_true) / DT
    f_true = np.sort(lam.imag / (2 * np.pi))
    z_true = -lam.real / np.abs(lam)
    np.testing.assert_allclose(np.sort(dmd.frequencies_hz_), f_true, rtol=1e-6)
    for f, z in MODES:
        i = np.argmin(np.abs(dmd.frequencies_hz_ - f * np.sqrt(1 - z * z)))
        assert dmd.damping_ratios_[i] == pytest.approx(z, abs=1e-6)
    assert z_true.size == 6


def test_attributes_shapes_and_reconstruction():
    Y, _ = damped_sinusoids(n=1500, p=4)
    dmd = HankelDMD(delays=15, rank=6, dt=DT).fit(Y)
    assert dmd.modes_.shape == (4, 6) and dmd.hankel_modes_.shape == (60, 6)
    assert dmd.amplitudes_.shape == (6,) and dmd.singular_values_.shape == (60,)
    assert dmd.delays_ == 15 and dmd.dt_ == DT and dmd.n_snapshots_ == 1500 - 15
    np.testing.assert_allclose(dmd.modes_, dmd.hankel_modes_[:4])
    assert dmd.mode_energies_.sum() == pytest.approx(1.0)
    # noise-free data: the free run from the first window reproduces the record, the forecast its continuation
    np.testing.assert_allclose(dmd.reconstruct(), Y, atol=1e-6 * np.abs(Y).max())
    Y_long, _ = damped_sinusoids(n=1800, p=4)
    np.testing.assert_allclose(dmd.predict(300), Y_long[1500:], atol=1e-6 * np.abs(Y).max())
    np.testing.assert_allclose(dmd.predict(50, initial=Y[:700]), Y[700:750], atol=1e-6 * np.abs(Y).max())


# ------------------------------------------------------------------------------------- dense textbook and PyDMD
@pytest.mark.parametrize("method", ["dense", "gram"])
@pytest.mark.parametrize("rank", [6, 20])
def test_exact_methods_agree_with_textbook(method, rank):
    Y, _ = damped_sinusoids(n=1500, p=5, noise=0.05, seed=1)
    ref, s_ref = textbook_eigs([Y], 20, rank)
    dmd = HankelDMD(delays=20, rank=rank, method=method).fit(Y)
    assert rel_err(dmd.eigenvalues_, ref) < 1e-8
    np.testing.assert_allclose(dmd.singular_values_, s_ref, rtol=1e-7, atol=1e-9 * s_ref[0])


def test_randomized_agrees_with_textbook_on_the_signal_subspace():
    Y, _ = damped_sinusoids(n=1500, p=5, noise=0.05, seed=1)
    ref, _ = textbook_eigs([Y], 20, 6)
    dmd = HankelDMD(delays=20, rank=6, method="randomized").fit(Y)
    assert rel_err(dmd.eigenvalues_, ref) < 1e-6
    more_power = HankelDMD(delays=20, rank=6, method="randomized", n_power_iter=5).fit(Y)
    assert rel_err(more_power.eigenvalues_, ref) < 1e-10


def test_matches_pydmd():
    pydmd = pytest.importorskip("pydmd", reason="PyDMD is a test-only dependency: pip install pydmd")
    rng = np.random.default_rng(4)
    Y, _ = damped_sinusoids(n=3000, p=6, noise=0.0, seed=4)
    Y = Y + 0.05 * rng.standard_normal(Y.shape)
    for d, r in [(30, 8), (40, 24)]:
        ref = pydmd.HankelDMD(svd_rank=r, d=d, exact=True).fit(Y.T)  # PyDMD: (n_features, n_snapshots)
        for method in ("gram", "dense"):
            dmd = HankelDMD(delays=d, rank=r, method=method).fit(Y)
            assert rel_err(dmd.eigenvalues_, ref.eigs) < 1e-6
        # exact DMD modes too: same columns up to a complex factor (MAC = 1)
        order_ours = np.lexsort((dmd.eigenvalues_.imag, dmd.eigenvalues_.real))
        order_ref = np.lexsort((ref.eigs.imag, ref.eigs.real))
        A, B = dmd.hankel_modes_[:, order_ours], ref.modes[:, order_ref]
        mac = np.abs(np.sum(A.conj() * B, 0)) ** 2 / (np.sum(np.abs(A) ** 2, 0) * np.sum(np.abs(B) ** 2, 0))
        assert mac.min() > 1 - 1e-6


# ------------------------------------------------------------------------------------------------ structure
@pytest.mark.parametrize("n, p, d", [(60, 3, 5), (400, 4, 12), (1500, 5, 40)])
def test_gram_blocks_equal_dense_products(n, p, d):
    y = np.random.default_rng(n).standard_normal((n, p)) + 3.0
    Z = np.vstack([y[i : n - d + i].T for i in range(d + 1)])  # (d+1)-delay Hankel of the n-d snapshot pairs
    ZZ = hd._extended_gram(y, d)
    np.testing.assert_allclose(ZZ, Z @ Z.T, rtol=0, atol=1e-12 * np.abs(Z @ Z.T).max())


def test_hankel_products_equal_dense_products():
    rng = np.random.default_rng(2)
    records = [rng.standard_normal((300, 3)), rng.standard_normal((220, 3))]
    d = 17
    ops = hd._HankelProducts(records, d)
    X = np.hstack([np.vstack([y[i : len(y) - d + i].T for i in range(d)]) for y in records])
    Xp = np.hstack([np.vstack([y[1 + i : len(y) - d + 1 + i].T for i in range(d)]) for y in records])
    V = rng.standard_normal((X.shape[1], 4))
    U = rng.standard_normal((X.shape[0], 4))
    np.testing.assert_allclose(ops.matmat(V), X @ V, atol=1e-11)
    np.testing.assert_allclose(ops.matmat(V, shift=1), Xp @ V, atol=1e-11)
    np.testing.assert_allclose(ops.rmatmat(U), X.T @ U, atol=1e-11)
    np.testing.assert_allclose(ops.rmatmat(U, shift=1), Xp.T @ U, atol=1e-11)


@pytest.mark.parametrize("method", ["dense", "gram", "randomized"])
def test_list_of_records_never_crosses_boundaries(method):
    Y1, _ = damped_sinusoids(n=900, p=4, noise=0.02, seed=5)
    Y2, _ = damped_sinusoids(n=700, p=4, noise=0.02, seed=6)
    d, r = 12, 6
    ref, _ = textbook_eigs([Y1, Y2], d, r)
    dmd = HankelDMD(delays=d, rank=r, method=method).fit([Y1, Y2])
    assert dmd.n_records_ == 2 and dmd.n_snapshots_ == (900 - d) + (700 - d)
    assert rel_err(dmd.eigenvalues_, ref) < 1e-8
    # stacking the records as one would add columns that span the joint: a different answer
    joined, _ = textbook_eigs([np.vstack([Y1, Y2])], d, r)
    assert rel_err(joined, ref) > 1e-4


def test_missing_split_fits_the_finite_pieces():
    Y, _ = damped_sinusoids(n=1600, p=4, noise=0.02, seed=7)
    Yn = Y.copy()
    Yn[700:710, 2] = np.nan
    Yn[1590, 0] = np.nan  # leaves a 9-sample tail, too short to use
    split = HankelDMD(delays=12, rank=6, missing="split").fit(Yn)
    ref = HankelDMD(delays=12, rank=6).fit([Y[:700], Y[710:1590]])
    np.testing.assert_allclose(sort_eigs(split.eigenvalues_), sort_eigs(ref.eigenvalues_), rtol=1e-12)
    assert split.n_records_ == 2 and split.n_dropped_samples_ == 10 + 1 + 9


def test_delays_in_seconds():
    Y, _ = damped_sinusoids(n=800, p=3)
    assert HankelDMD(delays=0.25, rank=6, dt=DT).fit(Y).delays_ == 20


# --------------------------------------------------------------------------------------------------- rank
def test_svht_recovers_rank_of_low_rank_plus_white_noise():
    rng = np.random.default_rng(0)
    m, n, k = 300, 800, 7
    L = rng.standard_normal((m, k)) @ rng.standard_normal((k, n)) * 0.3
    s = np.linalg.svd(L + rng.standard_normal((m, n)) * 0.05, compute_uv=False)
    assert svht_rank(s, (m, n)) == k
    assert svht_omega(1.0) == pytest.approx(2.86)  # square matrix, Gavish & Donoho's 2.858


@pytest.mark.parametrize("noise", [0.05, 0.5])
def test_auto_rank_finds_the_hankel_rank_of_sinusoids_in_white_noise(noise):
    rng = np.random.default_rng(3)
    n, p = 3000, 12
    t = np.arange(n) * 0.01
    S = np.stack([np.cos(2 * np.pi * f * t + rng.uniform(0, 6)) for f in (0.7, 1.9, 3.1, 4.4)], 1)
    Y = S @ rng.standard_normal((4, p)) + noise * rng.standard_normal((n, p))
    for method in ("dense", "gram"):
        assert HankelDMD(delays=30, rank="auto", method=method).fit(Y).rank_ == 8  # 4 real sinusoids


def test_energy_fraction_rank():
    Y, _ = damped_sinusoids(n=2000, p=5, noise=0.05, seed=8)
    _, s = textbook_eigs([Y], 20, 1)
    e = np.cumsum(s**2) / np.sum(s**2)
    dmd = HankelDMD(delays=20, rank=0.99).fit(Y)
    assert dmd.rank_ == int(np.searchsorted(e, 0.99) + 1)


def test_rank_above_numerical_rank_is_lowered_with_a_warning():
    Y, _ = damped_sinusoids(n=1000, p=4)  # exactly rank 6
    with pytest.warns(RuntimeWarning, match="numerical rank"):
        dmd = HankelDMD(delays=10, rank=12, method="dense").fit(Y)
    assert dmd.rank_ == 6


# ------------------------------------------------------------------------------------------- mode labels
def test_mode_table_tells_a_forced_line_from_randomly_excited_modes():
    Y = random_vibration()
    dmd = HankelDMD(delays=40, rank=12, dt=0.05).fit(Y)
    table = dmd.mode_table()
    assert sum(row["energy"] for row in table) == pytest.approx(1.0)
    assert set(table[0]) == {"index", "frequency_hz", "damping_ratio", "energy", "phase_locking", "kind"}
    harmonics = [row for row in table if row["kind"] == "harmonic"]
    assert len(harmonics) == 1 and harmonics[0]["frequency_hz"] == pytest.approx(0.605, rel=1e-3)
    structural = [row["frequency_hz"] for row in table if row["kind"] == "structural"]
    for f in (0.48, 1.5):
        assert min(abs(np.array(structural) - f)) < 0.03 * f
    lines = harmonic_candidates(Y, dt=0.05, delays=(30, 40, 50), rank=12)
    assert len(lines) == 1 and lines[0]["frequency_hz"] == pytest.approx(0.605, rel=1e-3)
    assert len(lines[0]["damping_ratios"]) == 3


def test_a_lightly_damped_free_decay_is_not_a_harmonic():
    """Both are deterministic and nearly undamped, but only the forced line keeps its amplitude."""
    dt, n = 0.05, 8000
    t = np.arange(n) * dt
    decay = np.exp(-0.005 * 2 * np.pi * 0.5 * t) * np.cos(2 * np.pi * 0.5 * t)  # 0.5 %, fades within 400 s
    line = 0.2 * np.cos(2 * np.pi * 0.605 * t + 1.0)
    Y = np.c_[decay + line, decay - line, 0.3 * decay + 2 * line]
    table = HankelDMD(delays=30, rank=4, dt=dt).fit(Y).mode_table()
    kinds = {round(row["frequency_hz"], 2): row["kind"] for row in table}
    assert kinds == {0.5: "structural", 0.6: "harmonic"} or kinds == {0.5: "structural", 0.61: "harmonic"}


# ---------------------------------------------------------------------------------------------- bad input
def test_errors_are_clear_value_errors():
    Y, _ = damped_sinusoids(n=500, p=4)
    bad = Y.copy()
    bad[[3, 4, 90], 2] = np.nan
    bad[7, 0] = np.inf
    with pytest.raises(ValueError, match=r"channel 0: inf at samples \[7\].*channel 2: NaN at samples \[3, 4, 90\]"):
        HankelDMD(delays=10, rank=4).fit(bad)
    with pytest.raises(ValueError, match="at least delays \\+ 2 = 52"):
        HankelDMD(delays=50, rank=4).fit(Y[:51])
    with pytest.raises(ValueError, match=r"Y\[1\] has 30 samples"):
        HankelDMD(delays=50, rank=4).fit([Y, Y[:30]])
    with pytest.raises(ValueError, match="larger than possible.*at most 40"):
        HankelDMD(delays=10, rank=41).fit(Y)
    const = Y.copy()
    const[:, 1] = 3.0
    with pytest.raises(ValueError, match=r"constant channel\(s\) \[1\]"):
        HankelDMD(delays=10, rank=4).fit(const)
    with pytest.raises(ValueError, match="give dt"):
        HankelDMD(delays=0.5, rank=4).fit(Y)
    with pytest.raises(ValueError, match="rank must be"):
        HankelDMD(rank="optimal").fit(Y)
    with pytest.raises(ValueError, match="rank"):
        HankelDMD(delays=10, rank=1.5).fit(Y)
    with pytest.raises(ValueError, match="method must be"):
        HankelDMD(delays=10, method="svd").fit(Y)
    with pytest.raises(ValueError, match="randomized"):
        HankelDMD(delays=10, rank="auto", method="randomized").fit(Y)
    with pytest.raises(ValueError, match="exact_svd_max_bytes"):
        HankelDMD(delays=10, rank=4, method="dense", exact_svd_max_bytes=1000).fit(Y)
    with pytest.raises(ValueError, match="2-D"):
        HankelDMD(delays=10, rank=4).fit(Y[:, 0])
    with pytest.raises(ValueError, match="delays must be >= 1"):
        HankelDMD(delays=0, rank=4).fit(Y)
    with pytest.raises(NotFittedError, match="fit"):
        HankelDMD().predict(10)
    with pytest.raises(ValueError, match="initial must have 4 channels"):
        HankelDMD(delays=10, rank=4).fit(Y).predict(5, initial=Y[:20, :3])


def test_auto_method_falls_back_to_randomized_beyond_the_budget():
    Y, mu_true = damped_sinusoids(n=1200, p=4)
    dmd = HankelDMD(delays=100, rank=6, exact_svd_max_bytes=2**20).fit(Y)
    assert dmd.method_ == "randomized"
    assert rel_err(dmd.eigenvalues_, mu_true) < 1e-6


def test_docstring_examples_run():
    for module in (hd, validation):
        result = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
        assert result.failed == 0 and result.attempted > 0


def test_no_warnings_on_ordinary_data():
    Y, _ = damped_sinusoids(n=1000, p=4, noise=0.01)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        HankelDMD(delays=10, rank=6, dt=DT).fit(Y).mode_table()

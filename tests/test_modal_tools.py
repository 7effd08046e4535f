"""MAC, mode pairing, real mode shapes and probabilistic mode shapes against independent truths: hand-computed MACs,
known permutations, and a proportionally damped 3-DOF system whose real mode shapes come from ``eigh(K, M)``."""

import doctest

import numpy as np
import pytest
import scipy.linalg as sla
from scipy import signal

import estimators.modal as modal
from estimators.modal import ModeShapeDistribution, mac, pair_modes, probabilistic_mode_shapes, real_mode_shape

DT = 0.05  # s


# ---------------------------------------------------------------------------------------------------- MAC
def test_mac_of_identical_scaled_and_orthogonal_vectors():
    a = np.array([1.0, -2.0, 0.5, 3.0])
    assert mac(a, a) == pytest.approx(1.0)
    assert mac(a, -7.5 * a) == pytest.approx(1.0)
    assert mac([1.0, 0.0, 0.0], [0.0, 3.0, -1.0]) == 0.0
    assert isinstance(mac(a, a), float)
    # hand computation: a.b = 1*2 + 2*0 + 2*1 = 4; |a|^2 = 9, |b|^2 = 5 -> 16 / 45
    assert mac([1.0, 2.0, 2.0], [2.0, 0.0, 1.0]) == pytest.approx(16 / 45)


def test_mac_is_complex_aware():
    phi = np.array([1.0 + 0.2j, -0.4 + 0.9j, 0.3 - 0.1j])
    assert mac(phi, (0.3 - 2.0j) * phi) == pytest.approx(1.0)  # any complex scaling
    # a^H b = conj(1) * 1 + conj(i) * (-i) = 1 - 1 = 0: orthogonal in C^2, although a^T b = 2
    assert mac([1.0, 1j], [1.0, -1j]) == pytest.approx(0.0, abs=1e-15)
    assert mac([1.0, 1j], [1.0, 1j]) == pytest.approx(1.0)
    # |a^H b|^2 / (a^H a)(b^H b), worked by hand: a = [1, i], b = [1, 1]: a^H b = 1 - i, |.|^2 = 2, norms 2 * 2
    assert mac([1.0, 1j], [1.0, 1.0]) == pytest.approx(0.5)


def test_mac_of_matrices_is_column_by_column():
    rng = np.random.default_rng(0)
    A = rng.standard_normal((5, 3)) + 1j * rng.standard_normal((5, 3))
    B = rng.standard_normal((5, 4))
    M = mac(A, B)
    assert M.shape == (3, 4)
    for i in range(3):
        for j in range(4):
            a, b = A[:, i], B[:, j]
            ref = abs(np.sum(np.conj(a) * b)) ** 2 / (np.sum(np.abs(a) ** 2) * np.sum(np.abs(b) ** 2))
            assert M[i, j] == pytest.approx(ref)
    np.testing.assert_allclose(mac(np.eye(4), np.eye(4)), np.eye(4))
    assert mac(A[:, 0], B).shape == (4,) and mac(A, B[:, 1]).shape == (3,)
    np.testing.assert_allclose(mac(A[:, 0], B), M[0])
    np.testing.assert_allclose(mac(A, B[:, 1]), M[:, 1])


def test_mac_errors():
    with pytest.raises(ValueError, match="same number of rows"):
        mac([1.0, 2.0], [1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="zero mode shape"):
        mac([0.0, 0.0], [1.0, 2.0])
    with pytest.raises(ValueError, match="finite"):
        mac([np.nan, 1.0], [1.0, 2.0])
    with pytest.raises(ValueError, match="vector .* or a matrix"):
        mac(np.ones((2, 2, 2)), np.ones(2))
    with pytest.raises(ValueError, match="numeric"):
        mac(["a", "b"], [1.0, 2.0])


# ----------------------------------------------------------------------------------------------- pairing
def test_pair_modes_recovers_a_shuffled_permutation():
    rng = np.random.default_rng(4)
    p, n = 8, 6
    shapes = rng.standard_normal((p, n))
    freqs = np.array([0.03, 0.12, 0.48, 0.49, 1.55, 2.0])  # two close modes at 0.48 / 0.49 Hz
    perm = rng.permutation(n)
    freq_b = freqs[perm] * (1 + 0.01 * rng.standard_normal(n))
    shapes_b = (shapes[:, perm] + 0.05 * rng.standard_normal((p, n))) * np.exp(1j * rng.uniform(0, 6, n))
    pairs = pair_modes(freqs, shapes, freq_b, shapes_b)
    assert [q["index_a"] for q in pairs] == list(range(n))
    # mode i of a sits at position where perm == i in b
    assert [q["index_b"] for q in pairs] == [int(np.flatnonzero(perm == i)[0]) for i in range(n)]
    for q in pairs:
        assert q["freq_a"] == freqs[q["index_a"]] and q["freq_b"] == freq_b[q["index_b"]]
        assert q["freq_rel_error"] == pytest.approx((q["freq_b"] - q["freq_a"]) / q["freq_a"])
        assert q["mac"] > 0.9


def test_pair_modes_uses_shapes_to_separate_close_modes():
    # b's frequencies are swapped relative to a's (0.48 <-> 0.49): frequency alone pairs them wrongly
    shapes = np.array([[1.0, 0.0], [0.0, 1.0], [0.5, 0.5]])
    fa, fb = [0.48, 0.49], [0.491, 0.479]
    assert [q["index_b"] for q in pair_modes(fa, None, fb, None)] == [1, 0]
    assert [q["index_b"] for q in pair_modes(fa, shapes, fb, shapes)] == [0, 1]
    assert np.isnan(pair_modes(fa, None, fb, None)[0]["mac"])


def test_pair_modes_tolerances_and_unequal_sets():
    shapes = np.eye(3)
    # b has an extra mode and misses a's third; the third of a has no partner within 10 %
    pairs = pair_modes([0.5, 1.0, 3.0], shapes, [1.02, 0.2, 0.5], shapes[:, [1, 2, 0]])
    assert [(q["index_a"], q["index_b"]) for q in pairs] == [(0, 2), (1, 0)]
    assert pair_modes([0.5], None, [0.56], None, max_freq_rel=0.1) == []
    assert len(pair_modes([0.5], None, [0.56], None, max_freq_rel=0.15)) == 1
    # min_mac rejects a pair whose frequency matches but whose shape does not
    assert pair_modes([0.5], shapes[:, :1], [0.5], shapes[:, 1:2], min_mac=0.5) == []
    assert len(pair_modes([0.5], shapes[:, :1], [0.5], shapes[:, 1:2])) == 1


def test_pair_modes_errors():
    with pytest.raises(ValueError, match="freq_a must hold finite frequencies > 0"):
        pair_modes([0.0, 1.0], None, [1.0], None)
    with pytest.raises(ValueError, match="shapes_b must have one column per frequency"):
        pair_modes([1.0], np.ones((3, 1)), [1.0, 2.0], np.ones((3, 1)))
    with pytest.raises(ValueError, match="same number of rows"):
        pair_modes([1.0], np.ones((3, 1)), [1.0], np.ones((4, 1)))
    with pytest.raises(ValueError, match="min_mac needs both"):
        pair_modes([1.0], None, [1.0], None, min_mac=0.9)
    with pytest.raises(ValueError, match="max_freq_rel must be > 0"):
        pair_modes([1.0], None, [1.0], None, max_freq_rel=0.0)


# --------------------------------------------------------------------------------------- real mode shapes
def test_real_mode_shape_undoes_a_complex_rotation_and_fixes_scale_and_sign():
    v = np.array([0.2, -0.7, 1.4, -0.35])
    for angle in (0.0, 0.9, 2.5, -1.7):
        out = real_mode_shape(-3.0 * v * np.exp(1j * angle))
        np.testing.assert_allclose(out, v / 1.4, atol=1e-12)
    np.testing.assert_allclose(real_mode_shape(v, ref=1), -v / 1.4)  # entry 1 made positive
    # a slightly complex shape: the real part after the best rotation
    out = real_mode_shape(np.array([1.0, 0.5 + 0.05j, -0.8]))
    assert out[0] == pytest.approx(1.0) and out[1] == pytest.approx(0.5, abs=0.01)
    with pytest.raises(ValueError, match="zero"):
        real_mode_shape([0.0, 0.0])
    with pytest.raises(ValueError, match="one vector"):
        real_mode_shape(np.ones((2, 2)))


# ------------------------------------------------------------------------------------ probabilistic shapes
def proportional_three_dof():
    M = np.diag([2.0, 1.5, 1.0])
    k1, k2, k3 = 60.0, 40.0, 30.0
    K = np.array([[k1 + k2, -k2, 0.0], [-k2, k2 + k3, -k3], [0.0, -k3, k3]])
    C = 0.03 * M + 0.005 * K  # Rayleigh damping: real mode shapes
    return M, C, K


def velocities(M, C, K, n, dt, seed, noise=0.05):
    """Velocity response to white-noise forces, exact in discrete time (Van Loan), with measurement noise."""
    nd = M.shape[0]
    A = np.block([[np.zeros((nd, nd)), np.eye(nd)], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    B = np.vstack([np.zeros((nd, nd)), np.linalg.inv(M)])
    ns = 2 * nd
    G = sla.expm(np.block([[-A, B @ B.T], [np.zeros((ns, ns)), A.T]]) * dt)
    Ad = G[ns:, ns:].T
    Qd = Ad @ G[:ns, ns:]
    rng = np.random.default_rng(seed)
    w = rng.standard_normal((n, ns)) @ np.linalg.cholesky((Qd + Qd.T) / 2).T
    mu, W = np.linalg.eig(Ad)
    z_in = np.linalg.solve(W, w.T)
    z = np.stack([signal.lfilter([1.0], [1.0, -m], z_in[j]) for j, m in enumerate(mu)])
    v = (W @ z).real.T[:, nd:]
    return v + noise * v.std(axis=0) * rng.standard_normal(v.shape)


@pytest.fixture(scope="module")
def ensemble():
    M, C, K = proportional_three_dof()
    w2, phi = sla.eigh(K, M)
    true_f = np.sqrt(w2) / (2 * np.pi)
    true_shapes = phi / phi[np.argmax(np.abs(phi), axis=0), np.arange(3)]  # largest entry +1
    records = [velocities(M, C, K, 4000, DT, seed) for seed in range(4)]  # four 200 s records
    out = probabilistic_mode_shapes(records, DT, delays=(45, 60, 75), rank=24, target_frequencies_hz=true_f)
    return true_f, true_shapes, out


def test_probabilistic_band_contains_the_true_mode_shapes(ensemble):
    true_f, true_shapes, out = ensemble
    assert len(out) == 3
    for j, dist in enumerate(out):
        assert isinstance(dist, ModeShapeDistribution)
        assert dist.target_frequency_hz == true_f[j]
        assert dist.n_fits == 4 * 3
        assert dist.n_found >= dist.n_fits // 2, f"mode {j} found in {dist.n_found} of {dist.n_fits} fits"
        truth = true_shapes[:, j]
        assert np.all((dist.lower - 1e-12 <= truth) & (truth <= dist.upper + 1e-12)), (j, dist.lower, dist.upper)
        assert np.all(dist.lower <= dist.mean) and np.all(dist.mean <= dist.upper)
        assert mac(dist.mean, truth) > 0.999
        np.testing.assert_allclose(np.median(dist.frequencies_hz), true_f[j], rtol=0.05)


def test_probabilistic_shapes_bookkeeping(ensemble):
    _, _, out = ensemble
    for dist in out:
        k = dist.n_found
        assert dist.shapes.shape == (k, 3)
        assert dist.frequencies_hz.shape == dist.damping_ratios.shape == dist.delays.shape == (k,)
        np.testing.assert_allclose(np.abs(dist.shapes).max(axis=1), 1.0)
        assert np.all(dist.shapes[:, dist.ref_channel] > 0)  # sign convention, over the whole ensemble
        assert set(dist.delays.tolist()) <= {45, 60, 75}
        assert dist.record_index.min() >= 0 and dist.record_index.max() <= 3
        assert np.all(np.abs(dist.frequencies_hz / dist.target_frequency_hz - 1) <= 0.1)
        # each (record, delay) fit contributes at most one shape per target
        assert len(set(zip(dist.record_index.tolist(), dist.delays.tolist(), strict=True))) == k


def test_a_target_without_a_mode_gives_nan_and_no_shapes():
    M, C, K = proportional_three_dof()
    y = velocities(M, C, K, 2000, DT, 0)
    (dist,) = probabilistic_mode_shapes([y], DT, delays=[30], rank=8, target_frequencies_hz=[5.0])
    assert dist.n_found == 0 and dist.n_fits == 1
    assert np.all(np.isnan(dist.mean)) and dist.shapes.shape == (0, 3)


def test_probabilistic_shapes_errors():
    y = np.random.default_rng(0).standard_normal((500, 3))
    with pytest.raises(ValueError, match="delays must list at least one"):
        probabilistic_mode_shapes([y], DT, delays=[], target_frequencies_hz=[1.0])
    with pytest.raises(ValueError, match="kinds must be"):
        probabilistic_mode_shapes([y], DT, delays=[10], rank=4, target_frequencies_hz=[1.0], kinds=("modal",))
    with pytest.raises(ValueError, match="percentiles must satisfy"):
        probabilistic_mode_shapes([y], DT, delays=[10], rank=4, target_frequencies_hz=[1.0], percentiles=(97.5, 2.5))
    with pytest.raises(ValueError, match="target_frequencies_hz must hold finite frequencies > 0"):
        probabilistic_mode_shapes([y], DT, delays=[10], rank=4, target_frequencies_hz=[-1.0])
    bad = y.copy()
    bad[3, 1] = np.nan
    with pytest.raises(ValueError, match=r"records\[1\] must be finite: channel 1: NaN at samples \[3\]"):
        probabilistic_mode_shapes([y, bad], DT, delays=[10], rank=4, target_frequencies_hz=[1.0])
    with pytest.raises(TypeError):
        probabilistic_mode_shapes([y], DT, delays=[10], rank=4)  # target frequencies are required


def test_docstring_examples_run():
    result = doctest.testmod(modal, optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0

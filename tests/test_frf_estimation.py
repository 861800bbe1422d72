"""Multi-reference H1 and multiple coherence (sixdof.validation.estimation.estimate_frfs) against the exact
FRF of a two-mass system driven by two uncorrelated white-noise forces, and the resolution check."""

import numpy as np
import pytest
import scipy.linalg
import scipy.signal

from sixdof import InputError
from sixdof.validation import check_resolution, estimate_frf, estimate_frfs
from sixdof.validation.estimation import BINS_PER_BANDWIDTH
from tolerances import H1_MAX_SIGMAS, H1_SIGMA_CALIBRATION, TOL_COHERENCE_NOISE_FREE

FS, NPERSEG = 50.0, 1024


def two_masses():
    """A two-mass chain (2.58 and 8.77 Hz, damping ratios 8 % and 5 %) held by zero-order hold at FS: the
    discrete system ``(Ad, Bd, Cd, Dd)`` that maps sampled forces on both masses to x1, x2 and x1 - x2
    exactly, and its exact FRF."""
    M = np.diag([1.0, 1.5])
    K = np.array([[2300.0, -1500.0], [-1500.0, 1500.0]])
    w2, V = scipy.linalg.eigh(K, M)
    zeta = np.array([0.08, 0.05])
    C = M @ V @ np.diag(2 * zeta * np.sqrt(w2)) @ V.T @ M  # modal damping: V^T C V = diag(2 zeta w)
    Minv = np.linalg.inv(M)
    A = np.block([[np.zeros((2, 2)), np.eye(2)], [-Minv @ K, -Minv @ C]])
    B = np.vstack([np.zeros((2, 2)), Minv])
    Cout = np.array([[1.0, 0, 0, 0], [0, 1.0, 0, 0], [1.0, -1.0, 0, 0]])
    Ad, Bd, Cd, Dd, _ = scipy.signal.cont2discrete((A, B, Cout, np.zeros((3, 2))), 1 / FS, method="zoh")

    def frf(f_hz):
        z = np.exp(2j * np.pi * np.asarray(f_hz) / FS)
        return np.stack([Cd @ np.linalg.solve(zk * np.eye(4) - Ad, Bd) + Dd for zk in z])  # (nf, 3, 2)

    def respond(forces):
        y = np.zeros((forces.shape[0], 3))
        for j in range(2):
            num, den = scipy.signal.ss2tf(Ad, Bd, Cd, Dd, input=j)
            for i in range(3):
                y[:, i] += scipy.signal.lfilter(num[i], den, forces[:, j])
        return y

    return np.sqrt(w2) / (2 * np.pi), zeta, frf, respond


def test_h1_of_two_references_is_the_exact_frf_within_its_leakage_error():
    _, _, frf, respond = two_masses()
    rng = np.random.default_rng(3)
    sigma = np.array([1.0, 2.0])
    nperseg = 2 * NPERSEG  # 41 s segments against the first mode's 0.77 s decay
    forces = rng.standard_normal((32 * nperseg, 2)) * sigma
    est = estimate_frfs(forces, respond(forces), FS, nperseg)
    H = frf(est.f_hz)
    assert est.H.shape == (nperseg // 2 + 1, 3, 2) and est.coherence.shape == (nperseg // 2 + 1, 3)
    assert est.averages == 63 and est.window == "hann" and est.overlap == 0.5
    assert est.effective_averages == pytest.approx(63 / 1.0556, rel=0.02)
    # Noise-free, what remains is leakage: the response inside a segment to forces before it, which the
    # multiple coherence sees as output noise (measured 1 - gamma^2 <= 0.5 %).
    assert np.min(est.coherence[1:-1]) >= 1.0 - TOL_COHERENCE_NOISE_FREE
    # H1's random error for uncorrelated references (Bendat & Piersol 9.90 with the coherence of reference j
    # conditioned on the others: gamma^2 times reference j's share of the output's power).
    share = np.abs(H) ** 2 * sigma**2 / np.sum(np.abs(H) ** 2 * sigma**2, axis=2, keepdims=True)
    g2 = est.coherence[:, :, None]
    eps = np.sqrt((1 - g2) / (2 * est.effective_averages * g2 * share))
    judged = (eps <= 0.2) & (np.arange(est.f_hz.size) > 0)[:, None, None]
    assert judged.sum() > 1000
    z = (np.abs(est.H - H) / (np.abs(H) * eps))[judged]
    assert np.max(z) <= H1_MAX_SIGMAS


def test_multiple_coherence_with_output_noise_is_snr_over_one_plus_snr():
    _, _, frf, respond = two_masses()
    rng = np.random.default_rng(4)
    sigma = np.array([1.0, 2.0])
    forces = rng.standard_normal((128 * NPERSEG, 2)) * sigma
    clean = respond(forces)
    noise_sigma = 0.3 * np.std(clean, axis=0)
    est = estimate_frfs(forces, clean + noise_sigma * rng.standard_normal(clean.shape), FS, NPERSEG)
    H = frf(est.f_hz)
    # White inputs and white output noise: SNR(f) = sum_j |H_ij|^2 sigma_j^2 / sigma_n^2 per output.
    snr = np.sum(np.abs(H) ** 2 * sigma**2, axis=2) / noise_sigma**2
    exact = snr / (1 + snr)
    judged = (exact > 0.1) & (exact < 0.95)
    assert judged.sum() > 300
    # Bendat & Piersol 9.73: the coherence estimate's standard deviation sqrt(2) gamma (1 - gamma^2) / sqrt(n_d).
    spread = np.sqrt(2 * exact) * (1 - exact) / np.sqrt(est.effective_averages)
    z = (est.coherence - exact)[judged] / spread[judged]
    assert np.max(np.abs(z)) <= H1_MAX_SIGMAS
    assert abs(np.mean(z**2) - 1.0) <= H1_SIGMA_CALIBRATION


def test_one_reference_is_estimate_frf():
    _, _, _, respond = two_masses()
    rng = np.random.default_rng(5)
    forces = np.column_stack([rng.standard_normal(8 * 256), np.zeros(8 * 256)])
    y = respond(forces) + 1e-3 * rng.standard_normal((8 * 256, 3))
    one = estimate_frf(forces[:, 0], y, FS, 256)
    multi = estimate_frfs(forces[:, :1], y, FS, 256)
    kw = dict(fs=FS, nperseg=256, noverlap=128, detrend=False)  # Hann is scipy's default
    _, pxx = scipy.signal.welch(forces[:, 0], **kw)
    _, pyy = scipy.signal.welch(y, axis=0, **kw)
    _, pxy = scipy.signal.csd(forces[:, :1], y, axis=0, **kw)
    # The definitions written out: S_xy / S_xx and |S_xy|^2 / (S_xx S_yy).
    np.testing.assert_allclose(one.H1, pxy / pxx[:, None], rtol=1e-13)
    np.testing.assert_allclose(one.coherence, np.abs(pxy) ** 2 / (pxx[:, None] * pyy), rtol=1e-12)
    np.testing.assert_array_equal(one.H1, multi.H[:, :, 0])
    np.testing.assert_array_equal(one.coherence, multi.coherence)


def test_correlated_references_and_bad_records_are_refused():
    rng = np.random.default_rng(6)
    x = rng.standard_normal((4096, 2))
    y = rng.standard_normal((4096, 3))
    with pytest.raises(InputError, match=r"^inputs: expected references that are not fully correlated, got "
                                         r"input column 2 fully correlated with columns 0, 1 at every frequency"):
        estimate_frfs(np.column_stack([x, x[:, 0] - 0.5 * x[:, 1]]), y, FS, 512)
    with pytest.raises(InputError, match=r"column 1 fully correlated with column 0 at"):
        estimate_frfs(np.column_stack([x[:, 0], 3.0 * x[:, 0]]), y, FS, 512)
    with pytest.raises(InputError, match=r"input column 0 carries no power"):
        estimate_frfs(np.column_stack([np.zeros(4096), x[:, 0]]), y, FS, 512)
    with pytest.raises(InputError, match=r"^nperseg: expected an integer from 8 to the number of samples 4096, "
                                         r"got 8192"):
        estimate_frfs(x, y, FS, 8192)
    bad = y.copy()
    bad[17, 2] = np.nan
    with pytest.raises(InputError, match=r"^outputs: expected finite samples, got .*row 17, column 2"):
        estimate_frfs(x, bad, FS, 512)
    with pytest.raises(InputError, match=r"^outputs: expected samples of shape \(4096, n_outputs\)"):
        estimate_frfs(x, y[:-1], FS, 512)
    with pytest.raises(InputError, match=r"^overlap: expected a fraction of a segment in \[0, 1\), got 1"):
        estimate_frfs(x, y, FS, 512, overlap=1.0)


def test_resolution_check_follows_the_bins_per_bandwidth_rule():
    f_n, zeta = np.array([3.0, 8.0]), np.array([0.04, 0.01])
    bandwidth = 2 * 0.01 * 8.0  # the sharper mode: 0.16 Hz
    assert check_resolution(bandwidth / BINS_PER_BANDWIDTH, f_n, zeta) is None
    assert check_resolution(np.arange(0, 10, bandwidth / 5), f_n, zeta) is None
    note = check_resolution(0.05, f_n, zeta)
    assert note.startswith("the estimate's bins (0.05 Hz) do not resolve the sharpest mode (8 Hz, damping ratio "
                           "0.01: half-power bandwidth 0.16 Hz) with 4 bins per bandwidth")
    assert note.endswith("(segments of at least 25 s resolve it)")
    assert check_resolution(1.0, [], []) is None

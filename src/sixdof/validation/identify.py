"""Modal identification of measured FRFs: poly-reference LSCF ("PolyMAX") poles, LSFD mode shapes.

The method is that of

* P. Guillaume, P. Verboven, S. Vanlanduit, H. Van der Auweraer, B. Peeters, "A poly-reference
  implementation of the least-squares complex frequency-domain estimator", Proc. IMAC XXI (2003);
* B. Peeters, H. Van der Auweraer, P. Guillaume, J. Leuridan, "The PolyMAX frequency-domain method: a
  new standard for modal parameter estimation?", Shock and Vibration 11 (2004) 395-409.

**Poles** (:func:`identify_modes`, steps 1-3). Each output's row of FRFs ``H_o(w)`` (1 x n_ref) is
modelled as a right matrix fraction ``H_o = B_o(w) A(w)^-1`` with polynomials in ``z = exp(i w dt)``
(``dt = 1 / (2 f_max)``, ``f_max`` the top of the band, so that the band fills the upper half of the unit
circle) and real matrix coefficients: ``A = sum_r z^r alpha_r`` (n_ref x n_ref each), ``B_o = sum_r z^r
beta_or`` (1 x n_ref each), ``r = 0..p``. The linearized equation error ``B_o - H_o A`` is minimized in
least squares over all bins; eliminating the numerators leaves the reduced normal equations
``M alpha = 0`` with ``M = sum_o (T_o - S_o' R_o^-1 S_o)`` (Guillaume et al., eq. 12), solved with the
highest coefficient fixed, ``alpha_p = I`` (the PolyMAX constraint, which gives clean stabilization). The
poles are the eigenvalues of the companion matrix of ``A(z)' ``, ``s = ln(z) / dt``, and the first block
of each eigenvector is the pole's participation factor (its left null vector: ``l' A(z) = 0``). All
orders share one set of Toeplitz sums (``R, S, T`` depend only on ``s - r``), so the whole diagram costs
little more than its largest order.

Each output is weighted by the inverse of its RMS over the band and references (outputs in different
units or at different levels count alike); the bins are not weighted.

**Stability** (:class:`StabilityDiagram`). Each pole of order ``p`` (one of each complex-conjugate pair,
``Im s > 0``) is compared with the pole of order ``p - 1`` nearest in frequency: *new* (0), *stable in
frequency* (1: within :data:`FREQUENCY_TOLERANCE`), *stable in frequency and damping* (2: also damping
within :data:`DAMPING_TOLERANCE`, relative), *stable in frequency, damping and participation vector* (3:
also MAC of the participation factors above :data:`VECTOR_MAC`).

**Selection**, automatic, seeded by nothing but the data (:func:`select_poles`): the candidates are the
poles of class 3 with a damping ratio in ``(0, MAX_DAMPING)`` inside the band. They are grouped into
clusters from the highest order down: a pole joins the cluster whose first pole is nearest in frequency,
within :data:`CLUSTER_TOLERANCE`, whose participation factor it matches (MAC at least
:data:`CLUSTER_MAC`), and which holds no pole of its order yet (two poles of one order are two modes);
otherwise it starts a cluster. A cluster with poles at no fewer than :data:`MIN_ORDER_FRACTION` of the
orders is a mode; its representative is its pole nearest the cluster's median frequency. Closely spaced
modes resolve because their participation vectors differ (several references) and because one order
holds both; with a single reference only the second argument is left.

**Mode shapes** (:func:`lsfd`): with the poles ``lambda`` and participation factors ``l`` fixed, the
least-squares frequency-domain fit of every output over all references and bins of the band::

    H_oj(w) = sum_i [ psi_oi l_ji / (i w - lambda_i) + conj(psi_oi l_ji) / (i w - conj(lambda_i)) ]
              + LR_oj / (i w)^2 + UR_oj                                          (receptance)

with real lower (``LR``, the mass line of modes below the band) and upper (``UR``, the residual compliance
of modes above it) residual terms.

**The quantity.** Poles do not depend on it. The model above is written in receptance, whatever was
measured; it is fitted to the data as given, mobility being ``(i w)`` and accelerance ``(i w)^2`` times
receptance, so the least-squares weighting is that of the measured data (where its noise lives) and the
residues, shapes and residual terms are receptance ones. Bins at 0 Hz are left out.

**Scaling.** Each mode's residue matrix (receptance x rad/s) is ``shapes[:, i] participation[:, i]'``
exactly; the shape is scaled so that its largest-magnitude entry is ``1 + 0j``, which puts the scale
and the phase into the participation factor.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sixdof.analysis.frf.records import QUANTITIES
from sixdof.errors import InputError, Plain, readonly
from sixdof.results import Result, label, part, quantity, result_type
from sixdof.validation.correlation import mac

__all__ = ["CLUSTER_MAC", "CLUSTER_TOLERANCE", "DAMPING_TOLERANCE", "FREQUENCY_TOLERANCE", "Identification",
           "IdentifiedModes", "MAX_DAMPING", "MIN_ORDER_FRACTION", "StabilityDiagram", "VECTOR_MAC", "identify_modes",
           "lsfd", "mac", "plscf_poles", "select_poles"]

#: Stable in frequency: relative change of the natural frequency from the previous order.
FREQUENCY_TOLERANCE = 0.01
#: Stable in damping: relative change of the damping ratio from the previous order.
DAMPING_TOLERANCE = 0.05
#: Stable participation vector: MAC with the previous order's pole above this.
VECTOR_MAC = 0.98
#: Poles with a damping ratio at or above this are not candidate modes (a mounted machine's modes are far below).
MAX_DAMPING = 0.2
#: A pole joins a cluster within this relative frequency distance of the cluster's first pole...
CLUSTER_TOLERANCE = 0.01
#: ... and with at least this MAC of participation vectors with it.
CLUSTER_MAC = 0.9
#: A cluster is a mode when its poles come from at least this fraction of the orders of the diagram.
MIN_ORDER_FRACTION = 0.3
#: Default largest order: the diagram then holds ``max_order * n_ref`` poles, about this many.
DEFAULT_POLES = 120

#: Stability classes, in the order of their codes.
STABILITY_CLASSES = ("new", "frequency", "frequency and damping", "frequency, damping and vector")


# ----------------------------------------------------------------------------------------------------
# Results.
# ----------------------------------------------------------------------------------------------------


def _residue_units(modes: IdentifiedModes) -> str:
    return f"({modes.unit}) rad/s" if modes.unit else ""


@result_type
@dataclass(frozen=True, eq=False)
class IdentifiedModes(Result):
    """Modes identified from measured FRFs (:func:`identify_modes`).

    Attributes
    ----------
    frequency_hz : ndarray, shape (m,)
        Undamped natural frequencies ``|s| / (2 pi)`` [Hz], ascending.
    damping_ratio : ndarray, shape (m,)
        Viscous damping ratios ``-Re(s) / |s|`` [1].
    shapes : ndarray, shape (n_out, m), complex
        Mode shapes at the measured outputs from the residues, each scaled so that its largest-magnitude
        entry is ``1 + 0j`` [1].
    participation : ndarray, shape (n_ref, m), complex
        Participation factors, scaled so that mode i's residue matrix of the receptance is
        ``outer(shapes[:, i], participation[:, i])`` [receptance unit x rad/s].
    lower_residual, upper_residual : ndarray, shape (n_out, n_ref)
        The LSFD residual terms ``LR / (i w)^2 + UR`` of the receptance [receptance unit x rad^2/s^2 and
        receptance unit].
    unit : str
        The receptance unit (output per input) when the caller gave it, else ``""``.
    """

    frequency_hz: np.ndarray = quantity("Hz", ("mode",))
    damping_ratio: np.ndarray = quantity("1", ("mode",))
    shapes: np.ndarray = quantity("1", ("output", "mode"),
                                  description="residue-based mode shapes, largest-magnitude entry 1 + 0j")
    participation: np.ndarray = quantity(_residue_units, ("reference", "mode"),
                                         description="residue of mode i = outer(shapes[:, i], participation[:, i]), "
                                                     "receptance unit x rad/s")
    lower_residual: np.ndarray = quantity("", ("output", "reference"),
                                          description="LR of the receptance model LR / (i w)^2, receptance unit x "
                                                      "rad^2/s^2")
    upper_residual: np.ndarray = quantity("", ("output", "reference"),
                                          description="UR of the receptance model, receptance unit")
    unit: str = label(name="receptance_unit", default="")

    @property
    def poles(self) -> np.ndarray:
        """The poles ``s = -zeta w_n + i w_n sqrt(1 - zeta^2)`` [rad/s], shape (m,), complex."""
        return _poles(self.frequency_hz, self.damping_ratio)

    def synthesize(self, f_hz: np.ndarray, quantity: str = "receptance") -> np.ndarray:
        """The FRFs of the identified model at ``f_hz`` [Hz] (> 0), in ``quantity``, shape (nf, n_out, n_ref)."""
        power = _quantity_power(quantity)
        iw = 2j * np.pi * np.asarray(f_hz, dtype=float)
        residues = self.shapes[None, :, None, :] * self.participation[None, None, :, :]  # (1, out, ref, mode)
        lam = self.poles
        modal = np.sum(residues / (iw[:, None, None, None] - lam)
                       + residues.conj() / (iw[:, None, None, None] - lam.conj()), axis=-1)
        receptance = modal + self.lower_residual / iw[:, None, None] ** 2 + self.upper_residual
        return iw[:, None, None] ** power * receptance


@result_type
@dataclass(frozen=True, eq=False)
class StabilityDiagram(Result):
    """The poles of every model order of the pLSCF estimator, their stability and the selection.

    Attributes
    ----------
    order : ndarray of int, shape (n_poles,)
        Model order (polynomial degree ``p``) of each pole; the poles of one order are consecutive.
    frequency_hz, damping_ratio : ndarray, shape (n_poles,)
        Undamped natural frequency [Hz] and damping ratio [1] of each pole (``Im s > 0``, any damping).
    stability : ndarray of int, shape (n_poles,)
        0 new, 1 stable in frequency, 2 in frequency and damping, 3 in frequency, damping and participation
        vector, against the previous order (:data:`STABILITY_CLASSES`).
    participation : ndarray, shape (n_poles, n_ref), complex
        Participation factor of each pole, unit norm.
    cluster : ndarray of int, shape (n_poles,)
        The selection's cluster of each candidate pole, -1 for poles that are no candidates.
    selected : ndarray of int, shape (m,)
        Index of each identified mode's pole into the pole axis.
    max_order : int
    frequency_tolerance, damping_tolerance, vector_mac, max_damping, cluster_tolerance, cluster_mac,
    min_order_fraction : float
        The rules used (:data:`FREQUENCY_TOLERANCE` etc.).
    """

    order: np.ndarray = quantity("1", ("pole",))
    frequency_hz: np.ndarray = quantity("Hz", ("pole",))
    damping_ratio: np.ndarray = quantity("1", ("pole",))
    stability: np.ndarray = quantity("1", ("pole",), description="0 new, 1 stable frequency, 2 frequency and "
                                                                 "damping, 3 frequency, damping and vector")
    participation: np.ndarray = quantity("1", ("pole", "reference"), description="unit-norm participation factor")
    cluster: np.ndarray = quantity("1", ("pole",), description="cluster of a candidate pole, -1 when none")
    selected: np.ndarray = quantity("1", ("mode",), description="pole index of each identified mode")
    max_order: int = label()
    frequency_tolerance: float = label(default=FREQUENCY_TOLERANCE)
    damping_tolerance: float = label(default=DAMPING_TOLERANCE)
    vector_mac: float = label(default=VECTOR_MAC)
    max_damping: float = label(default=MAX_DAMPING)
    cluster_tolerance: float = label(default=CLUSTER_TOLERANCE)
    cluster_mac: float = label(default=CLUSTER_MAC)
    min_order_fraction: float = label(default=MIN_ORDER_FRACTION)


@result_type
@dataclass(frozen=True, eq=False)
class Identification(Result):
    """Result of :func:`identify_modes`: the identified modes and the stability diagram they came from.

    Attributes
    ----------
    modes : IdentifiedModes
    stability : StabilityDiagram
    quantity : str
        The quantity of the FRFs identified (``"receptance"``, ``"mobility"`` or ``"accelerance"``).
    band_hz : tuple of float
        The lowest and highest frequency of the bins used [Hz].
    """

    modes: IdentifiedModes = part(IdentifiedModes, group="modes")
    stability: StabilityDiagram = part(StabilityDiagram, group="stability")
    quantity: str = label()
    band_hz: tuple[float, float] = label(decode=lambda b: (float(b[0]), float(b[1])))


# ----------------------------------------------------------------------------------------------------
# The estimator.
# ----------------------------------------------------------------------------------------------------


def _poles(frequency_hz: np.ndarray, damping_ratio: np.ndarray) -> np.ndarray:
    wn = 2 * np.pi * np.asarray(frequency_hz, dtype=float)
    zeta = np.asarray(damping_ratio, dtype=float)
    return wn * (-zeta + 1j * np.sqrt(np.clip(1 - zeta ** 2, 0.0, None)))


def _quantity_power(name: str) -> int:
    if name not in QUANTITIES:
        raise InputError("quantity", "'receptance', 'mobility' or 'accelerance'", name)
    return QUANTITIES[name]


@dataclass(frozen=True)
class _Poles:
    """The poles of every order (one of each conjugate pair), flattened: see :class:`StabilityDiagram`."""

    order: np.ndarray
    s: np.ndarray
    participation: np.ndarray


def plscf_poles(f_hz: np.ndarray, H: np.ndarray, max_order: int) -> _Poles:
    """The pLSCF poles of orders 1 to ``max_order`` of the FRFs ``H`` (nf, n_out, n_ref) at ``f_hz`` [Hz] (> 0).

    Returns the poles [rad/s] with ``Im s > 0`` of every order, their order and their unit-norm participation
    factors (see the module's text for the model and the normal equations).
    """
    nf, n_out, n_ref = H.shape
    dt = 1.0 / (2.0 * float(f_hz[-1]))
    scale = np.sqrt(np.mean(np.abs(H) ** 2, axis=(0, 2)))
    Hn = H / np.where(scale > 0, scale, 1.0)[None, :, None]
    P = max_order
    # Toeplitz sums over the bins, for every lag d = s - r in -P..P: R, S, T of any order are read from them.
    lags = np.arange(-P, P + 1)
    E = np.exp(1j * 2 * np.pi * f_hz[None, :] * dt * lags[:, None])  # (2P+1, nf)
    r_lag = np.real(E.sum(axis=1))  # R[r, s] = Re sum_k z^(s-r)
    s_lag = -np.real(E @ Hn.reshape(nf, n_out * n_ref)).reshape(2 * P + 1, n_out, n_ref)
    gram = np.einsum("koi,koj->kij", Hn.conj(), Hn).reshape(nf, n_ref * n_ref)
    t_lag = np.real(E @ gram).reshape(2 * P + 1, n_ref, n_ref)

    orders, poles, participations = [], [], []
    for p in range(1, P + 1):
        k = np.arange(p + 1)
        lag = k[None, :] - k[:, None] + P  # s - r, offset
        R = r_lag[lag]
        S = s_lag[lag].transpose(2, 0, 1, 3).reshape(n_out, p + 1, (p + 1) * n_ref)  # S_o[r, (s, j)]
        T = t_lag[lag].transpose(0, 2, 1, 3).reshape((p + 1) * n_ref, (p + 1) * n_ref)  # T[(r, i), (s, j)]
        RinvS = np.linalg.solve(R, S.transpose(1, 0, 2).reshape(p + 1, -1)).reshape(p + 1, n_out, -1)
        # sum_o S_o' R^-1 S_o as one product over the stacked (o, r) rows.
        M = T - S.reshape(n_out * (p + 1), -1).T @ RinvS.transpose(1, 0, 2).reshape(n_out * (p + 1), -1)
        M = (M + M.T) / 2
        n = p * n_ref
        # alpha_p = I: the lower coefficients from the first n rows of M alpha = 0.
        try:
            low = np.linalg.solve(M[:n, :n], -M[:n, n:])
        except np.linalg.LinAlgError:
            low = np.linalg.lstsq(M[:n, :n], -M[:n, n:], rcond=None)[0]
        companion = np.zeros((n, n))
        companion[:-n_ref, n_ref:] = np.eye(n - n_ref)
        companion[-n_ref:, :] = -low.T
        z = np.linalg.eigvals(companion).astype(complex)
        with np.errstate(divide="ignore", invalid="ignore"):
            s = np.log(z) / dt
        keep = np.isfinite(s) & (s.imag > 0)
        # The participation factor is the eigenvector's first block, the null vector l of A(z)' (l' A(z) = 0):
        # from an SVD of each small n_ref x n_ref A(z) rather than the eigenvectors of the whole companion
        # matrix, which would cost three times its eigenvalues.
        alpha = np.concatenate([low, np.eye(n_ref)]).reshape(p + 1, n_ref, n_ref)
        A = np.einsum("kr,rij->kij", z[keep, None] ** np.arange(p + 1)[None, :], alpha)
        L = np.linalg.svd(A.transpose(0, 2, 1))[2][:, -1, :].conj()  # (n_keep, n_ref), unit norm
        orders.append(np.full(int(np.sum(keep)), p))
        poles.append(s[keep])
        participations.append(L)
    return _Poles(order=np.concatenate(orders), s=np.concatenate(poles),
                  participation=np.concatenate(participations, axis=0))


def _frequency_damping(s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    wn = np.abs(s)
    return wn / (2 * np.pi), -s.real / wn


def _stability(poles: _Poles) -> np.ndarray:
    """The stability class (0-3) of every pole against the previous order's pole nearest in frequency."""
    f, zeta = _frequency_damping(poles.s)
    classes = np.zeros(poles.s.size, dtype=np.int64)
    for p in np.unique(poles.order)[1:]:
        now = np.flatnonzero(poles.order == p)
        before = np.flatnonzero(poles.order == p - 1)
        if before.size == 0 or now.size == 0:
            continue
        nearest = before[np.argmin(np.abs(f[now][:, None] - f[before][None, :]), axis=1)]
        df = np.abs(f[now] - f[nearest]) / f[nearest]
        dz = np.abs(zeta[now] - zeta[nearest]) / np.maximum(np.abs(zeta[nearest]), np.finfo(float).tiny)
        vec = np.abs(np.sum(poles.participation[now].conj() * poles.participation[nearest], axis=1)) ** 2
        stable_f = df < FREQUENCY_TOLERANCE
        stable_fd = stable_f & (dz < DAMPING_TOLERANCE)
        classes[now] = stable_f.astype(int) + stable_fd + (stable_fd & (vec > VECTOR_MAC))
    return classes


def select_poles(order: np.ndarray, frequency_hz: np.ndarray, damping_ratio: np.ndarray, stability: np.ndarray,
                 participation: np.ndarray, band_hz: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    """The automatic pole selection of the module's text.

    Parameters
    ----------
    order, frequency_hz, damping_ratio, stability : ndarray, shape (n_poles,)
        As in :class:`StabilityDiagram` (frequencies in Hz).
    participation : ndarray, shape (n_poles, n_ref), complex
        Unit-norm participation factors.
    band_hz : (float, float)
        The band the modes must lie in [Hz].

    Returns
    -------
    selected : ndarray of int, shape (m,)
        Index of each mode's representative pole, by ascending frequency.
    cluster : ndarray of int, shape (n_poles,)
        Cluster of each candidate pole, -1 for the others.
    """
    candidate = ((stability == 3) & (damping_ratio > 0) & (damping_ratio < MAX_DAMPING)
                 & (frequency_hz >= band_hz[0]) & (frequency_hz <= band_hz[1]))
    cluster = np.full(order.size, -1, dtype=np.int64)
    seeds: list[int] = []  # the first pole of each cluster
    for p in np.unique(order[candidate])[::-1]:
        members = np.flatnonzero(candidate & (order == p))
        if seeds:
            seed = np.asarray(seeds)
            distance = np.abs(frequency_hz[members][:, None] - frequency_hz[seed][None, :]) / frequency_hz[seed]
            vector = np.abs(participation[members].conj() @ participation[seed].T) ** 2
            distance[(distance > CLUSTER_TOLERANCE) | (vector < CLUSTER_MAC)] = np.inf
        else:
            distance = np.full((members.size, 0), np.inf)
        taken = np.zeros(distance.shape[1], dtype=bool)
        # Nearest pairs first; each cluster takes one pole of this order, each pole one cluster.
        for flat in np.argsort(distance, axis=None):
            i, c = np.unravel_index(flat, distance.shape)
            if not np.isfinite(distance[i, c]):
                break
            if cluster[members[i]] < 0 and not taken[c]:
                cluster[members[i]] = c
                taken[c] = True
        for i in members[cluster[members] < 0]:
            cluster[i] = len(seeds)
            seeds.append(int(i))
    n_orders = int(np.max(order)) - int(np.min(order)) + 1 if order.size else 1
    needed = math.ceil(MIN_ORDER_FRACTION * n_orders)
    selected = []
    for c in range(len(seeds)):
        members = np.flatnonzero(cluster == c)
        if np.unique(order[members]).size >= needed:
            median = np.median(frequency_hz[members])
            selected.append(int(members[np.argmin(np.abs(frequency_hz[members] - median))]))
    selected = np.asarray(selected, dtype=np.int64)
    return selected[np.argsort(frequency_hz[selected], kind="stable")], cluster


def lsfd(f_hz: np.ndarray, H: np.ndarray, poles: np.ndarray, participation: np.ndarray,
         power: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Least-squares frequency-domain mode shapes and residual terms, with the poles and participation fixed.

    Parameters
    ----------
    f_hz : ndarray, shape (nf,)
        Frequencies [Hz], > 0.
    H : ndarray, shape (nf, n_out, n_ref), complex
        The FRFs, ``(i w)^power`` times receptance.
    poles : ndarray, shape (m,), complex
        [rad/s], ``Im > 0``.
    participation : ndarray, shape (n_ref, m), complex
    power : int
        0 receptance, 1 mobility, 2 accelerance.

    Returns
    -------
    psi : ndarray, shape (n_out, m), complex
        Residue mode shapes: mode i's receptance residue is ``outer(psi[:, i], participation[:, i])``.
    lower, upper : ndarray, shape (n_out, n_ref)
        The residual terms ``LR / (i w)^2 + UR`` of the receptance (real).
    """
    nf, n_out, n_ref = H.shape
    m = poles.size
    iw = 2j * np.pi * np.asarray(f_hz, dtype=float)
    weight = iw ** power
    first = 1.0 / (iw[:, None] - poles[None, :])  # (nf, m)
    second = 1.0 / (iw[:, None] - poles.conj()[None, :])
    # Columns (nf, n_ref, unknown): Re psi_i, Im psi_i, then LR_j and UR_j.
    lf = participation[None, :, :]
    re_psi = lf * first[:, None, :] + lf.conj() * second[:, None, :]
    im_psi = 1j * (lf * first[:, None, :] - lf.conj() * second[:, None, :])
    eye = np.eye(n_ref)[None, :, :]
    lower = eye / iw[:, None, None] ** 2
    upper = np.broadcast_to(eye, (nf, n_ref, n_ref)).astype(complex)
    columns = np.concatenate([re_psi, im_psi, lower, upper], axis=2) * weight[:, None, None]
    A = columns.reshape(nf * n_ref, 2 * m + 2 * n_ref)
    B = H.transpose(0, 2, 1).reshape(nf * n_ref, n_out)  # rows (k, j), one column per output
    A_real = np.concatenate([A.real, A.imag])
    B_real = np.concatenate([B.real, B.imag])
    norms = np.linalg.norm(A_real, axis=0)
    norms = np.where(norms > 0, norms, 1.0)
    x = np.linalg.lstsq(A_real / norms, B_real, rcond=None)[0] / norms[:, None]
    psi = (x[:m] + 1j * x[m:2 * m]).T
    return psi, x[2 * m:2 * m + n_ref].T, x[2 * m + n_ref:].T


# ----------------------------------------------------------------------------------------------------
# The entry.
# ----------------------------------------------------------------------------------------------------


def identify_modes(f_hz: np.ndarray, H: np.ndarray, quantity: str = "receptance",
                   band_hz: tuple[float, float] | None = None, max_order: int | None = None, *,
                   unit: str = "") -> Identification:
    """Modal identification of measured FRFs by poly-reference LSCF (PolyMAX) and LSFD (see the module's text).

    Parameters
    ----------
    f_hz : array_like, shape (nf,)
        Frequencies [Hz], ascending, >= 0 (bins at 0 Hz are not used).
    H : array_like, shape (nf, n_out, n_ref), complex
        FRFs: ``H[k, o, j]`` output o per unit reference input j at ``f_hz[k]``.
    quantity : str
        What ``H`` is: ``"receptance"`` (displacement), ``"mobility"`` (velocity) or ``"accelerance"``
        (acceleration) per input.
    band_hz : (float, float), optional
        The band to identify in [Hz]: the bins within it are used and the modes lie in it. Default all bins.
    max_order : int, optional
        Largest model order (polynomial degree) of the stability diagram; orders 1 to it are computed. Default
        ``ceil(DEFAULT_POLES / n_ref)``, at most what the bins support (``nf_band >= 2 (max_order + 1)``).
    unit : str
        The receptance's unit (output per input, e.g. ``"m/N"``), kept with the modes; ``""`` when unknown.

    Returns
    -------
    Identification
        The modes (none when nothing is stable enough) and the stability diagram.

    Raises
    ------
    InputError
        Arrays of the wrong shape, non-finite or not ascending; an unknown quantity; a band not inside the data;
        too few bins for ``max_order``.
    """
    power = _quantity_power(quantity)
    f = _frequencies(f_hz)
    H = np.asarray(H)
    if H.ndim != 3 or H.shape[0] != f.size or 0 in H.shape:
        raise InputError("H", f"complex FRFs of shape (nf, n_out, n_ref) with nf = {f.size}",
                         Plain(f"an array of shape {H.shape}"))
    if not np.issubdtype(H.dtype, np.number) or not np.all(np.isfinite(H)):
        raise InputError("H", "finite complex FRFs", Plain("non-finite or non-numeric values"))
    H = H.astype(complex)
    lo, hi = (float(f[0]), float(f[-1])) if band_hz is None else _band(band_hz, f)
    inside = (f >= lo) & (f <= hi) & (f > 0)
    f_band, H_band = f[inside], H[inside]
    n_ref = H.shape[2]
    supported = f_band.size // 2 - 1
    if max_order is None:
        max_order = min(math.ceil(DEFAULT_POLES / n_ref), supported)
    elif not isinstance(max_order, (int, np.integer)) or isinstance(max_order, bool) or max_order < 2:
        raise InputError("max_order", "an integer >= 2", max_order)
    if max_order < 2 or max_order > supported:
        raise InputError("band_hz" if band_hz is not None else "f_hz",
                         f"at least 2 (max_order + 1) = {2 * (max(int(max_order), 2) + 1)} bins above 0 Hz in the band",
                         Plain(f"{f_band.size} bins from {lo:g} to {hi:g} Hz"))
    max_order = int(max_order)

    poles = plscf_poles(f_band, H_band, max_order)
    stability = _stability(poles)
    freq, zeta = _frequency_damping(poles.s)
    band = (float(f_band[0]), float(f_band[-1]))
    selected, cluster = select_poles(poles.order, freq, zeta, stability, poles.participation, band)

    s = poles.s[selected]
    L = poles.participation[selected].T  # (n_ref, m)
    psi, lower, upper = lsfd(f_band, H_band, s, L, power)
    if selected.size:
        largest = psi[np.argmax(np.abs(psi), axis=0), np.arange(selected.size)]
        largest = np.where(largest != 0, largest, 1.0)
        psi, L = psi / largest, L * largest
    modes = IdentifiedModes(frequency_hz=readonly(freq[selected]), damping_ratio=readonly(zeta[selected]),
                            shapes=readonly(psi, complex), participation=readonly(L, complex),
                            lower_residual=readonly(lower), upper_residual=readonly(upper), unit=unit)
    diagram = StabilityDiagram(order=readonly(poles.order, np.int64), frequency_hz=readonly(freq),
                               damping_ratio=readonly(zeta), stability=readonly(stability, np.int64),
                               participation=readonly(poles.participation, complex),
                               cluster=readonly(cluster, np.int64), selected=readonly(selected, np.int64),
                               max_order=max_order)
    return Identification(modes=modes, stability=diagram, quantity=quantity, band_hz=band)


def _frequencies(f_hz) -> np.ndarray:
    """``f_hz`` checked: ascending finite frequencies >= 0 [Hz], at least two."""
    expected = "ascending finite frequencies >= 0 in Hz, shape (nf,) with nf >= 2"
    try:
        f = np.asarray(f_hz, dtype=float)
    except (TypeError, ValueError):
        raise InputError("f_hz", expected, Plain(f"a {type(f_hz).__name__}")) from None
    if f.ndim != 1 or f.size < 2:
        raise InputError("f_hz", expected, Plain(f"an array of shape {f.shape}"))
    if not np.all(np.isfinite(f)) or f[0] < 0:
        raise InputError("f_hz", expected, Plain(f"frequencies from {np.min(f):g} to {np.max(f):g} Hz"))
    if np.any(np.diff(f) <= 0):
        k = int(np.argmax(np.diff(f) <= 0))
        raise InputError("f_hz", expected, Plain(f"f_hz[{k + 1}] = {f[k + 1]:g} after f_hz[{k}] = {f[k]:g}"))
    return f


def _band(band_hz, f: np.ndarray) -> tuple[float, float]:
    """``band_hz`` checked against the data's frequencies ``f`` [Hz]."""
    expected = f"(low, high) in Hz with {f[0]:g} <= low < high <= {f[-1]:g}"
    try:
        lo, hi = (float(b) for b in band_hz)
    except (TypeError, ValueError):
        raise InputError("band_hz", expected, band_hz) from None
    if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi) or hi < f[0] or lo > f[-1]:
        raise InputError("band_hz", expected, band_hz)
    return lo, hi

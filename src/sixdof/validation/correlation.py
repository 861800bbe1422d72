"""Test modes paired with model modes by MAC, and the verdict on their agreement.

The modal assurance criterion of two shapes ``a``, ``b`` on the same channels is
``|a^H b|^2 / ((a^H a)(b^H b))`` (Allemang & Brown 1982): 1 for shapes proportional by any complex factor,
0 for orthogonal ones. Test modes are paired with model modes one to one, maximizing the sum of MAC
(:func:`scipy.optimize.linear_sum_assignment`); the model's shapes on the measured channels are
``rows @ modes.shapes`` (:func:`channel_shapes`). Mode and pair indices are 0-based in the arrays and
numbered from 1 wherever they are printed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sixdof.errors import InputError, Plain, readonly
from sixdof.results import Result, label, quantity, result_type

__all__ = ["Correlation", "channel_shapes", "correlate_modes", "mac", "pair_modes"]

#: A test mode whose best MAC with any model mode is below this is left unpaired: at 0.5 two shapes share
#: less than half their direction, which no one calls the same mode.
PAIRING_FLOOR = 0.5
#: Default verdict limits: the usual test-analysis correlation criteria for rigid-body modes (frequency within
#: 5 %, MAC at least 0.9; see also :data:`sixdof.io.study_report.SAME_SHAPE_MAC`).
MAX_FREQUENCY_ERROR_PERCENT, MIN_MAC = 5.0, 0.9
#: Weight of the frequency distance ``|ln(f_model / f_test)|`` beside MAC in the pairing: it only breaks ties
#: between assignments whose MAC sums agree within about this (two close modes of nearly equal shapes).
FREQUENCY_TIE_WEIGHT = 1e-6


def _shapes(value, field: str) -> np.ndarray:
    array = np.asarray(value)
    if array.ndim == 1:
        array = array[:, None]
    if array.ndim != 2 or array.shape[0] == 0 or not np.all(np.isfinite(array)):
        raise InputError(field, "finite shapes of shape (n_dofs, n_modes)", Plain(f"shape {array.shape}"))
    norms = np.sum(np.abs(array) ** 2, axis=0)
    if np.any(norms == 0):
        raise InputError(field, "shapes that are not zero", Plain(f"a zero shape in column {int(np.argmin(norms))}"))
    return array


def mac(a, b) -> np.ndarray:
    """Modal assurance criterion of every shape of ``a`` with every shape of ``b``.

    Parameters
    ----------
    a : array_like, shape (n, m1) or (n,), real or complex
    b : array_like, shape (n, m2) or (n,), real or complex
        Shapes on the same ``n`` DOFs, one per column.

    Returns
    -------
    ndarray, shape (m1, m2)
        ``|a_i^H b_j|^2 / ((a_i^H a_i)(b_j^H b_j))``, in [0, 1].
    """
    a, b = _shapes(a, "a"), _shapes(b, "b")
    if a.shape[0] != b.shape[0]:
        raise InputError("b", f"shapes on the same {a.shape[0]} DOFs as a", Plain(f"shape {b.shape}"))
    cross = np.abs(np.conj(a).T @ b) ** 2
    return np.clip(cross / np.outer(np.sum(np.abs(a) ** 2, axis=0), np.sum(np.abs(b) ** 2, axis=0)), 0.0, 1.0)


def channel_shapes(rows, shapes) -> np.ndarray:
    """The model's mode shapes on the measured channels: ``rows @ shapes``, shape (n_channels, n_modes)."""
    return np.asarray(rows, dtype=float) @ np.asarray(shapes, dtype=float)


def pair_modes(mac_matrix, f_test, f_model, floor: float = PAIRING_FLOOR) -> tuple[tuple[int, int], ...]:
    """Pairs (test mode, model mode), 0-based, one to one, maximizing the sum of their MAC.

    Parameters
    ----------
    mac_matrix : array_like, shape (m_test, m_model)
        MAC of each test mode with each model mode (:func:`mac`).
    f_test : array_like, shape (m_test,)
        Test natural frequencies [Hz].
    f_model : array_like, shape (m_model,)
        Model natural frequencies [Hz]: they break ties between assignments of equal MAC (two close modes
        of nearly equal shapes go to the nearer frequency, :data:`FREQUENCY_TIE_WEIGHT`).
    floor : float
        A test mode whose best MAC is below this, or whose assigned MAC is, is left unpaired.

    Returns
    -------
    tuple of (int, int)
        ``(test index, model index)`` in ascending test index.
    """
    from scipy.optimize import linear_sum_assignment

    M = np.asarray(mac_matrix, dtype=float)
    ft, fm = np.asarray(f_test, dtype=float), np.asarray(f_model, dtype=float)
    if M.ndim != 2 or ft.shape != (M.shape[0],) or fm.shape != (M.shape[1],):
        raise InputError("mac_matrix", f"shape (len(f_test), len(f_model)) = ({ft.size}, {fm.size})",
                         Plain(f"shape {M.shape}"))
    if np.any(ft <= 0) or np.any(fm <= 0):
        raise InputError("f_test" if np.any(ft <= 0) else "f_model", "positive frequencies [Hz]",
                         ft if np.any(ft <= 0) else fm)
    candidates = np.flatnonzero(M.max(axis=1, initial=0.0) >= floor)
    if candidates.size == 0:
        return ()
    distance = np.abs(np.log(fm[None, :] / ft[candidates, None]))
    rows, cols = linear_sum_assignment(-M[candidates] + FREQUENCY_TIE_WEIGHT * distance)
    return tuple((int(candidates[r]), int(c)) for r, c in zip(rows, cols) if M[candidates[r], c] >= floor)


@result_type
@dataclass(frozen=True, eq=False)
class Correlation(Result):
    """Test modes against model modes: pairs, MAC, frequency errors and the verdict (from
    :func:`correlate_modes`). Mode indices are 0-based here; printed, they are numbered from 1.

    Attributes
    ----------
    f_test, f_model : ndarray, shape (m_test,), (m_model,)
        Natural frequencies [Hz].
    damping_test, damping_model : ndarray, shape (m_test,), (m_model,)
        Damping ratios.
    mac : ndarray, shape (m_test, m_model)
        MAC on the measured DOFs (channels).
    mac_body : ndarray, shape (m_test, m_model), or None
        MAC on the six projected body DOFs, when given.
    pair_test, pair_model : ndarray, shape (n_pairs,), int
        The pairs' test and model mode indices (0-based), in ascending test index.
    max_frequency_error_percent, min_mac : float
        The verdict's limits.
    correlated : bool
        Every test mode paired, every pair within both limits.
    reasons : tuple of str
        Why not, one line per failing pair or unpaired test mode (modes numbered from 1; test modes by
        ``test_number``).
    test_number : ndarray of int, shape (m_test,)
        The number each test mode is known by (from 1: its number among every mode identified).
    """

    f_test: np.ndarray = quantity("Hz", ("test_mode",))
    f_model: np.ndarray = quantity("Hz", ("model_mode",))
    damping_test: np.ndarray = quantity("1", ("test_mode",))
    damping_model: np.ndarray = quantity("1", ("model_mode",))
    mac: np.ndarray = quantity("1", ("test_mode", "model_mode"), description="MAC on the measured channels")
    pair_test: np.ndarray = quantity("1", ("pair",), description="test mode of each pair (0-based)")
    pair_model: np.ndarray = quantity("1", ("pair",), description="model mode of each pair (0-based)")
    max_frequency_error_percent: float = label()
    min_mac: float = label()
    correlated: bool = label(encode=int, decode=bool)
    reasons: tuple = label(encode=lambda r: "\n".join(r), decode=lambda s: tuple(str(s).split("\n")) if s else ())
    mac_body: np.ndarray | None = quantity("1", ("test_mode", "model_mode"), default=None,
                                           description="MAC on the six projected body DOFs")
    test_number: np.ndarray | None = quantity("1", ("test_mode",), default=None,
                                              description="the number each test mode is known by (from 1)")

    @property
    def frequency_error_percent(self) -> np.ndarray:
        """``100 (f_model - f_test) / f_test`` per pair, shape (n_pairs,)."""
        return 100.0 * (self.f_model[self.pair_model] - self.f_test[self.pair_test]) / self.f_test[self.pair_test]

    @property
    def pair_mac(self) -> np.ndarray:
        """MAC on the measured channels per pair, shape (n_pairs,)."""
        return self.mac[self.pair_test, self.pair_model]

    @property
    def pair_within(self) -> np.ndarray:
        """Whether each pair is within both of the verdict's limits (its frequency error and its MAC on the
        channels), shape (n_pairs,), bool."""
        return ((np.abs(self.frequency_error_percent) <= self.max_frequency_error_percent)
                & (self.pair_mac >= self.min_mac))


def _positive(value, field: str, size: int | None = None) -> np.ndarray:
    array = np.asarray(value, dtype=float).ravel()
    if (size is not None and array.size != size) or not np.all(np.isfinite(array)) or np.any(array < 0):
        raise InputError(field, f"{size if size is not None else 'some'} finite values >= 0", value)
    return array


def correlate_modes(f_test, damping_test, shapes_test, f_model, damping_model, shapes_model, body_test=None,
                    body_model=None, max_frequency_error_percent: float = MAX_FREQUENCY_ERROR_PERCENT,
                    min_mac: float = MIN_MAC, floor: float = PAIRING_FLOOR, test_numbers=None) -> Correlation:
    """Pair test modes with model modes by MAC on the measured channels and judge the pairs.

    Parameters
    ----------
    f_test, damping_test : array_like, shape (m_test,)
        Identified natural frequencies [Hz] and damping ratios.
    shapes_test : array_like, shape (n_channels, m_test), complex or real
        Identified shapes on the measured channels.
    f_model, damping_model : array_like, shape (m_model,)
        The model's natural frequencies [Hz] and damping ratios.
    shapes_model : array_like, shape (n_channels, m_model)
        The model's shapes on the same channels (:func:`channel_shapes`).
    body_test, body_model : array_like, shape (6, m_test), (6, m_model), optional
        Both shapes as the six body DOFs (the test's projected, :func:`~sixdof.validation.projection.project_to_body`;
        the model's ``modes.shapes``), for a second MAC matrix. Pairing uses the measured channels.
    max_frequency_error_percent : float
        A pair fails beyond this ``|100 (f_model - f_test) / f_test|``.
    min_mac : float
        A pair fails below this MAC on the measured channels.
    floor : float
        Pairing floor (:func:`pair_modes`).
    test_numbers : array_like of int, shape (m_test,), optional
        The number each test mode is known by in the reasons and tables (default 1 to ``m_test``): its number
        among all the modes identified, when only some are correlated.

    Returns
    -------
    Correlation
    """
    phi_t, phi_m = _shapes(shapes_test, "shapes_test"), _shapes(shapes_model, "shapes_model")
    ft = _positive(f_test, "f_test", phi_t.shape[1])
    fm = _positive(f_model, "f_model", phi_m.shape[1])
    zt, zm = _positive(damping_test, "damping_test", ft.size), _positive(damping_model, "damping_model", fm.size)
    if not max_frequency_error_percent > 0:
        raise InputError("max_frequency_error_percent", "a positive limit [%]", max_frequency_error_percent)
    if not 0 < min_mac <= 1:
        raise InputError("min_mac", "a limit in (0, 1]", min_mac)
    if phi_m.shape[0] != phi_t.shape[0]:
        raise InputError("shapes_model", f"shapes on the test's {phi_t.shape[0]} channels",
                         Plain(f"shape {phi_m.shape}"))
    matrix = mac(phi_t, phi_m)
    body = None
    if body_test is not None or body_model is not None:
        if body_test is None or body_model is None:
            raise InputError("body_test" if body_test is None else "body_model",
                             "body shapes given on both sides or on neither", Plain("one side only"))
        body = mac(_shapes(body_test, "body_test"), _shapes(body_model, "body_model"))
        if body.shape != matrix.shape:
            raise InputError("body_model", f"body shapes (6, {ft.size}) and (6, {fm.size})",
                             Plain(f"a MAC matrix of shape {body.shape}"))
    numbers = np.arange(1, ft.size + 1) if test_numbers is None else np.asarray(test_numbers, dtype=int)
    if numbers.shape != ft.shape:
        raise InputError("test_numbers", f"one number per test mode, shape ({ft.size},)",
                         Plain(f"shape {numbers.shape}"))
    pairs = pair_modes(matrix, ft, fm, floor)
    paired = {t for t, _ in pairs}
    reasons = [f"test mode {numbers[t]} ({ft[t]:.4g} Hz): no model mode with MAC >= {floor:g}"
               for t in range(ft.size) if t not in paired]
    for t, m in pairs:
        error = 100.0 * (fm[m] - ft[t]) / ft[t]
        failing = []
        if abs(error) > max_frequency_error_percent:
            failing.append(f"frequency error {error:+.2f} % beyond +-{max_frequency_error_percent:g} %")
        if matrix[t, m] < min_mac:
            failing.append(f"MAC {matrix[t, m]:.3f} below {min_mac:g}")
        if failing:
            reasons.append(f"test mode {numbers[t]} ({ft[t]:.4g} Hz) with model mode {m + 1} ({fm[m]:.4g} Hz): "
                           + ", ".join(failing))
    reasons.sort(key=lambda text: int(text.split()[2]))
    as_int = np.asarray([t for t, _ in pairs], dtype=int), np.asarray([m for _, m in pairs], dtype=int)
    return Correlation(f_test=readonly(ft), f_model=readonly(fm), damping_test=readonly(zt),
                       damping_model=readonly(zm), mac=readonly(matrix), pair_test=readonly(as_int[0], int),
                       pair_model=readonly(as_int[1], int),
                       max_frequency_error_percent=float(max_frequency_error_percent), min_mac=float(min_mac),
                       correlated=not reasons, reasons=tuple(reasons),
                       mac_body=None if body is None else readonly(body), test_number=readonly(numbers, int))

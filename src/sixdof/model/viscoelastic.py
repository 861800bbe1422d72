"""Generalized Maxwell (Prony series) models of a visco-elastic mount along one axis.

A spring ``k0`` (the long-term stiffness) in parallel with ``n`` Maxwell branches, branch ``i`` a spring
``k_i`` in series with a dashpot ``c_i = k_i tau_i`` (``tau_i``: its relaxation time). Its complex
(dynamic) stiffness at the angular frequency ``w = 2 pi f`` is

    K(w) = k0 + sum_i k_i (i w tau_i) / (1 + i w tau_i),

rising from ``k0`` (static) to ``k0 + sum_i k_i`` (instantaneous), each branch dissipating most near
``w tau_i = 1``. Storage stiffness ``K' = Re K``, loss factor ``eta = Im K / Re K``. Such a model is causal
and, with every ``k_i >= 0`` and ``tau_i > 0``, passive; each branch adds one internal state to a time
simulation.

:func:`read_dynamic_stiffness` reads measured ``K'`` and ``eta`` against frequency, :func:`fit_maxwell` fits
a model to them, :func:`constant_loss_model` builds the causal model nearest a constant complex stiffness
``k (1 + i eta)`` over a band. Both return a :class:`MaxwellFit` that reports how far it is from its data.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from sixdof.errors import InputError, Plain, finite_array, frequency_band, integer, number, readonly
from sixdof.files import csv_numbers, csv_rows
from sixdof.results import Result, label, quantity

#: What a dynamic stiffness table holds, for error messages.
TABLE = ("a UTF-8 CSV file of a header row, then rows of three numbers: frequency in Hz, storage stiffness K' "
         "in N/m, loss factor")
#: Relaxation times per decade of the data's frequency range that ``terms=None`` gives (see :func:`fit_maxwell`).
TERMS_PER_DECADE = 2
#: Points per decade at which :func:`constant_loss_model` samples its constant complex stiffness.
POINTS_PER_DECADE = 20
#: A fit this close to its data (worst relative error in ``|K*|``, worst loss angle error in degrees) models the
#: mount it was fitted to: a scenario's measured table must be fitted this well unless it states other limits,
#: and the report says which fits are not (a constant loss factor made causal over a wide band cannot be).
FIT_MODULUS_ERROR = 0.05
FIT_LOSS_ANGLE_ERROR_DEG = 1.0


def relaxation(f_hz, tau) -> np.ndarray:
    """``(i w tau) / (1 + i w tau)``, ``w = 2 pi f``: a Maxwell branch's dynamic stiffness per unit stiffness, complex,
    ``f_hz`` [Hz] and ``tau`` [s] broadcast together."""
    s_tau = 2j * np.pi * np.asarray(f_hz, dtype=float) * np.asarray(tau, dtype=float)
    return s_tau / (1 + s_tau)


def maxwell_stiffness(f_hz, long_term: float, stiffness, tau) -> np.ndarray:
    """Complex stiffness ``K(w) = k0 + sum_i k_i (i w tau_i) / (1 + i w tau_i)`` of a generalized Maxwell model.

    Parameters
    ----------
    f_hz : array_like
        Frequencies [Hz], any shape; ``w = 2 pi f``.
    long_term : float
        Long-term (static) stiffness ``k0`` [N/m].
    stiffness : array_like, shape (terms,)
        Branch stiffnesses ``k_i`` [N/m].
    tau : array_like, shape (terms,)
        Branch relaxation times ``tau_i`` [s].

    Returns
    -------
    numpy.ndarray
        ``K`` [N/m], complex, the shape of ``f_hz``.

    Raises
    ------
    sixdof.errors.InputError
        When ``stiffness`` and ``tau`` are not 1-D arrays of the same length.
    """
    stiffness, tau = np.asarray(stiffness, dtype=float), np.asarray(tau, dtype=float)
    if stiffness.ndim != 1 or tau.shape != stiffness.shape:
        raise InputError("tau", f"{stiffness.size} relaxation times in s, one per branch stiffness", tau)
    return long_term + (stiffness * relaxation(np.asarray(f_hz, dtype=float)[..., None], tau)).sum(axis=-1)


@dataclass(frozen=True, eq=False)
class MaxwellFit(Result):
    """A generalized Maxwell model fitted to dynamic stiffness data, and how far it is from them.

    Attributes
    ----------
    name : str
        What it models (``"<mount> <axis>"`` in a scenario; empty when fitted alone).
    source : str
        Where its data came from (a file, or a constant loss factor).
    long_term : float
        Long-term stiffness ``k0`` [N/m].
    stiffness : numpy.ndarray, shape (terms,)
        Branch stiffnesses ``k_i`` [N/m], all ``>= 0``.
    tau : numpy.ndarray, shape (terms,)
        Branch relaxation times ``tau_i`` [s], decreasing.
    f_hz, storage, loss_factor : numpy.ndarray, shape (points,)
        The data fitted: frequencies [Hz], storage stiffness ``K'`` [N/m] and loss factor [-].
    modulus_error : float
        Worst relative error of the fit's ``|K|`` over the data points [-].
    loss_angle_error_deg : float
        Worst error of the fit's loss angle ``atan(eta)`` over the data points [deg].
    """

    long_term: float = quantity("N/m", (), decode=float, description="long-term (static) stiffness k0 of the fit")
    stiffness: np.ndarray = quantity("N/m", ("term",), description="Maxwell branch stiffnesses of the fit")
    tau: np.ndarray = quantity("s", ("term",), description="Maxwell branch relaxation times of the fit")
    f_hz: np.ndarray = quantity("Hz", ("point",), description="frequencies of the data fitted")
    storage: np.ndarray = quantity("N/m", ("point",), description="storage stiffness K' of the data fitted")
    loss_factor: np.ndarray = quantity("1", ("point",), description="loss factor of the data fitted")
    modulus_error: float = quantity("1", (), decode=float, description="worst relative error of |K*| over the data")
    loss_angle_error_deg: float = quantity("deg", (), decode=float,
                                           description="worst error of the loss angle over the data")
    name: str = label(default="")
    source: str = label(default="")

    @property
    def band_hz(self) -> tuple[float, float]:
        """Lowest and highest frequency of the data fitted [Hz]."""
        return float(self.f_hz[0]), float(self.f_hz[-1])

    def dynamic_stiffness(self, f_hz) -> np.ndarray:
        """The model's complex stiffness [N/m] at ``f_hz`` [Hz] (see :func:`maxwell_stiffness`)."""
        return maxwell_stiffness(f_hz, self.long_term, self.stiffness, self.tau)


def read_dynamic_stiffness(path, field: str = "dynamic_stiffness.file") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Read measured dynamic stiffness from a CSV file.

    The file has a header row, then one row per frequency: frequency [Hz], storage stiffness ``K'`` [N/m],
    loss factor [-]. Blank lines and lines starting with ``#`` are skipped.

    Parameters
    ----------
    path : str or pathlib.Path
        The CSV file.
    field : str
        Field named by the errors (``"mounts[0].dynamic_stiffness.file"``).

    Returns
    -------
    f_hz, storage, loss_factor : numpy.ndarray, shape (points,)
        Frequencies [Hz] (> 0, strictly increasing), storage stiffness [N/m] (> 0), loss factor [-] (>= 0);
        read-only.

    Raises
    ------
    sixdof.errors.InputError
        Naming ``field``, the file and the offending line: a missing or unreadable file, a row that is not
        three finite numbers, fewer than 2 rows, or data breaking the rules above.
    """
    path = Path(path)
    rows, lines = [], []
    for k, (line, row) in enumerate(csv_rows(path, field, TABLE)):
        if k:  # the first row is the header
            rows.append(csv_numbers(row, 3, line, str(path), field, TABLE))
            lines.append(line)
    if len(rows) < 2:
        received = "a single point" if rows else "no data rows"
        raise InputError(field, f"{TABLE}, at least 2 rows", Plain(f"{received} in {path}"))
    f_hz, storage, loss_factor = readonly(rows).T
    broken = _first_broken_rule(f_hz, storage, loss_factor)
    if broken is not None:
        k, _, rule = broken
        raise InputError(field, f"{TABLE}, with {rule}", Plain(f"line {lines[k]} of {path}: {rows[k]}"))
    return f_hz, storage, loss_factor


def _first_broken_rule(f_hz: np.ndarray, storage: np.ndarray, loss_factor: np.ndarray) -> tuple[int, str, str] | None:
    """``(point, array name, rule)`` of the first rule of dynamic stiffness data that a data point breaks
    (in the order below), or ``None``."""
    rules = (
        ("f_hz", f_hz <= 0, "frequencies > 0 Hz"),
        ("f_hz", np.diff(f_hz, prepend=0.0) <= 0, "strictly increasing frequencies"),
        ("storage", storage <= 0, "storage stiffness K' > 0 N/m"),
        ("loss_factor", loss_factor < 0, "loss factor >= 0"),
    )
    for name, bad, rule in rules:
        if bad.any():
            return int(np.argmax(bad)), name, rule
    return None


def fit_maxwell(f_hz, storage, loss_factor, terms: int | None = None, *, field: str = "dynamic_stiffness"
                ) -> MaxwellFit:
    """The generalized Maxwell model nearest measured dynamic stiffness, with its worst errors.

    The relaxation times are fixed, ``tau_i = 1 / (2 pi f_i)`` with the ``f_i`` log-spaced over the data's
    band, ends included (one term: their geometric mean); the long-term stiffness ``k0`` carries the static
    load (relaxations below the band would take it over and leave the mount no static stiffness). The
    stiffnesses ``[k0, k_1 ... k_n] >= 0`` are the
    non-negative least-squares solution (:func:`scipy.optimize.nnls`) of the relative complex error
    ``(K_model - K_data) / |K_data|`` over the data points, ``K_data = K' (1 + i eta)``: every point weighs
    the same whatever its stiffness. Non-negative stiffnesses make the model passive (it dissipates energy
    at every frequency: ``Im K >= 0``) whatever the data; where the data are not those of a passive, causal
    mount, the errors reported show it.

    Parameters
    ----------
    f_hz : array_like, shape (points,)
        Frequencies [Hz], > 0 and strictly increasing, at least 2.
    storage : array_like, shape (points,)
        Storage stiffness ``K'`` [N/m], > 0.
    loss_factor : array_like, shape (points,)
        Loss factor ``eta = K'' / K'`` [-], >= 0.
    terms : int, optional
        Number of Maxwell branches, at most ``points``. Default: two per decade of the band plus one,
        ``1 + round(2 log10(f_max / f_min))``, at most ``points``: neighbouring relaxation frequencies
        about a factor ``sqrt(10)`` apart, which reproduces a broad relaxation spectrum closely and a single
        sharp one lying midway between two of them to about 1 % in ``|K|``; pass more terms for a closer fit.
    field : str
        Field named by the errors (``field + ".f_hz"``, ``field + ".terms"``...).

    Returns
    -------
    MaxwellFit

    Raises
    ------
    sixdof.errors.InputError
        When the data are not finite 1-D arrays of one length >= 2 following the rules above, or ``terms`` is
        not a positive integer up to ``points``.
    """
    data = {name: finite_array(value, f"{field}.{name}", f"a 1-D array of finite {what}", (-1,))
            for name, value, what in (("f_hz", f_hz, "frequencies in Hz"), ("storage", storage, "stiffnesses in N/m"),
                                      ("loss_factor", loss_factor, "loss factors"))}
    f_hz, storage, loss_factor = data.values()
    if len({a.size for a in data.values()}) > 1 or f_hz.size < 2:
        raise InputError(field, "f_hz, storage and loss_factor of one length >= 2 (a single point cannot be fitted)",
                         Plain(f"lengths {[a.size for a in data.values()]}"))
    broken = _first_broken_rule(f_hz, storage, loss_factor)
    if broken is not None:
        k, name, rule = broken
        raise InputError(f"{field}.{name}", rule, Plain(f"{name}[{k}] = {data[name][k]:g}"))
    points = f_hz.size
    if terms is None:
        terms = min(points, 1 + round(TERMS_PER_DECADE * math.log10(f_hz[-1] / f_hz[0])))
    terms = integer(terms, f"{field}.terms", "a positive number of Maxwell branches", 1)
    if terms > points:
        raise InputError(f"{field}.terms", f"at most {points} Maxwell branches (one per data point)", terms)

    f_relax = np.geomspace(f_hz[0], f_hz[-1], terms) if terms > 1 else np.array([math.sqrt(f_hz[0] * f_hz[-1])])
    tau = 1 / (2 * np.pi * f_relax)
    k_data = storage * (1 + 1j * loss_factor)
    weight = 1 / np.abs(k_data)
    columns = np.column_stack([np.ones(points), relaxation(f_hz[:, None], tau)]) * weight[:, None]
    scale = np.abs(k_data).max()  # solve for k / scale: order-one unknowns for nnls' tolerances
    import scipy.optimize  # here: building a model imports this module, not the fit's optimizer

    solution, _ = scipy.optimize.nnls(np.vstack([columns.real, columns.imag]),
                                      np.concatenate([(k_data * weight).real, (k_data * weight).imag]) / scale)
    k0, stiffness = scale * solution[0], readonly(scale * solution[1:])
    k_fit = maxwell_stiffness(f_hz, k0, stiffness, tau)
    return MaxwellFit(
        long_term=float(k0), stiffness=stiffness, tau=readonly(tau), f_hz=f_hz, storage=storage,
        loss_factor=loss_factor,
        modulus_error=float(np.max(np.abs(np.abs(k_fit) - np.abs(k_data)) * weight)),
        loss_angle_error_deg=float(np.degrees(np.max(np.abs(np.arctan(k_fit.imag / k_fit.real)
                                                             - np.arctan(loss_factor))))),
    )


def constant_loss_model(stiffness: float, loss_factor: float, band_hz, terms: int | None = None) -> MaxwellFit:
    """The causal generalized Maxwell model nearest a constant complex stiffness ``k (1 + i eta)`` over a band.

    A frequency-independent complex stiffness (hysteretic, or structural, damping) is a common description
    of an elastomer mount, but it is not causal: by the Kramers-Kronig relations a loss angle
    ``delta = atan(eta)`` that is the same at every frequency requires ``|K|`` to rise like
    ``w^(2 delta / pi)`` (the fractional-derivative spring ``K ~ (i w)^(2 delta / pi)``, whose phase is
    ``delta`` everywhere), about ``10^(2 delta / pi)`` per decade (+16 % for ``eta = 0.1``). No causal model,
    this one included, can keep both ``|K|`` and the loss angle constant; the fit shares the misfit between
    them, and the :class:`MaxwellFit` reports both worst errors (``modulus_error``,
    ``loss_angle_error_deg``): they grow with ``eta`` and with the band's width.

    Parameters
    ----------
    stiffness : float
        Storage stiffness ``k`` [N/m], > 0.
    loss_factor : float
        Loss factor ``eta`` [-], >= 0.
    band_hz : array_like, shape (2,)
        Band ``[low, high]`` [Hz], ``0 < low < high``, sampled at 20 log-spaced points per decade
        (:data:`POINTS_PER_DECADE`), ends included.
    terms : int, optional
        Number of Maxwell branches (see :func:`fit_maxwell`, which does the fit).

    Returns
    -------
    MaxwellFit

    Raises
    ------
    sixdof.errors.InputError
        Naming the argument that is out of range.
    """
    k = number(stiffness, "stiffness", "a storage stiffness in N/m > 0", low=0.0, strict=True)
    eta = number(loss_factor, "loss_factor", "a loss factor >= 0", low=0.0)
    low, high = frequency_band(band_hz, "band_hz")
    f_hz = np.geomspace(low, high, 1 + max(1, round(POINTS_PER_DECADE * math.log10(high / low))))
    return fit_maxwell(f_hz, np.full_like(f_hz, k), np.full_like(f_hz, eta), terms, field="constant_loss_model")


AXES = "uvw"


def with_fits(system, fits):
    """``system`` with fitted Maxwell models on mount axes: each fit's long-term stiffness replaces the
    mount's stiffness along that axis, and its branches (those with stiffness > 0) become
    :class:`~sixdof.model.system.Maxwell` branches of the mount named ``"<mount> <axis> <i>"``.

    Parameters
    ----------
    system : sixdof.model.system.System
    fits : sequence of (str, str, MaxwellFit)
        Mount name, axis (``"u"``, ``"v"`` or ``"w"``) and the fit along it.

    Returns
    -------
    sixdof.model.system.System
    """
    from sixdof.model.system import Maxwell

    mounts = {m.name: m for m in system.mounts}
    branches = list(system.maxwell)
    for mount, axis, fit in fits:
        a = AXES.index(axis)
        stiffness = np.array(mounts[mount].stiffness)
        stiffness[a] = fit.long_term
        mounts[mount] = dataclasses.replace(mounts[mount], stiffness=stiffness)
        branches += [Maxwell(name=f"{mount} {axis} {i + 1}", mount=mount, stiffness=np.eye(3)[a] * k, tau=float(t))
                     for i, (k, t) in enumerate(zip(fit.stiffness, fit.tau)) if k > 0]
    return dataclasses.replace(system, mounts=tuple(mounts.values()), maxwell=tuple(branches))


def loss_band(system) -> tuple[float, float]:
    """The default band [Hz] of :func:`causal_loss_factors`: from half the lowest to twice the highest natural
    frequency of the elastic modes, where the mounts' damping shapes the response."""
    f = np.asarray(system.modes.frequency_hz)
    f = f[f > 0]
    return float(f.min() / 2), float(f.max() * 2)


def causal_loss_factors(system, band_hz=None, terms: int | None = None):
    """``system`` with every mount axis's loss factor replaced by the causal Maxwell model nearest its
    complex stiffness ``k (1 + i eta)`` over ``band_hz`` (:func:`constant_loss_model`), so that the time
    response and the frequency responses model the same mount.

    Parameters
    ----------
    system : sixdof.model.system.System
    band_hz : array_like, shape (2,), optional
        ``[low, high]`` [Hz]; default :func:`loss_band`.
    terms : int, optional
        Maxwell branches per axis (default: see :func:`fit_maxwell`).

    Returns
    -------
    system : sixdof.model.system.System
        Without loss factors, with the branches (:func:`with_fits`).
    fits : tuple of MaxwellFit
        One per mount axis with a loss factor, named ``"<mount> <axis>"``.
    """
    band = loss_band(system) if band_hz is None else frequency_band(band_hz, "band_hz")
    fits = []
    for mount in system.mounts:
        for a in np.flatnonzero(mount.loss_factor > 0):
            fit = constant_loss_model(mount.stiffness[a], mount.loss_factor[a], band, terms)
            fits.append((mount.name, AXES[a], dataclasses.replace(
                fit, name=f"{mount.name} {AXES[a]}", source=f"loss factor {mount.loss_factor[a]:g}")))
    plain = dataclasses.replace(system, mounts=tuple(dataclasses.replace(m, loss_factor=np.zeros(3))
                                                     for m in system.mounts))
    return with_fits(plain, fits), tuple(fit for _, _, fit in fits)

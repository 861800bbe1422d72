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
from sixdof.model.parts import Maxwell, relaxation
from sixdof.results import Result, label, quantity, result_type

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
#: What the causal model of a constant loss factor must reproduce of ``k (1 + i eta)`` at each frequency it is
#: checked at (every elastic natural frequency and operating frequency of a scenario): ``|K*|`` within 5 %, the
#: loss factor within 10 % of itself (``|eta_fit - eta| <= 0.1 eta``).
LOSS_MODULUS_TARGET = 0.05
LOSS_FACTOR_TARGET = 0.10
#: Relaxation frequencies per decade that :func:`constant_loss_model` chooses its branches among, from the
#: bottom of its band to :data:`RELAXATION_REACH` above its top: branches relaxing above the band hold the loss
#: factor up at its top (within it they alone would let it fall there); none relaxes below the band, where it
#: would take the static load over from the long-term stiffness.
CAUSAL_TERMS_PER_DECADE = 4
RELAXATION_REACH = 3.0
#: The band of :func:`causal_loss_factors` reaches this factor below and above the frequencies checked.
BAND_MARGIN = 2.0
#: Between the checked frequencies (over the rest of the band) :func:`constant_loss_model` allows this many
#: times the errors it reaches at them.
BAND_SLACK = 3.0


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


@result_type
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
    loss_factor_error : float
        Worst relative error of the fit's loss factor over the data points with a loss factor,
        ``max |eta_fit - eta| / eta`` [-] (0 when no point has one).
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
    loss_factor_error: float = quantity("1", (), decode=float, default=0.0,
                                        description="worst relative error of the loss factor over the data")
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
    return _with_errors(float(k0), stiffness, tau, f_hz, storage, loss_factor)


def _with_errors(k0: float, stiffness, tau, f_hz, storage, loss_factor) -> MaxwellFit:
    """The :class:`MaxwellFit` of a model and its data, with its worst errors over them."""
    k_fit = maxwell_stiffness(f_hz, k0, stiffness, tau)
    k_data = storage * (1 + 1j * loss_factor)
    eta_fit, lossy = k_fit.imag / k_fit.real, loss_factor > 0
    return MaxwellFit(
        long_term=float(k0), stiffness=readonly(stiffness), tau=readonly(tau), f_hz=readonly(f_hz),
        storage=readonly(storage), loss_factor=readonly(loss_factor),
        modulus_error=float(np.max(np.abs(np.abs(k_fit) / np.abs(k_data) - 1))),
        loss_angle_error_deg=float(np.degrees(np.max(np.abs(np.arctan(eta_fit) - np.arctan(loss_factor))))),
        loss_factor_error=float(np.max(np.abs(eta_fit[lossy] / loss_factor[lossy] - 1), initial=0.0)),
    )


def constant_loss_model(stiffness: float, loss_factor: float, band_hz, terms: int | None = None,
                        check_hz=None) -> MaxwellFit:
    """The causal generalized Maxwell model nearest a constant complex stiffness ``k (1 + i eta)`` at the
    frequencies that matter.

    A frequency-independent complex stiffness (hysteretic, or structural, damping) is a common description
    of an elastomer mount, but it is not causal: by the Kramers-Kronig relations a loss angle
    ``delta = atan(eta)`` that is the same at every frequency requires ``|K|`` to rise like
    ``w^(2 delta / pi)`` (the fractional-derivative spring ``K ~ (i w)^(2 delta / pi)``, whose phase is
    ``delta`` everywhere), about ``10^(2 delta / pi)`` per decade (+16 % for ``eta = 0.1``). No causal model,
    this one included, can keep both ``|K|`` and the loss factor constant over a wide band: over the span
    ``f_max / f_min`` of the frequencies checked, ``|K|`` must change by about ``(f_max / f_min)^(2 eta / pi)``.

    The model is the minimax fit at the frequencies checked: the smallest ``s`` for which
    ``|Re K / k - 1|`` (hence ``|K*|``) is within ``s`` :data:`LOSS_MODULUS_TARGET` and ``Im K / Re K`` within
    ``s`` :data:`LOSS_FACTOR_TARGET` of ``eta`` relative, at every frequency checked and within
    :data:`BAND_SLACK` times that over the band (sampled at :data:`POINTS_PER_DECADE` points per decade),
    found by bisection on ``s`` of linear programs (:func:`scipy.optimize.linprog`) in the stiffnesses
    ``k0, k_i >= 0`` (passive), the branches' relaxation frequencies log-spaced over and beyond the band. Among the
    models at that ``s`` it takes the one of least instantaneous stiffness ``k0 + sum k_i``. Both
    constraints are linear: the loss factor's is ``(1 - s t) eta Re K <= Im K <= (1 + s t) eta Re K``, the
    modulus's bounds ``Re K`` so that ``|K| = Re K sqrt(1 + eta_fit^2)`` stays within its target. The
    :class:`MaxwellFit`'s data are the frequencies checked, its errors the exact worst ones there
    (``modulus_error``, ``loss_factor_error``, ``loss_angle_error_deg``).

    Parameters
    ----------
    stiffness : float
        Storage stiffness ``k`` [N/m], > 0.
    loss_factor : float
        Loss factor ``eta`` [-], >= 0.
    band_hz : array_like, shape (2,)
        Band ``[low, high]`` [Hz], ``0 < low < high``, over which the relaxation frequencies lie.
    terms : int, optional
        Relaxation frequencies to choose the branches among, log-spaced from the bottom of the band to
        :data:`RELAXATION_REACH` above its top, ends included (the fit keeps those it needs, a few). Default
        :data:`CAUSAL_TERMS_PER_DECADE` per decade plus one.
    check_hz : array_like, optional
        The frequencies [Hz] within the band where the targets must hold (a scenario's natural and operating
        frequencies); default: the band's samples, :data:`POINTS_PER_DECADE` per decade, ends included.

    Returns
    -------
    MaxwellFit

    Raises
    ------
    sixdof.errors.InputError
        Naming the argument that is out of range (a frequency checked outside the band included).
    """
    k = number(stiffness, "stiffness", "a storage stiffness in N/m > 0", low=0.0, strict=True)
    eta = number(loss_factor, "loss_factor", "a loss factor >= 0", low=0.0)
    low, high = frequency_band(band_hz, "band_hz")
    band = np.geomspace(low, high, 1 + max(1, round(POINTS_PER_DECADE * math.log10(high / low))))
    if check_hz is None:
        check = band
    else:
        check = np.unique(finite_array(check_hz, "check_hz", "a 1-D array of finite frequencies in Hz", (-1,)))
        inside = (check >= low * (1 - 1e-12)) & (check <= high * (1 + 1e-12))
        if not check.size or not inside.all():
            raise InputError("check_hz", f"frequencies within the band {low:g}-{high:g} Hz",
                             Plain(", ".join(f"{f:.4g}" for f in check[~inside]) + " Hz" if check.size else "none"))
    reach = (low, high * RELAXATION_REACH)  # none below: they would take the static load over from k0
    if terms is None:
        terms = 1 + math.ceil(CAUSAL_TERMS_PER_DECADE * math.log10(reach[1] / reach[0]))
    terms = integer(terms, "terms", "a positive number of Maxwell branches", 1)
    tau = 1 / (2 * np.pi * (np.geomspace(*reach, terms) if terms > 1 else np.array([math.sqrt(low * high)])))
    if eta == 0.0:
        stiffness_k, k0 = np.zeros(terms), k
    else:
        between = band[(band > check[0]) & (band < check[-1])]  # beyond the frequencies checked: free
        k0, stiffness_k = _minimax_loss_fit(eta, check, between, tau)
        k0, stiffness_k = k * k0, k * stiffness_k
    return _with_errors(k0, stiffness_k, tau, check, np.full_like(check, k), np.full_like(check, eta))


def _minimax_loss_fit(eta: float, check: np.ndarray, band: np.ndarray, tau: np.ndarray) -> tuple[float, np.ndarray]:
    """``k0 / k`` and ``k_i / k`` of :func:`constant_loss_model` (see there)."""
    import scipy.optimize  # here: building a model imports this module, not the fit's optimizer

    modulus = math.sqrt(1 + eta ** 2)

    def rows(f_hz, s):
        columns = np.column_stack([np.ones(f_hz.size), relaxation(f_hz[:, None], tau)])
        re, im = columns.real, columns.imag
        high, low = (1 + LOSS_FACTOR_TARGET * s) * eta, max(1 - LOSS_FACTOR_TARGET * s, 0.0) * eta
        # K within the sector of loss angles [atan(low), atan(high)] and |K| / k within (1 -+ M s) |1 + i eta|: the
        # sector's two edges, and for |K| its projection on the sector's bisector, at least the inner radius (the
        # tangent there) and at most the outer radius's chord (cos of the half-width): linear, and within a factor
        # cos(half-width) (1 - 1e-3 for eta = 1) of the exact annular sector.
        first, last = math.atan(low), math.atan(high)
        middle, chord = (first + last) / 2, math.cos((last - first) / 2)
        projection = re * math.cos(middle) + im * math.sin(middle)
        a = np.vstack([im - high * re, low * re - im, projection, -projection])
        outer = chord * (1 + LOSS_MODULUS_TARGET * s) * modulus
        b = np.concatenate([np.zeros(2 * f_hz.size), np.full(f_hz.size, outer),
                            np.full(f_hz.size, -(1 - LOSS_MODULUS_TARGET * s) * modulus)])
        return a, b

    def solve(s, cost):
        (a1, b1), (a2, b2) = rows(check, s), rows(band, BAND_SLACK * s)
        return scipy.optimize.linprog(cost, A_ub=np.vstack([a1, a2]), b_ub=np.concatenate([b1, b2]),
                                      bounds=(0, None), method="highs")

    feasible = np.zeros(tau.size + 1)
    low, high = 0.0, 1 / LOSS_FACTOR_TARGET  # from there on the loss factor's lower bound is 0: a plain spring
    while solve(high, feasible).status != 0:  # meets it, and the modulus's bounds once s is large enough
        low, high = high, 2 * high
    for _ in range(24):  # s to 1e-6
        middle = (low + high) / 2
        if solve(middle, feasible).status == 0:
            high = middle
        else:
            low = middle
    found = solve(high * (1 + 1e-6) + 1e-9, np.ones(tau.size + 1))
    if found.status != 0:  # cannot happen: ``high`` was feasible
        raise RuntimeError(f"constant_loss_model: the linear program failed at s = {high:g}: {found.message}")
    return float(found.x[0]), found.x[1:]


AXES = "uvw"


def with_fits(system, fits):
    """``system`` with fitted Maxwell models on mount axes: each fit's long-term stiffness replaces the
    mount's stiffness along that axis, and its branches (those with stiffness > 0) become
    :class:`~sixdof.model.parts.Maxwell` branches of the mount named ``"<mount> <axis> <i>"``.

    Parameters
    ----------
    system : sixdof.model.system.System
    fits : sequence of (str, str, MaxwellFit)
        Mount name, axis (``"u"``, ``"v"`` or ``"w"``) and the fit along it.

    Returns
    -------
    sixdof.model.system.System
        With the gravity preload ``system`` was given, if any (the statics of the new stiffnesses are
        :func:`sixdof.analysis.statics.with_gravity_preload`'s).
    """
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


def checked_frequencies(system, operating_hz=()) -> np.ndarray:
    """The frequencies [Hz] at which :func:`causal_loss_factors` checks its models: every elastic natural
    frequency of ``system`` (its mounts' stiffness as given, undamped) and every operating frequency, sorted."""
    f = np.asarray(system.modes.frequency_hz, dtype=float)
    f = np.concatenate([f[f > 0], np.asarray(operating_hz, dtype=float).ravel()])
    return np.unique(f[f > 0])


def loss_band(system, operating_hz=()) -> tuple[float, float]:
    """The default band [Hz] of :func:`causal_loss_factors`: from :data:`BAND_MARGIN` below the lowest to
    :data:`BAND_MARGIN` above the highest frequency checked (:func:`checked_frequencies`)."""
    f = checked_frequencies(system, operating_hz)
    if not f.size:
        raise InputError("system", "an elastic mode or an operating frequency for the loss factors' Maxwell models",
                         Plain("none: every mode has zero frequency"))
    return float(f.min() / BAND_MARGIN), float(f.max() * BAND_MARGIN)


def causal_loss_factors(system, band_hz=None, terms: int | None = None, operating_hz=()):
    """``system`` with every mount axis's loss factor replaced by the causal Maxwell model nearest its
    complex stiffness ``k (1 + i eta)`` at every elastic natural frequency and operating frequency
    (:func:`constant_loss_model`, checked at :func:`checked_frequencies`), which a time solve can carry.

    Parameters
    ----------
    system : sixdof.model.system.System
    band_hz : array_like, shape (2,), optional
        ``[low, high]`` [Hz], covering every frequency checked; default :func:`loss_band`.
    terms : int, optional
        Relaxation frequencies per axis to choose the branches among (default: see :func:`constant_loss_model`).
    operating_hz : array_like, optional
        The operating frequencies [Hz] of the excitation (harmonic loads, unbalance).

    Returns
    -------
    system : sixdof.model.system.System
        Without loss factors, with the branches (:func:`with_fits`); each axis's long-term stiffness replaces
        its stiffness (the statics see it; a gravity preload stays as given, see :func:`with_fits`).
    fits : tuple of MaxwellFit
        One per mount axis with a loss factor, named ``"<mount> <axis>"``, its data the frequencies checked.

    Raises
    ------
    sixdof.errors.InputError
        ``band_hz`` when it leaves out a frequency checked.
    """
    check = checked_frequencies(system, operating_hz)
    band = loss_band(system, operating_hz) if band_hz is None else frequency_band(band_hz, "band_hz")
    outside = check[(check < band[0]) | (check > band[1])]
    if outside.size:
        raise InputError("band_hz", f"a band covering every natural and operating frequency ({check[0]:.4g}-"
                         f"{check[-1]:.4g} Hz), where the loss factors' models are checked",
                         Plain(f"[{band[0]:g}, {band[1]:g}] Hz, without {', '.join(f'{f:.4g}' for f in outside)} Hz"))
    fits, models = [], {}
    for mount in system.mounts:
        for a in np.flatnonzero(mount.loss_factor > 0):
            k, eta = float(mount.stiffness[a]), float(mount.loss_factor[a])
            if eta not in models:  # the model is k times that of k = 1: one fit per loss factor
                models[eta] = constant_loss_model(1.0, eta, band, terms, check_hz=check)
            unit = models[eta]
            fits.append((mount.name, AXES[a], dataclasses.replace(
                unit, long_term=k * unit.long_term, stiffness=readonly(k * unit.stiffness),
                storage=readonly(k * unit.storage), name=f"{mount.name} {AXES[a]}", source=f"loss factor {eta:g}")))
    plain = dataclasses.replace(system, mounts=tuple(dataclasses.replace(m, loss_factor=np.zeros(3))
                                                     for m in system.mounts))
    return with_fits(plain, fits), tuple(fit for _, _, fit in fits)


def loss_fit_misses(fits) -> list[str]:
    """One message per causal model of a loss factor (``source`` ``"loss factor ..."``) that misses
    :data:`LOSS_MODULUS_TARGET` in ``|K*|`` or :data:`LOSS_FACTOR_TARGET` in loss factor at a frequency it is
    checked at, naming its mount axes, its worst errors and where; none: []."""
    groups: dict[int, list] = {}
    for fit in fits:
        if fit.source.startswith("loss factor ") and (fit.modulus_error > LOSS_MODULUS_TARGET
                                                      or fit.loss_factor_error > LOSS_FACTOR_TARGET):
            # One model per loss factor, scaled by each axis's k: the same relative misfit, one message.
            groups.setdefault((fit.source, fit.modulus_error, fit.loss_factor_error), []).append(fit)
    messages = []
    for members in groups.values():
        fit = members[0]
        k = fit.dynamic_stiffness(fit.f_hz)
        modulus = np.abs(np.abs(k) / np.abs(fit.storage * (1 + 1j * fit.loss_factor)) - 1)
        eta = np.abs(k.imag / k.real / fit.loss_factor - 1)
        messages.append(
            f"the causal Maxwell model of {fit.source} ({', '.join(m.name for m in members)}) that the time paths "
            f"use misses k (1 + i eta) by up to {100 * fit.modulus_error:.3g} % in |K*| (at "
            f"{fit.f_hz[np.argmax(modulus)]:.4g} Hz) and {100 * fit.loss_factor_error:.3g} % in loss factor (at "
            f"{fit.f_hz[np.argmax(eta)]:.4g} Hz) over the natural and operating frequencies "
            f"{fit.f_hz[0]:.4g}-{fit.f_hz[-1]:.4g} Hz (targets {100 * LOSS_MODULUS_TARGET:g} % and "
            f"{100 * LOSS_FACTOR_TARGET:g} %): a constant loss factor is not causal, and over this spread of "
            "frequencies no causal model holds it; the time response's damping and stiffness differ from the "
            "frequency responses' there")
    return messages


def long_term_note(fits) -> str:
    """The line a run prints and records when its statics use the long-term stiffness of the causal Maxwell
    models of the loss factors (``fits`` :class:`MaxwellFit`, those with ``source`` ``"loss factor ..."``), with
    their worst errors at the frequencies checked; "" without such models."""
    causal = [fit for fit in fits if fit.source.startswith("loss factor ")]
    if not causal:
        return ""
    ratios = {fit.source: fit.long_term / fit.storage[0] for fit in causal}
    return ("statics: with the long-term (zero-frequency) stiffness of the causal Maxwell models of the loss factors, "
            + ", ".join(f"{ratio:.3g} k for {source}" for source, ratio in ratios.items())
            + f" (the time paths' model; worst errors at the natural and operating frequencies "
            f"{100 * max(f.modulus_error for f in causal):.3g} % in |K*|, "
            f"{100 * max(f.loss_factor_error for f in causal):.3g} % in loss factor)")

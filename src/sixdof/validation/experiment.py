"""The validation experiment: the modal results of a system checked against simulated time histories.

Like is compared with like: the model side is computed from exactly what the time integration
integrates, ``M q'' + C q' + K q = Q`` with the total viscous ``C``. Hysteretic loss factors
(a frequency-independent complex stiffness ``k (1 + i eta)``) have no causal time-domain form, so the
time histories cannot contain them: the model FRF here leaves them out, and the report says so.

Two experiments on the time-domain solver, each compared with what the modal analysis predicts (the
estimators are in :mod:`sixdof.validation.estimation`):

1. **Free decay.** Released in mode r's damped (complex) shape, ``q = Re(s), q' = Re(lambda s)``, the
   body moves as ``Re(s e^{lambda t})``: that mode alone, whatever the damping (classical or not).
   :func:`~sixdof.validation.estimation.decay_estimate` gives its damped frequency and damping ratio,
   compared with the exact ``Im(lambda) / 2 pi`` and ``-Re(lambda) / |lambda|`` of the complex
   eigenvalue (:func:`sixdof.analysis.statespace.damped_modes`), not the diagonal approximation.
2. **Random excitation.** A force at a body point, Gaussian white noise sampled at ``fs`` and
   linearly interpolated (a tabulated signal), drives the body; the H1 FRF and coherence of the
   mode's modal coordinate per unit force are estimated and compared with the model FRF including
   the first-order hold of the sampled force (:func:`~sixdof.validation.estimation.held_model_frf`).

Verdicts: every mode gets four checks (:data:`CHECKS`), each a measured disagreement against a stated
limit (:class:`Check`); a mode passes when all four pass, the validation when every mode does. The
limits are the module's named thresholds (:data:`K_SIGMA`, :data:`DECAY_RTOL`, :data:`DECAY_ZETA_ATOL`,
:data:`PEAK_BINS`, :data:`H1_FLOOR`): statistical where the estimate has a statistical error (H1),
numerical floors where it has none (a noise-free decay, a peak located to a bin).

Runtime: one random run per elastic mode, each ``averages`` Welch segments of ``segment_samples``
samples with 50 % overlap; a mode's segment lasts ``4 / (2 zeta_r f_r)`` (its bins a quarter of its
half-power bandwidth), at least 8 periods, at most ``max_segment_s``, and its sample rate is
``segment_samples / segment`` (at least ``oversampling`` times the top of the mode's band). Every run
has the same sample count, so the solver compiles once.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from sixdof.frozen import BriefRepr
from sixdof.model.system import System
from sixdof.results import TimeHistory, label, part, quantity, result_type, sequence, stacked
from sixdof.validation.estimation import (
    DecayEstimate,
    EstimatedFRF,
    as_column,
    first_column,
)

#: A disagreement with a statistical error counts when it exceeds this many standard errors. One-sided
#: Gaussian tail beyond 3 sigma: 0.13 %, so a six-mode validation of a correct model fails by chance
#: about once in 130 runs (and the seed is fixed: the same scenario gives the same verdict every time),
#: while the mismatches it is there to catch (hysteresis left in the model: 27 to 93 sigma) are far out.
K_SIGMA = 3.0
#: Free decays are noise-free: their only errors are the solver's (rtol 1e-8 per DOF scale) and the
#: estimator's (extrema by parabolic interpolation at >= 64 samples per cycle, ~1e-6, measured).
#: Damped frequency: relative limit; damping ratio: relative to the model's ratio. 100 times the
#: numerical error and below the modelling differences that matter (1 % of stiffness moves a
#: frequency 5e-3, 1 % of damping moves zeta 1e-2 of itself).
DECAY_RTOL = 1e-3
#: Absolute floor of the damping-ratio check for (nearly) undamped modes [1].
DECAY_ZETA_ATOL = 1e-5
#: The H1 peak (parabola through the largest bin and its neighbours) must lie within this many
#: frequency bins of the model's peak: the estimate resolves no finer than a bin.
PEAK_BINS = 1.0
#: Relative FRF error allowed besides the random error, for systematic errors that the Bendat-Piersol
#: random error leaves out (Welch resolution bias, solver tolerance 1e-5), which matter where the
#: random error is small (~2e-3 at well-excited peaks). The peak bins' resolution bias (Hann, bins a
#: quarter of the half-power bandwidth: a few %) touches a few bins and barely moves the median.
#: Measured on the engine and a six-mode box, seeds 0-2: the median without floor is 0.8-1.6 (its
#: mean square 1.3-3.7 against 2 expected: the random error is calibrated), 0-1.4 with it.
H1_FLOOR = 0.01
#: The median of a Rayleigh variable of scale 1 (the magnitude of a complex Gaussian error whose
#: parts each have the standard deviation ``eps``): the median of ``|H1 - G| / (|G| eps)`` when the
#: model is right.
RAYLEIGH_MEDIAN = math.sqrt(2.0 * math.log(2.0))
#: Standard error of a sample median of N such values is ``MEDIAN_SPREAD / sqrt(N)``:
#: ``1 / (2 p(m))`` with ``p(m) = m e^{-m^2/2}`` the Rayleigh density at its median m.
MEDIAN_SPREAD = 1.0 / (2.0 * RAYLEIGH_MEDIAN * math.exp(-RAYLEIGH_MEDIAN**2 / 2.0))
#: Adjacent Hann-windowed bins are correlated: one independent value per equivalent noise bandwidth
#: (1.5 bins for Hann).
BINS_PER_INDEPENDENT = 1.5
#: The checks of each mode: (name, unit, what is measured against what).
CHECKS = (
    ("decay_frequency", "1", "|fd_decay / fd_model - 1| <= DECAY_RTOL"),
    ("decay_damping", "1", "|zeta_decay - zeta_model| <= DECAY_RTOL zeta_model + DECAY_ZETA_ATOL"),
    ("frf_peak", "Hz", "|fpk_h1 - fpk_model| <= PEAK_BINS df"),
    ("frf_h1", "1", "median over the band of max(|H1 - G| / |G| - H1_FLOOR, 0) / eps "
                    "<= RAYLEIGH_MEDIAN + K_SIGMA MEDIAN_SPREAD sqrt(BINS_PER_INDEPENDENT / N)"),
)
PASS, FAIL = "PASS", "FAIL"
#: Points of a random run's model curve across its band (figures).
MODEL_CURVE_POINTS = 801


@dataclass(frozen=True)
class ValidationSettings:
    """How :func:`~sixdof.validation.runs.validate` excites and samples the system. Every default adapts to the system.

    Parameters
    ----------
    load_point : array_like, shape (3,), optional
        Where the random force acts [m from the CG]. Default: the first mount's position, which
        sits off every plane of symmetry of usual layouts.
    load_direction : str or array_like, shape (3,), optional
        Direction of the random force. Default ``[1, 1, 1]``: every DOF is driven.
    force_rms : float
        RMS of the random force [N] (linear system: scale only). Default 1000.
    segment_samples : int
        Samples per Welch segment, the same in every run. Default 2048.
    oversampling : float
        Sample rate of each run at least this many times the top of its mode's band. Default 4.
    max_segment_s : float
        Longest Welch segment [s] (undamped or very lightly damped modes). Default 120.
    averages : int
        Welch segments (50 % overlap) per run. Default 8.
    decay_cycles : float
        Damped cycles simulated per free decay, fewer when the amplitude would fall below 1e-3 of
        its start. Default 8.
    decay_samples : int
        Samples per free decay (one compiled solver serves all modes). Default 512.
    seed : int
        Seed of the random force. Default 0.
    rtol, atol : float
        Solver tolerances of the random runs (free decays: the solver's defaults). Default 1e-5 each, relative
        to each DOF's scale: far below the estimates' statistical errors (~1e-2), half the steps of 1e-7.
    """

    load_point: tuple | None = None
    load_direction: object = (1.0, 1.0, 1.0)
    force_rms: float = 1000.0
    segment_samples: int = 2048
    oversampling: float = 4.0
    max_segment_s: float = 120.0
    averages: int = 8
    decay_cycles: float = 8.0
    decay_samples: int = 512
    seed: int = 0
    rtol: float = 1e-5
    atol: float = 1e-5


@dataclass(frozen=True, eq=False)
class FreeDecay:
    """One free-decay run (figure-ready): the modal coordinate and its estimate.

    Attributes
    ----------
    mode : int
        1-based mode number.
    history : sixdof.results.TimeHistory
        The body's motion after release in the damped (complex) mode shape.
    eta : ndarray, shape (n,)
        Modal coordinate ``phi_r' M q`` at ``history.t`` [sqrt(kg) m].
    estimate : DecayEstimate
    """

    mode: int = label()
    history: TimeHistory = part(lambda: TimeHistory, prefix="")
    eta: np.ndarray = quantity("kg^0.5 m", ("t",), description="modal coordinate phi_r' M q")
    estimate: DecayEstimate = part(lambda: DecayEstimate, prefix="")


@dataclass(frozen=True)
class ModeCheck:
    """One row of the validation table (one elastic mode).

    Attributes
    ----------
    mode : int
        1-based, ascending frequency.
    dominant_dof : str
    f_model_hz : float
        Undamped natural frequency [Hz].
    zeta_model : float
        Exact damping ratio ``-Re(lambda) / |lambda|`` of the mode's complex eigenvalue (viscous
        damping only: what the time integration integrates).
    f_damped_model_hz : float
        Exact damped frequency ``Im(lambda) / 2 pi`` [Hz].
    f_damped_estimated_hz : float
        From the free decay [Hz].
    zeta_estimated : float
        From the free decay (logarithmic decrement).
    log_decrement_estimated : float
    f_peak_model_hz : float
        Peak of the model FRF of the mode's modal coordinate, on a fine grid [Hz].
    f_peak_estimated_hz : float
        Peak of the H1 estimate of the same FRF [Hz].
    frequency_resolution_hz : float
        Bin width of the estimate [Hz].
    h1_median_error : float
        Median of ``|H1 - G| / |G|`` over the mode's band where the coherence is >= 0.9 (``G`` the
        held model FRF, :func:`held_model_frf`).
    h1_error_in_sigmas : float
        Median over the same bins of ``max(|H1 - G| / |G| - H1_FLOOR, 0) / eps``, ``eps`` the random
        error (:func:`h1_random_error`): the error beyond the floor in units of the random error, at
        most about 1.2 when the model is right (the median of a complex Gaussian error's magnitude,
        :data:`RAYLEIGH_MEDIAN`).
    h1_error_at_peak : float
        ``|H1 - G| / |G|`` at the peak bin.
    h1_sigma_at_peak : float
        The random error of ``|H1|`` there (:func:`h1_random_error`).
    """

    mode: int = quantity("1", (), description="elastic modes checked (mode numbers of /modal/mode)")
    dominant_dof: str = quantity("", (), decode=str)
    f_model_hz: float = quantity("Hz", (), decode=float)
    zeta_model: float = quantity("1", (), decode=float)
    f_damped_model_hz: float = quantity("Hz", (), decode=float)
    f_damped_estimated_hz: float = quantity("Hz", (), decode=float)
    zeta_estimated: float = quantity("1", (), decode=float)
    log_decrement_estimated: float = quantity("1", (), decode=float)
    f_peak_model_hz: float = quantity("Hz", (), decode=float)
    f_peak_estimated_hz: float = quantity("Hz", (), decode=float)
    frequency_resolution_hz: float = quantity("Hz", (), decode=float)
    h1_median_error: float = quantity("1", (), decode=float)
    h1_error_in_sigmas: float = quantity("1", (), decode=float)
    h1_error_at_peak: float = quantity("1", (), decode=float)
    h1_sigma_at_peak: float = quantity("1", (), decode=float)

    @property
    def f_damped_error(self) -> float:
        """Relative error of the free decay's damped frequency."""
        return self.f_damped_estimated_hz / self.f_damped_model_hz - 1.0

    @property
    def zeta_error(self) -> float:
        """``zeta_estimated - zeta_model`` (absolute: zeta may be 0)."""
        return self.zeta_estimated - self.zeta_model

    @property
    def f_peak_offset_hz(self) -> float:
        """``f_peak_estimated_hz - f_peak_model_hz`` [Hz]: what the ``frf_peak`` check holds against a bin."""
        return self.f_peak_estimated_hz - self.f_peak_model_hz


#: Columns of :meth:`ValidationReport.table`: (attribute, header, format). Each header names its unit as the
#: other tables do ([1]: a ratio; [relative]: over the model's value), in the units of the checks (:data:`CHECKS`)
#: so that a column and its check show the same number; the frequencies are named as in the checks' rules.
COLUMNS = (
    ("mode", "mode", "{:d}"),
    ("dominant_dof", "dof", "{}"),
    ("f_model_hz", "f_model [Hz]", "{:.5g}"),
    ("f_damped_model_hz", "fd_model [Hz]", "{:.6g}"),
    ("f_damped_estimated_hz", "fd_decay [Hz]", "{:.6g}"),
    ("f_damped_error", "fd_err [relative]", "{:+.1e}"),
    ("zeta_model", "zeta_model [1]", "{:.5f}"),
    ("zeta_estimated", "zeta_decay [1]", "{:.5f}"),
    ("zeta_error", "zeta_err [1]", "{:+.1e}"),
    ("f_peak_model_hz", "fpk_model [Hz]", "{:.5g}"),
    ("f_peak_estimated_hz", "fpk_h1 [Hz]", "{:.5g}"),
    ("f_peak_offset_hz", "fpk_h1 - fpk_model [Hz]", "{:+.2g}"),
    ("frequency_resolution_hz", "df [Hz]", "{:.2g}"),
    ("h1_median_error", "h1_err_med [relative]", "{:.1e}"),
    ("h1_error_in_sigmas", "h1_err/sigma [1]", "{:.2f}"),
    ("h1_error_at_peak", "h1_err_pk [relative]", "{:.1e}"),
    ("h1_sigma_at_peak", "h1_sigma_pk [relative]", "{:.1e}"),
)


@dataclass(frozen=True)
class Check:
    """One check of one mode: a measured disagreement against its limit (see :data:`CHECKS`).

    Attributes
    ----------
    key : str
        ``"<mode>:<name>"``, unique in a report (the labels of the ``check`` axis in the file).
    mode : int
        1-based mode number.
    name : str
        What is checked: ``decay_frequency``, ``decay_damping``, ``frf_peak`` or ``frf_h1``.
    value : float
        The disagreement measured, in ``unit`` (NaN when it could not be measured: a FAIL).
    limit : float
        The largest disagreement that passes, in ``unit``.
    unit : str
        ``1`` (relative, or in standard errors for ``frf_h1``) or ``Hz``.
    verdict : str
        ``PASS`` when ``value <= limit``, else ``FAIL``.
    """

    key: str = quantity("", (), decode=str, description="<mode>:<check name>")
    mode: int = quantity("1", (), decode=int, description="mode number (of /modal/mode)")
    name: str = quantity("", (), decode=str)
    value: float = quantity("", (), decode=float, description="disagreement measured, in the check's unit")
    limit: float = quantity("", (), decode=float, description="largest disagreement that passes")
    unit: str = quantity("", (), decode=str)
    verdict: str = quantity("", (), decode=str, description="PASS or FAIL")


def _check(mode: int, name: str, value: float, limit: float) -> Check:
    unit = next(u for n, u, _ in CHECKS if n == name)
    passed = bool(np.isfinite(value) and value <= limit)
    return Check(key=f"{mode}:{name}", mode=mode, name=name, value=float(value), limit=float(limit), unit=unit,
                 verdict=PASS if passed else FAIL)


@dataclass(frozen=True, eq=False)
class RandomRun:
    """One random-force run (figure-ready): H1 of one mode's modal coordinate and its model.

    Attributes
    ----------
    mode : int
        1-based mode number.
    band_hz : (float, float)
        The mode's band (half-way to its neighbours but at least three half-power bandwidths either side,
        within 0.7 to 1.3 times its frequency) [Hz].
    estimated : EstimatedFRF
        H1 and coherence of ``eta_r`` per unit force [sqrt(kg) m/N].
    model : ndarray, shape (nf, 1), complex
        The held model FRF at ``estimated.f_hz`` (:func:`held_model_frf`).
    model_f_hz, model_curve : ndarray, shape (n,), or None
        The same model on a grid :data:`MODEL_CURVE_POINTS` fine across the band [Hz], for figures: at the
        estimate's bins a sharp resonance would be a polygon.
    """

    mode: int = label()
    band_hz: tuple[float, float] = label(encode=lambda band: np.asarray(band, dtype=float),
                                         decode=lambda band: (float(band[0]), float(band[1])))
    estimated: EstimatedFRF = part(lambda: EstimatedFRF, prefix="")
    model: np.ndarray = quantity(lambda run: run.estimated.unit, ("f_hz",), encode=first_column, decode=as_column,
                                 description="model FRF of the same, with the first-order hold of the sampled force")
    model_f_hz: np.ndarray | None = quantity("Hz", ("model_f_hz",), default=None)
    model_curve: np.ndarray | None = quantity(lambda run: run.estimated.unit, ("model_f_hz",), default=None,
                                              description="the model on a fine grid across the band (figures)")


@result_type
@dataclass(frozen=True, eq=False)
class ValidationReport(BriefRepr):
    """Result of :func:`~sixdof.validation.runs.validate`: one row per elastic mode, and the runs behind them.

    Attributes
    ----------
    rows : tuple of ModeCheck
        The table (see :meth:`table`, :meth:`format`).
    random_runs : tuple of RandomRun
        One per elastic mode.
    decays : tuple of FreeDecay
        One per elastic mode.
    load_point, load_direction : ndarray, shape (3,)
        The random force's point [m] and unit direction.
    random_duration_s : float
        Simulated time of all random runs together [s].
    wall_time_s : float
        Wall-clock time of all simulations and estimates [s].
    notes : tuple of str
        What was left out of the comparison (hysteresis, rigid-body modes) and other remarks.
    checks : tuple of Check
        Four per mode (:data:`CHECKS`), each with its limit and verdict.
    mode_verdicts : tuple of str
        ``PASS`` or ``FAIL`` per row of ``rows``: every check of the mode passed, or not.
    verdict : str
        ``PASS`` when every mode passed, else ``FAIL``.
    """

    rows: tuple[ModeCheck, ...] = stacked(lambda: ModeCheck, dim="mode", key="mode")
    random_runs: tuple[RandomRun, ...] = sequence(lambda: RandomRun, group="random", key=lambda run: f"mode_{run.mode}")
    decays: tuple[FreeDecay, ...] = sequence(lambda: FreeDecay, group="decay", key=lambda decay: f"mode_{decay.mode}")
    load_point: np.ndarray = label()
    load_direction: np.ndarray = label()
    random_duration_s: float = label()
    wall_time_s: float = label()
    notes: tuple[str, ...] = label(default=())
    checks: tuple[Check, ...] = stacked(lambda: Check, dim="check", key="key", group="checks", default=())
    mode_verdicts: tuple[str, ...] = label(default=())
    verdict: str = label(default="")

    def table(self) -> tuple[tuple[str, ...], tuple[tuple, ...]]:
        """``(headers, rows)`` of raw values, one row per mode, columns as :data:`COLUMNS`."""
        headers = tuple(h for _, h, _ in COLUMNS)
        return headers, tuple(tuple(getattr(r, a) for a, _, _ in COLUMNS) for r in self.rows)


def mode_checks(row: ModeCheck, h1_bins: int) -> list[Check]:
    """The four checks of one mode (:data:`CHECKS`) from its table row.

    Parameters
    ----------
    row : ModeCheck
    h1_bins : int
        Bins of the mode's band used for ``h1_error_in_sigmas`` (coherence >= 0.9).
    """
    h1_limit = (RAYLEIGH_MEDIAN + K_SIGMA * MEDIAN_SPREAD * math.sqrt(BINS_PER_INDEPENDENT / h1_bins)
                if h1_bins else math.nan)
    return [
        _check(row.mode, "decay_frequency", abs(row.f_damped_error), DECAY_RTOL),
        _check(row.mode, "decay_damping", abs(row.zeta_error), DECAY_RTOL * row.zeta_model + DECAY_ZETA_ATOL),
        _check(row.mode, "frf_peak", abs(row.f_peak_offset_hz),
               PEAK_BINS * row.frequency_resolution_hz),
        _check(row.mode, "frf_h1", row.h1_error_in_sigmas, h1_limit),
    ]


def integrated_model(system: System) -> tuple[System, tuple[str, ...]]:
    """``system`` as the time integration of a check of its linear (modal, random) results sees it: linearized
    about its static equilibrium (:meth:`System.linearized`: the model its modes and FRFs describe) and the
    hysteretic loss factors removed.

    Returns
    -------
    system : System
        ``system`` itself when it is linear and no mount has a loss factor, else such a copy.
    mounts : tuple of str
        Names of the mounts whose loss factors were removed.
    """
    system = system.linearized()
    hysteretic = tuple(m.name for m in system.mounts if np.any(m.loss_factor))
    if not hysteretic:
        return system, ()
    mounts = tuple(dataclasses.replace(m, loss_factor=np.zeros(3)) for m in system.mounts)
    return dataclasses.replace(system, mounts=mounts), hysteretic

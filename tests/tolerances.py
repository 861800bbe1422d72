"""Tolerances used by the tests, named once. Each says what it bounds and why it is that size."""

# Linear algebra on 6x6 float64 matrices whose entries span ~12 decades (N/m vs N m/rad):
# results are compared relative to each quantity's own scale.
RTOL_LINALG = 1e-10
# Closed-form natural frequencies against the eigen-solver.
RTOL_FREQUENCY = 1e-10
# Round-off floor of an assembled matrix entry that must be zero, relative to the matrix scale.
RTOL_ZERO_ENTRY = 1e-14
# Absolute round-off of a few float64 operations on quantities of order one or less (unit vectors,
# dimensionless signals and transmissibilities, exact small-integer arithmetic): a few ulps of 1.
ATOL_UNIT_ROUNDOFF = 1e-15
# Modal damping ratios of classical damping (Rayleigh, modal) against their defining formulas
# (zeta = alpha / 2w + beta w / 2, the ratios asked for): a projection on mass-normalized modes.
RTOL_DAMPING_RATIO = 1e-12
# Exact damping ratios of non-proportional damping (from the complex eigenvalues, paired to modes)
# against -Re(lambda) / |lambda| of the 12x12 state matrix, or against the diagonal ratios where the
# damping is classical: a non-symmetric eigenproblem, conditioned worse than eigh.
RTOL_COMPLEX_DAMPING_RATIO = 1e-9
# Support reactions of gravity statics against the weight and the lever rule: a 6x6 solve and the
# mount forces from it.
RTOL_STATICS = 1e-9
# Statics of an ill-conditioned K (condition 2e8: one mount of 1e12 N/m among three of 1e4 N/m) against the exact
# rational solution, relative to the largest displacement: a float64 solve loses up to eps x condition (measured
# 2.9e-8); and the support reactions, whose stiff mount's 5 nm deflection cancels ~0.08 m terms (measured 3.6e-9).
RTOL_ILL_CONDITIONED_STATICS = 1e-7
# A mode release sets the mode's dominant DOF to the amplitude asked for: one scaling of the shape.
RTOL_MODE_RELEASE_AMPLITUDE = 1e-14
# A printed value of the seed paper agrees with ours when it equals ours rounded or truncated to the
# digits printed (the paper does both: f1 = 0.6255 Hz is printed 0.62): within one unit of its last
# printed digit (see tests/test_seed_case_study.py).
def printed_ulp(printed: str) -> float:
    """One unit in the last digit of a number as printed (``"-19.140"`` -> 0.001)."""
    mantissa = printed.lower().split("e")[0]
    decimals = len(mantissa.split(".")[1]) if "." in mantissa else 0
    exponent = int(printed.lower().split("e")[1]) if "e" in printed.lower() else 0
    return 10.0 ** (exponent - decimals)

# --- frequency responses (tests/test_frf.py) ---
# Direct (batched LU) and modal-summation receptances: measured ~4e-13 on the bridge (lightly damped
# 0.6 Hz modes), the requirement is 1e-10, relative to each entry's own scale.
RTOL_FRF_METHODS = 1e-10
# Z(w) H(w) - I in mass-scaled (dimensionless) form, entry by entry: measured <= 1e-12 on the bridge.
RTOL_FRF_IDENTITY = 1e-10
# FRFs against closed forms (SDOF receptance, transmissibility) and peer libraries (python-control),
# pointwise relative: both sides are a handful of float64 operations from exact.
RTOL_FRF_CLOSED_FORM = 1e-10
# Steady state of an ODE integration (scipy DOP853, rtol 1e-11) started on the FRF's steady state,
# relative to each DOF's amplitude: bounded by the integrator's global error.
RTOL_STEADY_STATE = 1e-7

# --- modal superposition (tests/test_superposition.py) ---
# Modal superposition against the exact matrix exponential of the state-space system, per DOF
# relative to its own peak: measured ~3e-12 on the bridge (quadrature and recursion are exact to
# round-off; the rest is the conditioning of the modal transform over 12 decades of K).
RTOL_MODAL_EXACT = 1e-9
# Modal superposition against the direct (diffrax) solver, all modes kept, per DOF relative to its
# own peak: the requirement.
RTOL_MODAL_DIRECT = 1e-6
# A run continued window by window from its end states (modal coordinates and ground integrals
# carried exactly) against the same run in one piece, per DOF relative to its peak: the same
# recursion from the same states, so round-off only (measured ~3e-15).
RTOL_WINDOWS = 1e-13
# The automatic count of quadrature nodes against many more on the same grid, per DOF relative to its
# peak: the quadrature adds no error of its own beyond round-off (measured <= 2e-14 on the bridge).
RTOL_QUADRATURE_NODES = 1e-12
# Real modes on the bridge with mount dashpots (modal damping coupling ~0.3) miss the response by
# ~1e-1 of a DOF's peak: a disagreement that must show, far above any round-off.
MODAL_DAMPING_COUPLING_MIN = 1e-3
# Classical damping is detected as such: the coupling left by the modal transform is round-off.
MODAL_DAMPING_COUPLING_CLASSICAL = 1e-10
# The truncation error a truncated superposition reports (against the full modal set) equals the error
# measured against the reference, up to the reference's own error (1e-9 to 1e-6 of a DOF's peak) next
# to a truncation error of 1e-3 to 1e-1.
RTOL_REPORTED_TRUNCATION = 1e-3
# Truncation to 4 of 6 modes under a slow load: the residual correction must at least halve the
# error of plain truncation (it removes the quasi-static part, ~(2 Hz / 21 Hz)^2 left).
MODAL_RESIDUAL_GAIN = 0.5

# --- direct time integration (tests/test_direct.py, test_response.py, test_excitation.py) ---
# Direct (diffrax) solution against the exact matrix exponential of the augmented state-space
# system, each DOF relative to its own peak: issue 3's requirement. Measured 1e-11..2e-8 at the
# default tolerances (rtol = atol = 1e-9 on the scaled state).
RTOL_DIRECT_EXACT = 1e-6
# Energy balance after a shock: work in = dissipated + stored, relative to the work in. Quadrature
# (Simpson on 10 kHz samples, split at the pulse edges) is good to ~1e-9 here.
RTOL_ENERGY_BALANCE = 1e-6
# Evaluating a signal against its closed form written out in the test: a few float64 operations.
RTOL_SIGNAL = 1e-12
# A body at rest on a ground displaced before the start, by modal superposition: the transform to
# modes and back leaves round-off, relative to the ground's displacement (and its rates at the highest
# natural frequency); measured ~4e-13 on the bridge.
RTOL_AT_REST = 1e-10
# Absolute motion = relative motion + ground motion, sample by sample: one float64 addition,
# relative to the largest value.
RTOL_RELATIVE_MOTION = 1e-12

# --- validation against time histories (tests/test_validate.py) ---
# H1 magnitude error in units of its Bendat-Piersol random error: over a few hundred bins of a
# seeded record, none beyond 5 sigma (Gaussian: p ~ 6e-7 per bin) ...
H1_MAX_SIGMAS = 5.0
# ... and the normalized errors' mean square within 0.3 of 1 (the formula is calibrated, not just
# a bound; the estimate of a mean square over ~500 bins has a sampling spread of ~0.1).
H1_SIGMA_CALIBRATION = 0.3
# Median over a band of |H1 - G| / (|G| eps) for simulated runs: 1.18 expected (median of a complex
# Gaussian error's magnitude), measured 0.8-1.4 on a six-mode system.
H1_MEDIAN_SIGMAS = 2.5
# Free-decay damped frequency and damping ratio (extrema by parabolic interpolation at ~64 samples
# per cycle, least squares over 16 extrema): measured ~7e-7 on the bridge.
RTOL_DECAY = 1e-5
# sixdof.analysis.direct.simulate (defaults rtol = atol = 1e-8 per DOF scale) against the FRF's steady state.
RTOL_DIRECT_STEADY_STATE = 1e-6

# --- batches of variants (tests/test_batch.py) ---
# Vectorized batch peaks against sixdof.analysis.direct.simulate run one by one, per DOF relative to that
# DOF's own peak (issue 7): both solves are ~1e-8 from exact; measured ~1e-9.
RTOL_BATCH_DIRECT = 1e-6
# The exact engine's batch peaks against superpose of each variant alone (the same arithmetic, the
# variants' coordinates side by side in chunks of any size), relative to each DOF's peak: round-off
# (measured ~5e-13).
RTOL_BATCH_CHUNKS = 1e-11
# The exact engine's batch peaks against scipy's DOP853 at rtol 1e-12 on the 12-state system, relative
# to each DOF's peak: bounded by DOP853's global error (measured ~1e-12).
RTOL_BATCH_SCIPY = 1e-10
# Batched jnp.linalg.eigh of the mass-scaled stiffness against scipy's eigh(K, M) per variant:
# measured ~5e-13 on the bridge.
RTOL_BATCH_FREQUENCY = 1e-10
# Batched assembly of K and C against System.K / System.C per variant, relative to the matrix scale.
RTOL_BATCH_MATRIX = 1e-12

# --- figures (tests/test_plots.py) ---
# A drawn value against the number it draws (a unit scale, an offset, a ratio): a few float64
# operations.
RTOL_DRAWN = 1e-12

# --- values quoted in the tests (tests/test_seed_case_study.py, test_cli.py) ---
# sixdof's natural frequencies of the bridge quoted to 4 decimals in Hz (38.0344, 21.3398, 1.1875).
ATOL_QUOTED_HZ = 1e-4
# sixdof's eigenvector entries of the bridge quoted to 6 or 7 significant digits.
RTOL_QUOTED = 1e-5
# The random time check's RMS values from the FRFs (trapezoidal rule on its fine grid, the band's edges
# included) against random_response's (Simpson on its own grid): two quadratures of the same smooth PSD. A sum
# over the grid, counting the PSD's jump at each band edge as a whole step, was 5.9e-5 off on the small box.
RTOL_TIME_CHECK_RMS = 1e-6

# --- ground records and their baseline (tests/test_ground_drift.py) ---
# Velocity and displacement of a linearly interpolated acceleration (first-order hold) against the closed
# form of a straight-line acceleration, relative to their peaks: cumulative sums of exact increments, 2000
# intervals of round-off (measured ~1e-15).
RTOL_RECORD_INTEGRAL = 1e-12
# A baseline-corrected record (polynomial fit to its velocity, its ends brought to rest: a KKT solve of at most
# 8 unknowns on powers of normalized time) against the exact answers: its end velocity and displacement against
# zero, and the same correction of the record with a polynomial drift added, relative to the record's peak
# velocity, displacement or acceleration (measured <= 4e-14; the fit's conditioning grows with its degree).
RTOL_BASELINE = 1e-10
# Frequency derivatives through the statics of gravity's geometric stiffness (JAX, stiffness_jax) against
# central differences (relative step 1e-4) of systems that each solve their own statics, relative to each
# parameter's largest derivative: the differences' truncation and round-off (measured 2.2e-8 on skewed_machine).
RTOL_GEOMETRIC_GRADIENT = 1e-6

# --- measured data: FRF estimation, projection, correlation (tests/test_frf_estimation.py, test_projection.py) ---
# Multiple coherence of noise-free two-reference H1 (two-mass system, 41 s Hann segments against a 0.77 s decay):
# its distance from 1 is the leakage of the response to forces before each segment, measured 5.0e-3.
TOL_COHERENCE_NOISE_FREE = 1e-2
# Least-squares DOFs of an exact rigid motion on 12 channels of a metre-sized frame (pinv of a 12x6 matrix of
# condition ~10): a few ulps of the unit-sized values.
ATOL_PROJECTION_ROUNDOFF = 1e-13

# --- measured test data (tests/test_testfile.py, tests/test_exchange.py) ---
# ASCII UFF55 and UFF15 write 6 significant digits (E13.5): a mode shape or node coordinate read back is within
# half a unit of its 6th digit, 5e-6 of its own size.
RTOL_UFF_ASCII = 5e-6

# --- model updating (tests/test_update.py) ---
# Variables updated to exact test modes against the truth: the eigen-equation residual is zero there, and the
# bounded quasi-Newton search (ftol 1e-15) stops within this of it (measured: see the commit).
RTOL_UPDATE_EXACT = 1e-6
# The updated scenario's modes, written at full precision and read back, against the update's: round-off only.
RTOL_UPDATED_TEXT = 1e-9
# Noisy test modes (stated noise, one seed): each updated variable within this many of its standard errors.
UPDATE_NOISE_SIGMAS = 3.0

# --- the OpenSeesPy reference of the hysteretic bearings (tests/test_opensees_reference.py) ---
# OpenSees' BoucWen material updates z by backward Euler along the strain path: its error is first order in the
# step (or the strain increment), Newmark's on an elastic model second order. A halving of the step divides the
# error by 2 (or 4) within this share (measured ratios 1.96-2.03 and 3.98-4.0).
FIRST_ORDER_RATIO = 0.1
SECOND_ORDER_RATIO = 0.05
# The reference solves (DOP853, rtol 1e-11 piece by piece) against rtol 1e-13: the error the comparisons carry
# from the reference side, per DOF relative to its peak (measured <= 1e-7 on the rigid body, 3e-10 on one mass).
RTOL_HYSTERESIS_REFERENCE = 1e-6
# The BoucWen material on a cyclic quasi-static path of 400 increments per yield deflection against the exact
# n = 1 law, relative to Fy (measured 5.8e-4: the backward Euler error of the increment).
RTOL_BOUC_WEN_MATERIAL = 1e-3
# OpenSees (Newmark average acceleration) at its finest step of each test against the scipy solves: the
# time-step error, first order (measured on one mass at 0.625 ms: peak displacement <= 5.9e-4, hysteretic force
# history <= 2.9e-3 of the peak force; on the rigid body at 0.3125 ms the forces 3.4e-3).
RTOL_OPENSEES_PEAK = 1e-3
RTOL_OPENSEES_FORCE = 5e-3
# Richardson's 2 x(h/2) - x(h) against the reference, as a share of x(h/2)'s error: the first-order term is all
# of the difference (measured 0.014-0.016 on one mass; 0.02-0.21 per DOF of the rigid body, least on its vertical
# DOF, whose error is partly Newmark's second-order one).
RTOL_OPENSEES_RICHARDSON = 0.1
RTOL_OPENSEES_RICHARDSON_BODY = 0.3
# The hysteretic rigid body at 0.3125 ms against solve_ivp, per DOF relative to its peak: first order, larger than
# on one mass at the same step as its modes are faster (measured 3.4e-4 on z to 7.2e-3 on rz).
RTOL_OPENSEES_BODY = 1e-2
# The elastic rigid body at 1.25 ms against the exact solution, per DOF relative to its peak (measured <= 3.8e-4).
RTOL_OPENSEES_ELASTIC = 1e-3
# sixdof's direct solve of the hysteretic rigid body at its default tolerances against solve_ivp, per DOF relative
# to its peak (measured 7.9e-8 on x to 2.6e-6 on rz).
RTOL_SIXDOF_HYSTERESIS = 1e-5

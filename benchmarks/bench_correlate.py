"""Identification and model updating of the bundled tap test against plain scipy least squares (issue 47, item 10).

The test is ``sixdof/scenarios/machine_tap_test.uff`` (15 accelerometer channels x 3 hammer references x 991
lines, 1-100 Hz, 1 % noise), its truth ``machine_tap_test.truth.json``: six rigid-body modes 7.1-20.2 Hz (a
pair 2.9 % apart at 19.7 and 20.2 Hz), a flexible mode at 60.7 Hz, the as-built deviations front_left w 0.85,
rear v 1.20, CG offset (6, 0, 8) mm. The scenario's planned ``[test]`` and ``[update]`` tables are switched on
in memory (:func:`scenario`).

1. **Identification**: :func:`sixdof.validation.identify.identify_modes` (poly-reference LSCF poles, LSFD
   shapes, automatic selection from the stability diagram; NumPy only) against a plain
   ``scipy.optimize.least_squares`` fit of a modal model to the same FRFs (:func:`scipy_modal_fit`): per mode
   its frequency, damping ratio and complex residue of every channel and reference, 644 unknowns for 7 modes,
   started from peak picking (:func:`picked_peaks`), the residues from a linear least-squares solve at the
   picked poles, the Jacobian by finite differences grouped by its sparsity (``jac_sparsity``: without it each
   Jacobian would take 645 model evaluations of a 89,190 x 644 dense matrix).
2. **Update**: :func:`sixdof.design.update.update` (eigen-equation residual, exact JAX gradients, L-BFGS-B from 4
   starts, then the output-error polish and the covariance) from the identified rigid-body modes, against a plain
   ``least_squares`` of the same 10 variables (scaled to [0, 1] within their bounds, as ``update`` does) on the
   FRF error (:func:`scipy_frf_update`): the model's accelerance on the channels,
   ``rows' H(w) cols'`` from :func:`sixdof.analysis.frf.receptance` of the model at the variables (rows and
   columns moved to its CG), minus the measured one, each FRF over its RMS, from the given model, the Jacobian
   by finite differences (11 model FRFs each).

``update`` builds its jitted objective per call, so every call traces and compiles it again (the persistent
compilation cache is the command line's, off here): JAX's own spans (tracing, lowering, XLA's compilation)
are summed apart from the wall time, for the first call and for later ones; then with JAX's persistent
compilation cache on, as ``sixdof correlate`` runs it (a fresh folder: one call fills it, the next reads it).

Timings: ``identify_modes`` best of 5, the scipy modal fit once (it takes ~50x as long), ``update`` three times
(its first call, then the best of two), the scipy update best of 2; ``--quick``: each once, ``update`` twice.
Run: ``OPENBLAS_NUM_THREADS=1 python benchmarks/bench_correlate.py [--quick]`` (~1 min on 2 cores, up to 2 min
when other programs load them); writes ``results/correlate.json``.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import sys
import tempfile
import time

import numpy as np
import scipy.optimize
import scipy.signal
import scipy.sparse

import common

SCENARIOS = common.ROOT / "src" / "sixdof" / "scenarios"
SCENARIO = SCENARIOS / "machine_tap_test.toml"
TEST_FILE = SCENARIOS / "machine_tap_test.uff"
TRUTH = json.loads((SCENARIOS / "machine_tap_test.truth.json").read_text())
#: The variables' true values, in the order of the scenario's [update]: the four w rates, front and rear v,
#: all u, then the CG offset [m].
TRUE_X = np.array([0.85, 1.0, 1.0, 1.0, 1.0, 1.2, 1.0, 0.006, 0.0, 0.008])
#: Peaks of at least this share of their curve's maximum in prominence start the scipy fit, merged within PEAK_MERGE.
PEAK_PROMINENCE, PEAK_MERGE = 0.1, 0.01
#: The scipy update fits the FRFs up to here [Hz]: 1.5x the highest rigid-body mode, half the flexible mode's
#: frequency (which the rigid model lacks).
UPDATE_BAND_HZ = 30.0
#: A test mode whose shape is this far from rigid-body motion (the share of it left by the projection) is not
#: updated to (the workflow's rule).
RIGID_RESIDUAL = 0.3


def scenario():
    """The bundled scenario with its planned ``[test]`` and ``[update]`` tables switched on: every commented
    TOML line of the tables uncommented, and the CG offset's entry written in the updating's grammar
    (``[update] cg_offset``)."""
    from sixdof.io.scenario import parse_scenario

    text = SCENARIO.read_text()
    head, planned = text.split("# [test]\n", 1)
    planned = planned[:planned.index("# [[update.vary]]                             # the grammar")]
    lines = [line[2:] if re.match(r"# (\[|[A-Za-z0-9_]+ = )", line) else line
             for line in ("# [test]\n" + planned).splitlines()]
    planned = "\n".join(lines)
    first = planned.index("[[update.vary]]")
    planned = (planned[:first] + "[update]\ncg_offset = { bounds = [[-0.03, 0.03], [-0.03, 0.03], [-0.03, 0.03]] }\n\n"
               + planned[first:])
    return parse_scenario(head + planned, source=str(SCENARIO), base_dir=SCENARIOS)


# ----------------------------------------------------------------------------------------------------
# The truth on the channels.
# ----------------------------------------------------------------------------------------------------


def truth_modes(model, test):
    """Frequencies (7,) [Hz], damping ratios (7,) and real shapes on the channels (n_out, 7) of the as-built
    truth: the model at TRUE_X's six modes, then the stated flexible mode."""
    from sixdof.design.update import model_modes, moved_rows

    frequency, shapes = (np.asarray(a) for a in model_modes(model, TRUE_X))
    offset = np.asarray(model.matrices(TRUE_X)[2])
    rigid = np.asarray(moved_rows(test.response_rows(), offset)) @ shapes
    flex = TRUTH["flexible_mode"]
    a, b = flex["half_spans_m"]
    nodes = np.array([TRUTH["nodes_body_m"][str(n)] for n in test.out_nodes])
    flexible = test.out_directions[:, 2] * nodes[:, 0] * nodes[:, 1] / (a * b)
    return (np.append(frequency, flex["frequency_hz"]), np.append(TRUTH["modal_damping"], flex["damping_ratio"]),
            np.column_stack([rigid, flexible]))


def accuracy(frequency_hz, damping_ratio, shapes, truth) -> dict:
    """Each true mode's match among the found ones (the one-to-one assignment of the largest total MAC): its
    frequency error [%], damping ratio error [% of the true ratio], MAC; and how many modes were found."""
    from sixdof.validation.correlation import mac

    f_true, zeta_true, shapes_true = truth
    found = mac(shapes_true, shapes)
    true_index, index = scipy.optimize.linear_sum_assignment(-found)
    rows = []
    for t, k in zip(true_index, index):
        rows.append({"true_hz": float(f_true[t]), "found_hz": float(frequency_hz[k]),
                     "frequency_error_percent": float(100 * (frequency_hz[k] / f_true[t] - 1)),
                     "damping_error_percent": float(100 * (damping_ratio[k] / zeta_true[t] - 1)),
                     "mac": float(found[t, k])})
    return {"modes_found": int(len(frequency_hz)), "modes": rows,
            "worst_frequency_error_percent": max(abs(r["frequency_error_percent"]) for r in rows),
            "worst_damping_error_percent": max(abs(r["damping_error_percent"]) for r in rows),
            "worst_mac": min(r["mac"] for r in rows)}


# ----------------------------------------------------------------------------------------------------
# 1. Identification: a plain scipy least-squares fit of a modal model.
# ----------------------------------------------------------------------------------------------------


def picked_peaks(f_hz, H):
    """Peak picking: the peaks of the sum of |H| over all FRFs and over each reference's, of at least
    PEAK_PROMINENCE of their curve's maximum in prominence, merged within PEAK_MERGE; frequencies [Hz] and
    half-power damping ratios (of the curve that found them, clipped to 0.5-10 %)."""
    curves = [np.abs(H).sum(axis=(1, 2))] + [np.abs(H[:, :, j]).sum(axis=1) for j in range(H.shape[2])]
    found = []
    for curve in curves:
        for k in scipy.signal.find_peaks(curve, prominence=PEAK_PROMINENCE * curve.max())[0]:
            width = scipy.signal.peak_widths(curve, [k], rel_height=1 - 1 / np.sqrt(2))[0][0]
            zeta = np.clip(width * (f_hz[1] - f_hz[0]) / (2 * f_hz[k]), 0.005, 0.1)
            if all(abs(f_hz[k] / f - 1) > PEAK_MERGE for f, _ in found):
                found.append((f_hz[k], zeta))
    found.sort()
    return np.array([f for f, _ in found]), np.array([z for _, z in found])


def _poles(frequency_hz, zeta):
    w = 2 * np.pi * frequency_hz
    return -zeta * w + 1j * w * np.sqrt(1 - zeta**2)


def _basis(f_hz, poles, power):
    """(nf, 2m) complex: the FRF of a unit real and a unit imaginary residue of each mode, in the quantity of
    ``power`` ((i w)^power times receptance)."""
    iw = 2j * np.pi * f_hz[:, None]
    a, b = 1 / (iw - poles), 1 / (iw - np.conj(poles))
    return iw**power * np.concatenate([a + b, 1j * (a - b)], axis=1)


def scipy_modal_fit(f_hz, H, power=2):
    """Frequencies [Hz], damping ratios, shapes on the channels (n_out, m, complex) and the fit's counts: a
    ``least_squares`` fit of ``H`` (nf, n_out, n_ref) by m modes (m = the picked peaks), each FRF
    ``(i w)^power sum_i [R_i / (i w - l_i) + conj(R_i) / (i w - conj(l_i))]``, every output weighted by its
    RMS's inverse (as the identification does)."""
    nf, n_out, n_ref = H.shape
    weight = 1 / np.sqrt(np.mean(np.abs(H) ** 2, axis=(0, 2)))
    Hw = (H * weight[None, :, None]).reshape(nf, -1)  # (nf, n_frf)
    n_frf = Hw.shape[1]
    f0, zeta0 = picked_peaks(f_hz, H)
    m = len(f0)
    # Residues at the picked poles by linear least squares (the basis is shared by all FRFs).
    B = _basis(f_hz, _poles(f0, zeta0), power)
    coefficients = np.linalg.lstsq(np.vstack([B.real, B.imag]), np.vstack([Hw.real, Hw.imag]), rcond=None)[0]
    scale_f = f0.copy()  # frequencies fitted relative to their start, residues as they come
    x0 = np.concatenate([np.ones(m), zeta0, coefficients.ravel()])  # residues (2m, n_frf) row-major

    def unpack(x):
        return x[:m] * scale_f, x[m:2 * m], x[2 * m:].reshape(2 * m, n_frf)

    calls = [0]

    def residuals(x):
        calls[0] += 1
        frequency, zeta, c = unpack(x)
        error = _basis(f_hz, _poles(frequency, zeta), power) @ c - Hw
        return np.concatenate([error.real.ravel(), error.imag.ravel()])

    # Sparsity: frequency and damping reach every residual; the residues of one FRF only its own.
    n_res = 2 * nf * n_frf
    frf_of_residual = np.tile(np.arange(n_frf), 2 * nf)
    rows = [np.repeat(np.arange(n_res), 2 * m)]
    cols = [np.tile(np.arange(2 * m), n_res)]
    for r in range(2 * m):  # residue row r of FRF j is parameter 2m + r n_frf + j
        rows.append(np.arange(n_res))
        cols.append(2 * m + r * n_frf + frf_of_residual)
    rows, cols = np.concatenate(rows), np.concatenate(cols)
    sparsity = scipy.sparse.csr_matrix((np.ones(rows.size, dtype=np.int8), (rows, cols)), shape=(n_res, x0.size))
    low = np.concatenate([np.full(m, 0.5), np.full(m, 1e-4), np.full(2 * m * n_frf, -np.inf)])
    high = np.concatenate([np.full(m, 1.5), np.full(m, 0.5), np.full(2 * m * n_frf, np.inf)])
    fit = scipy.optimize.least_squares(residuals, x0, bounds=(low, high), jac_sparsity=sparsity,
                                       tr_solver="lsmr", x_scale="jac")
    frequency, zeta, c = unpack(fit.x)
    residues = (c[:m] + 1j * c[m:]).T.reshape(n_out, n_ref, m) / weight[:, None, None]
    # Each mode's shape: the first left singular vector of its residue matrix (rank one in exact data).
    shapes = np.stack([np.linalg.svd(residues[:, :, i])[0][:, 0] for i in range(m)], axis=1)
    order = np.argsort(frequency)
    return {"frequency_hz": frequency[order], "damping_ratio": zeta[order], "shapes": shapes[:, order],
            "start_hz": f0, "start_damping": zeta0, "unknowns": int(x0.size), "residuals": int(n_res),
            "nfev": int(fit.nfev), "njev": int(fit.njev), "status": int(fit.status), "model_evaluations": calls[0]}


# ----------------------------------------------------------------------------------------------------
# 2. Update: a plain scipy least-squares FRF updating of the same variables.
# ----------------------------------------------------------------------------------------------------


def scipy_frf_update(model, test):
    """The variables (n,) minimizing the FRF error on the channels up to UPDATE_BAND_HZ, by ``least_squares``
    from the given model with a finite-difference Jacobian, and the number of model FRFs it computed."""
    from sixdof.analysis.frf import receptance
    from sixdof.design.update import moved_rows

    inside = test.f_hz <= UPDATE_BAND_HZ
    f, H = test.f_hz[inside], test.H[inside]
    weight = 1 / np.sqrt(np.mean(np.abs(H) ** 2, axis=0))  # (n_out, n_ref): every FRF counts alike
    rows, cols = test.response_rows(), test.load_columns()
    bounds = model.bounds
    low, width = bounds[:, 0], bounds[:, 1] - bounds[:, 0]
    calls = [0]

    def residuals(u):
        calls[0] += 1
        system, offset = model.system_at(low + width * u)
        moved_r = np.asarray(moved_rows(rows, offset))
        moved_c = np.asarray(moved_rows(cols.T, offset)).T  # a force's moment arm from the moved CG likewise
        A = receptance(system, f).quantity(test.quantity)
        error = (np.einsum("oi,fij,jr->for", moved_r, A, moved_c) - H) * weight
        return np.concatenate([error.real.ravel(), error.imag.ravel()])

    fit = scipy.optimize.least_squares(residuals, (model.initial - low) / width, bounds=(0.0, 1.0))
    return {"x": low + width * fit.x, "model_frfs": calls[0], "nfev": int(fit.nfev), "njev": int(fit.njev),
            "status": int(fit.status), "lines": int(f.size)}


# ----------------------------------------------------------------------------------------------------
# Timing.
# ----------------------------------------------------------------------------------------------------


class JaxSpans:
    """JAX's tracing, lowering and XLA compilation seconds, summed while ``on``."""

    EVENTS = ("/jax/core/compile/jaxpr_trace_duration", "/jax/core/compile/jaxpr_to_mlir_module_duration",
              "/jax/core/compile/backend_compile_duration")

    def __init__(self):
        import jax.monitoring

        self.seconds, self.on = 0.0, False
        jax.monitoring.register_event_duration_secs_listener(self._event)

    def _event(self, event, duration, **_):
        if self.on and event in self.EVENTS:
            self.seconds += duration

    def timed(self, fn):
        """Wall seconds of ``fn()``, JAX's compile seconds within them, and its value."""
        self.seconds, self.on = 0.0, True
        start = time.perf_counter()
        try:
            value = fn()
        finally:
            self.on = False
        return time.perf_counter() - start, self.seconds, value


def counting_update():
    """``update`` with its optimizer's objective-and-gradient evaluations counted (a list, reset per call)."""
    import sixdof.design.update as module

    counts = []
    inner = module.bounded_minimize

    def bounded_minimize(value_and_grad, *args, **kwargs):
        def counted(u):
            counts[-1] += 1
            return value_and_grad(u)
        return inner(counted, *args, **kwargs)

    module.bounded_minimize = bounded_minimize

    def run(*args, **kwargs):
        counts.append(0)
        return module.update(*args, **kwargs)

    return run, counts


def deviations(x) -> dict:
    """The deviations the test was made with, from the variables: front_left w, rear v, CG offset [mm]."""
    return {"front_left_w": float(x[0]), "rear_v": float(x[5]), "cg_offset_mm": [float(1e3 * v) for v in x[7:]]}


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="time each once (update twice: its first call and a later one)")
    args, _ = parser.parse_known_args(argv)  # run_all hands every script its arguments
    repeat, slow_repeat = (1, 1) if args.quick else (5, 2)

    from sixdof.design.update import TestModes, UpdateModel
    from sixdof.io.testfile import load_test
    from sixdof.validation.identify import identify_modes
    from sixdof.validation.projection import project_to_body

    sc = scenario()
    test = load_test(TEST_FILE, sc)
    model = UpdateModel(sc.system, sc.update)
    truth = truth_modes(model, test)
    print(f"{TEST_FILE.name}: {test.n_outputs} channels x {test.n_references} references x {test.f_hz.size} lines "
          f"({test.quantity})")

    # 1. Identification.
    first = time.perf_counter()
    identification = identify_modes(test.f_hz, test.H, test.quantity)
    first = time.perf_counter() - first
    ident_s, ident_median_s, identification = common.best(
        lambda: identify_modes(test.f_hz, test.H, test.quantity), repeat)
    found = identification.modes
    ours = accuracy(found.frequency_hz, found.damping_ratio, found.shapes, truth)
    print(f"identify_modes: best {ident_s:.3f} s of {repeat} (first call {first:.3f} s), {ours['modes_found']} modes; "
          f"worst errors: frequency {ours['worst_frequency_error_percent']:.3f} %, damping "
          f"{ours['worst_damping_error_percent']:.2f} %, MAC {ours['worst_mac']:.4f}")
    fit_s, _, fit = common.best(lambda: scipy_modal_fit(test.f_hz, test.H), 1)  # ~50x ours: once tells it
    theirs = accuracy(fit["frequency_hz"], fit["damping_ratio"], fit["shapes"], truth)
    print(f"scipy least_squares modal fit: {fit_s:.2f} s, {fit['unknowns']} unknowns, {fit['nfev']} evaluations + "
          f"{fit['njev']} Jacobians, {fit['model_evaluations']} model evaluations in all; worst errors: frequency "
          f"{theirs['worst_frequency_error_percent']:.3f} %, damping {theirs['worst_damping_error_percent']:.2f} %, "
          f"MAC {theirs['worst_mac']:.4f} (peaks picked at {np.round(fit['start_hz'], 2).tolist()} Hz)")
    identified = {"sixdof": {"best_s": ident_s, "median_s": ident_median_s, "first_s": first, **ours},
                  "scipy": {"time_s": fit_s, **{k: v for k, v in fit.items()
                                                if k not in ("frequency_hz", "damping_ratio", "shapes")},
                            "start_hz": fit["start_hz"].tolist(), "start_damping": fit["start_damping"].tolist(),
                            **theirs}}

    # 2. Update, from the identified rigid-body modes (as `sixdof correlate --update` takes them).
    rows = test.response_rows()
    rigid = project_to_body(found.shapes, rows, test.out_nodes, test.out_positions).residual <= RIGID_RESIDUAL
    test_modes = TestModes(found.frequency_hz[rigid], found.shapes[:, rigid], rows, found.damping_ratio[rigid])
    spans = JaxSpans()
    run, counts = counting_update()
    calls = []
    for _ in range(2 if args.quick else 3):  # the first call, then later ones
        wall, compile_s, result = spans.timed(lambda: run(sc, test_modes))
        calls.append({"wall_s": wall, "jax_compile_s": compile_s, "evaluations": counts[-1],
                      "iterations": int(len(result.history_objective))})
    later = min(c["wall_s"] for c in calls[1:])
    later_compile = min(c["jax_compile_s"] for c in calls[1:])
    print(f"update: first call {calls[0]['wall_s']:.2f} s ({calls[0]['jax_compile_s']:.2f} s JAX tracing and "
          f"compiling), later calls best {later:.2f} s ({later_compile:.2f} s of it compiling again); "
          f"{calls[0]['evaluations']} objective+gradient evaluations over {result.start.size} starts and the polish; "
          f"{deviations(result.updated)}")
    plain_s, _, plain = common.best(lambda: scipy_frf_update(model, test), slow_repeat)
    print(f"scipy least_squares FRF update: best {plain_s:.2f} s of {slow_repeat}, {plain['model_frfs']} model FRFs "
          f"({plain['nfev']} evaluations + {plain['njev']} finite-difference Jacobians, {plain['lines']} lines); "
          f"{deviations(plain['x'])}")
    # As the command line runs it: JAX's persistent compilation cache on (a fresh folder), filled by one call.
    with tempfile.TemporaryDirectory() as folder:
        os.environ["SIXDOF_JAX_CACHE"] = folder
        from sixdof._jax import enable_compilation_cache, jax

        enable_compilation_cache()
        cached = [spans.timed(lambda: run(sc, test_modes))[:2] for _ in range(2)]
        jax.config.update("jax_compilation_cache_dir", None)  # before its folder goes
    print(f"update with the persistent compilation cache: filling it {cached[0][0]:.2f} s ({cached[0][1]:.2f} s "
          f"compiling), from it {cached[1][0]:.2f} s ({cached[1][1]:.2f} s tracing and reading)")
    print(f"truth: {deviations(TRUE_X)}")
    updated = {"sixdof": {"first": calls[0], "later": calls[1:], "later_best_s": later, "later_compile_s": later_compile,
                          "cached": {"filling_s": cached[0][0], "filling_compile_s": cached[0][1],
                                     "from_cache_s": cached[1][0], "from_cache_compile_s": cached[1][1]},
                          "x": result.updated.tolist(), "deviations": deviations(result.updated),
                          "standard_error": result.standard_error.tolist(),
                          "undetermined": list(result.undetermined), "starts": int(result.start.size),
                          "test_modes": int(rigid.sum())},
               "scipy": {"time_s": plain_s, **{k: v for k, v in plain.items() if k != "x"}, "x": plain["x"].tolist(),
                         "deviations": deviations(plain["x"]), "band_hz": [float(test.f_hz[0]), UPDATE_BAND_HZ]},
               "truth": deviations(TRUE_X), "variables": [v.name for v in model.variables]}
    path = common.save("correlate", {"quick": args.quick, "repeat": repeat, "scipy_repeat": slow_repeat, "identification": identified,
                                     "update": updated, "channels": test.n_outputs,
                                     "references": test.n_references, "lines": int(test.f_hz.size)})
    print(f"-> {path}")


if __name__ == "__main__":
    main(sys.argv[1:])

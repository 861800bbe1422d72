"""The bridge beam on four lead-rubber bearings under a 20 s record: sixdof against OpenSeesPy at equal accuracy
(issue 48, item 8).

The model: the seed's 83 t bridge beam (mass, inertia, bearing positions, vertical stiffness and vertical dashpots
read from scenarios/bridge_beam_ground.toml, the seed's bridge with the ground scenario's dashpots) on four
identical lead-rubber bearings, Bouc-Wen on u and v (uncoupled), elastic along w (see :func:`lrb`). The record:
one spectrum-compatible accelerogram (sixdof.analysis.matching, SIMQKE's method, seed 48) of the EN 1998-1 type 1
elastic spectrum on ground B, agR = 2.5 m/s^2, 20 s at 100 Hz, along the beam (y).

Accuracy is measured against an independent reference, scipy solve_ivp (DOP853, rtol 1e-11, piece by piece
between the record's samples; tests/hysteresis_references.py), checked against rtol 1e-12: the worst error over
the DOFs that move (those a symmetry leaves at rest are left out), each DOF relative to its own peak, as
bench_direct.py measures. Two comparisons: at ``--target`` (1e-3 by default), OpenSees' step halved from the record's 10 ms and sixdof's
tolerance loosened until each error is no larger, both timed (best of ``--repeat``); and at sixdof's default
accuracy, which OpenSees' first-order Bouc-Wen update puts out of reach of a measured run (its time there is
extrapolated from its finest step). OpenSees is also
timed at the step its own halving settles the peaks to the target (tests/opensees_models.time_opensees): the
usual way to pick a step without a reference.

Run: python benchmarks/bench_opensees.py [--direction y] [--target 1e-3] [--repeat 3]
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

import common

sys.path.insert(0, str(common.ROOT / "tests"))  # the reference helpers live beside the tests that check them

import hysteresis_references  # noqa: E402
import opensees_models  # noqa: E402

SCENARIO = common.ROOT / "scenarios" / "bridge_beam_ground.toml"
G = 9.80665  # m/s^2

# Lead-rubber bearings for the 83 t beam (W = 814 kN, 204 kN per bearing), identical, as a design would have them:
# - isolation period on the post-yield stiffness T_d = 2 pi sqrt(m / (4 kd)) = 2 s: kd = 205 kN/m per bearing;
# - characteristic strength Qd = 6 % of W in all (EN 1998-2 and AASHTO designs take 3-10 %): 12.2 kN each;
# - elastic stiffness ku = 10 kd (the usual ratio of lead-rubber bearings, Naeim & Kelly 1999, ch. 4): 2.05 MN/m,
#   so the post-yield ratio a = 0.1, Fy = Qd / (1 - a) = 13.6 kN and d_y = Fy / ku = 6.6 mm;
# - Wen's loop with n = 1, b = g = 0.5 (issue 48's defaults).
# At a 0.1 m design displacement: k_eff = kd + Qd / D = 0.33 MN/m, xi_eff = 4 Qd (D - d_y) / (2 pi k_eff D^2) = 0.22.
ISOLATION_PERIOD_S = 2.0
STRENGTH_SHARE = 0.06
ELASTIC_TO_POST_YIELD = 10.0
EXPONENT, BETA, GAMMA = 1.0, 0.5, 0.5

# The record: EN 1998-1 type 1, ground B, agR 2.5 m/s^2, 5 % elastic spectrum, matched at 60 periods 0.05-4 s.
SPECTRUM = dict(type=1, ground_type="B", ag=2.5)
DURATION_S, RECORD_DT = 20.0, 0.01
SEED = 48


def lrb(mass):
    """(ku [N/m], Fy [N], a) of each of the four bearings from the beam's mass [kg], as the comment above derives."""
    kd = mass * (2 * np.pi / ISOLATION_PERIOD_S) ** 2 / 4
    ku = ELASTIC_TO_POST_YIELD * kd
    alpha = 1.0 / ELASTIC_TO_POST_YIELD
    qd = STRENGTH_SHARE * mass * G / 4
    return ku, qd / (1.0 - alpha), alpha


def bridge_model() -> dict:
    """The benchmark's body and bearings, keyword arguments of opensees_models.rigid_body_on_bearings."""
    from sixdof import load_scenario

    system = load_scenario(SCENARIO).system
    ku, fy, alpha = lrb(system.body.mass)
    mounts = system.mounts
    return dict(
        mass=system.body.mass,
        inertia=np.asarray(system.body.inertia),
        positions=np.array([m.position for m in mounts]),
        stiffness=np.array([[ku, ku, m.stiffness[2]] for m in mounts]),
        damping=np.array([[0.0, 0.0, m.damping[2]] for m in mounts]),  # the bearings' lead damps u and v
        hysteresis=[{"u": (fy, alpha, EXPONENT, BETA, GAMMA), "v": (fy, alpha, EXPONENT, BETA, GAMMA)}] * len(mounts),
    )


def record():
    """(t (n,) [s], ground acceleration (n,) [m/s^2]): one spectrum-compatible accelerogram."""
    from sixdof.analysis.matching import spectrum_compatible_records
    from sixdof.excitation.spectra import EC8Spectrum

    spectrum = EC8Spectrum(**SPECTRUM)
    periods = np.geomspace(0.05, 4.0, 60)
    records = spectrum_compatible_records(periods, spectrum.horizontal(periods), 1, seed=SEED, duration=DURATION_S,
                                          dt=RECORD_DT)
    return records.t, records.acceleration[0]


def sixdof_system(model: dict):
    """The sixdof System of ``model``: the same body and bearings, Bouc-Wen on u and v of each (uncoupled, as the
    OpenSees model's two BoucWen materials), no Rayleigh damping."""
    from sixdof import Mount, RigidBody, System
    from sixdof.model.hysteresis import BoucWen

    body = RigidBody(mass=model["mass"], inertia=np.asarray(model["inertia"]))
    mounts = [Mount(name=f"{j + 1}", position=p, stiffness=k, damping=c)
              for j, (p, k, c) in enumerate(zip(model["positions"], model["stiffness"], model["damping"]))]
    laws = []
    for mount, axes in zip(mounts, model["hysteresis"]):
        for axis, (fy, alpha, n, beta, gamma) in axes.items():
            laws.append(BoucWen(mount=mount.name, axes=[axis], yield_force=[fy], post_yield_ratio=alpha, exponent=n,
                                beta=beta, gamma=gamma))
    return System(body=body, mounts=mounts, bouc_wen=laws)


def sixdof_side(model: dict, t, ground_acc, direction: str, repeat: int, tolerance: float = 1e-9):
    """sixdof's solve of the same bridge and record (Tsit5, ``rtol = atol = tolerance`` on the state scale, default
    sixdof's own), samples at ``t``, timed as bench_direct.py does: compiled first (a run of the same structure),
    best of ``repeat``.

    Returns
    -------
    q : ndarray, shape (t, 6)
        CG displacement relative to the ground at ``t`` [m, rad].
    wall_s : float
        Best wall time of the solve [s].
    settings : str
        What was run (solver, tolerances, steps).
    """
    from sixdof.analysis.direct import SimulationSettings, simulate
    from sixdof.excitation import Excitation, GroundMotion
    from sixdof.excitation.signals import Table

    system = sixdof_system(model)
    vector = {"x": [1.0, 0.0, 0.0], "y": [0.0, 1.0, 0.0]}[direction]
    excitation = Excitation(ground=GroundMotion(quantity="acceleration", direction=vector,
                                                signal=Table(t=t, values=ground_acc)))
    dt = float(t[1] - t[0])
    settings = SimulationSettings(duration=float(t[-1] - t[0]) + dt, sample_rate_hz=1.0 / dt, start=float(t[0]),
                                  rtol=tolerance, atol=tolerance)
    history = simulate(system, excitation, settings)  # compiles
    wall = best_of(lambda: simulate(system, excitation, settings), repeat)
    q = history.q_relative[: t.size]
    stats = history.stats
    return q, wall, f"{stats.solver}, rtol {stats.rtol:g}, atol {stats.atol:g}, {stats.num_accepted} steps"


def opensees_at(model, t, ag, direction, target, length, q_ref, max_halvings=6):
    """Halve OpenSees' step from the record's until its worst error against ``q_ref`` is <= ``target``, at most
    ``max_halvings`` times.

    Returns the substeps per sample reached (None if the target was not) and ((dt, error, wall_s), ...) of every
    try.
    """
    substeps, tries = 1, []
    for _ in range(max_halvings + 1):
        start = time.perf_counter()
        history = opensees_models.rigid_body_on_bearings(**model, t=t, ground_acc=ag, direction=direction,
                                                         substeps=substeps)
        wall = time.perf_counter() - start
        error = opensees_models.worst_error(history.q, q_ref, length)
        tries.append((history.dt, error, wall))
        print(f"  OpenSees dt = {history.dt * 1e3:.4g} ms: worst per-DOF error {error:.3g}, {wall:.2f} s", flush=True)
        if error <= target:
            return substeps, tries
        substeps *= 2
    return None, tries


def extrapolated_wall(tries, target) -> float:
    """OpenSees' wall time [s] at ``target`` from its finest try, by its measured first order (error and time both
    go as dt: wall x error / target)."""
    dt, error, wall = tries[-1]
    return wall * error / target


def best_of(fn, repeat):
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return min(times)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--direction", default="y", choices=["x", "y"])
    parser.add_argument("--target", type=float, default=1e-3,
                        help="the accuracy OpenSees is held to when sixdof's side is not there")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args(argv)

    model = bridge_model()
    ku, fy, alpha = lrb(model["mass"])
    print(f"Lead-rubber bearings: ku = {ku / 1e6:.3g} MN/m, Fy = {fy / 1e3:.3g} kN (d_y = {fy / ku * 1e3:.2f} mm), "
          f"a = {alpha:g}, n = {EXPONENT:g}, b = {BETA:g}, g = {GAMMA:g}")
    t, ag = record()
    print(f"Record: {t[-1]:g} s at {1 / RECORD_DT:g} Hz, peak {np.max(np.abs(ag)):.3g} m/s^2 along {args.direction}")
    length = float(np.max(np.abs(model["positions"])))

    start = time.perf_counter()
    ref = hysteresis_references.rigid_body_ivp(**model, t=t, ground_acc=ag, direction=args.direction)
    ref_s = time.perf_counter() - start
    tighter = hysteresis_references.rigid_body_ivp(**model, t=t, ground_acc=ag, direction=args.direction, rtol=1e-12)
    ref_error = opensees_models.worst_error(ref.q, tighter.q, length)
    moving = opensees_models.moving_dofs(tighter.q, length)
    peaks = np.max(np.abs(tighter.q), axis=0)
    ductility = np.nanmax(np.abs(tighter.deflection[:, :, :2])) / (fy / ku)
    print(f"Reference (solve_ivp DOP853 rtol 1e-11, {ref.nfev} evaluations, {ref_s:.1f} s): {ref_error:.2g} from "
          f"rtol 1e-12; moving DOFs {[d for d, m in zip('x y z rx ry rz'.split(), moving) if m]}, peaks "
          f"{np.array2string(peaks[moving], precision=3)}; bearing ductility {ductility:.1f}")

    result = dict(model={k: np.asarray(v).tolist() for k, v in model.items() if k != "hysteresis"},
                  bearing=dict(ku=ku, fy=fy, alpha=alpha, n=EXPONENT, beta=BETA, gamma=GAMMA),
                  record=dict(spectrum=SPECTRUM, seed=SEED, duration=DURATION_S, dt=RECORD_DT,
                              direction=args.direction, peak=float(np.max(np.abs(ag)))),
                  reference=dict(seconds=ref_s, nfev=ref.nfev, error=ref_error, peaks=peaks.tolist(),
                                 ductility=float(ductility)))
    q_sixdof, sixdof_s, settings = sixdof_side(model, t, ag, args.direction, args.repeat)
    sixdof_error = opensees_models.worst_error(q_sixdof, tighter.q, length)
    result["sixdof"] = dict(seconds=sixdof_s, error=sixdof_error, settings=settings)
    print(f"sixdof at its defaults ({settings}): worst per-DOF error {sixdof_error:.3g}, {sixdof_s:.3g} s")

    # 1. At the accuracy OpenSees reaches in practice (--target): both measured; sixdof's tolerance loosened until
    # its error is no larger.
    print(f"At worst error <= {args.target:g}:")
    substeps, tries = opensees_at(model, t, ag, args.direction, args.target, length, tighter.q)
    if substeps is None:
        raise RuntimeError(f"OpenSees did not reach {args.target:g} by dt = {tries[-1][0]:g} s")
    opensees_s = best_of(lambda: opensees_models.rigid_body_on_bearings(
        **model, t=t, ground_acc=ag, direction=args.direction, substeps=substeps), args.repeat)
    dt = RECORD_DT / substeps
    for tolerance in (1e-4, 1e-5, 1e-6, 1e-7, 1e-8):
        q_loose, loose_s, loose = sixdof_side(model, t, ag, args.direction, args.repeat, tolerance)
        loose_error = opensees_models.worst_error(q_loose, tighter.q, length)
        print(f"  sixdof rtol = atol = {tolerance:g} ({loose}): worst per-DOF error {loose_error:.3g}, {loose_s:.3g} s")
        if loose_error <= args.target:
            break
    print(f"  OpenSees dt = {dt * 1e3:.4g} ms ({round(DURATION_S / dt)} steps): {opensees_s:.3g} s (best of "
          f"{args.repeat}); sixdof {loose_s:.3g} s: sixdof {opensees_s / loose_s:.3g}x faster")
    result["at_target"] = dict(target=args.target, opensees=dict(dt=dt, seconds=opensees_s, error=tries[-1][1],
                                                                  tries=tries, version=_opensees_version()),
                               sixdof=dict(tolerance=tolerance, seconds=loose_s, error=loose_error),
                               speedup=opensees_s / loose_s)

    # 2. At sixdof's own accuracy: OpenSees' first-order error puts it out of reach of a measured run; its time is
    # extrapolated from its finest step.
    extrapolated = extrapolated_wall(tries, sixdof_error)
    print(f"At sixdof's default accuracy ({sixdof_error:.2g}): OpenSees would need dt = "
          f"{tries[-1][0] * sixdof_error / tries[-1][1] * 1e3:.3g} ms, ~{extrapolated:.3g} s (extrapolated, first "
          f"order): sixdof ~{extrapolated / sixdof_s:.3g}x faster")
    result["at_sixdof_accuracy"] = dict(error=sixdof_error, sixdof_seconds=sixdof_s,
                                        opensees_extrapolated_seconds=extrapolated, speedup=extrapolated / sixdof_s)

    timing = opensees_models.time_opensees(**model, t=t, ground_acc=ag, direction=args.direction, rtol=args.target)
    settled_error = opensees_models.worst_error(timing.history.q, tighter.q, length)
    print(f"OpenSees, step halved until the peaks change by < {args.target:.3g}: dt = {timing.dt * 1e3:.4g} ms, "
          f"{timing.wall_s:.3g} s; its error against the reference {settled_error:.3g}")
    result["opensees_self_converged"] = dict(dt=timing.dt, seconds=timing.wall_s, change=timing.change,
                                             error=settled_error,
                                             tries=[[dt_, s_, None if np.isnan(c) else c] for dt_, s_, c in timing.tries])
    print(f"wrote {common.save('opensees', result)}")
    return 0


def _opensees_version() -> str:
    from importlib.metadata import version

    return version("openseespy")


if __name__ == "__main__":
    raise SystemExit(main())

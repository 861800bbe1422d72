"""Visco-elastic mounts (Maxwell branches) against independent answers: the standard linear solid in closed
form, the exact matrix exponential of an augmented state-space system built here, and the frequency domain."""

import dataclasses
import json

import numpy as np
import pytest
import scipy.linalg
import scipy.signal

from sixdof import Maxwell, Mount, RigidBody, System
from sixdof.analysis.batch import make_variants, run_batch, variant_system
from sixdof.analysis.direct import SimulationSettings, simulate
from sixdof.analysis.frf import cross_check, receptance
from sixdof.analysis.response import mount_forces
from sixdof.analysis.statespace import damped_modes, damping_ratios
from sixdof.analysis.superposition import superpose
from sixdof.cli import main
from sixdof.errors import InputError, ScenarioError
from sixdof.excitation import Excitation, GroundMotion, InitialState, Load
from sixdof.excitation.signals import HalfSine, Step
from sixdof.io.scenario import load_scenario, parse_scenario
from sixdof.io.store import load_results, write_results
from sixdof.results import RunResults
from sixdof.workflows.prepare import prepare
from systems import FOUR_MOUNT_CORNERS, THREE_MOUNTS, skewed_machine
from tolerances import (
    RTOL_BATCH_CHUNKS,
    RTOL_BATCH_DIRECT,
    RTOL_DIRECT_EXACT,
    RTOL_FRF_CLOSED_FORM,
    RTOL_FRF_METHODS,
    RTOL_MODAL_DIRECT,
    RTOL_MODAL_EXACT,
)

# The standard linear solid: a body of mass M on four mounts at the corners, each a spring K/4 in parallel
# with a Maxwell branch KB/4 of relaxation time TAU along z; vertical motion decouples by symmetry.
M, K, KB, TAU = 200.0, 8.0e5, 4.0e5, 0.004


def solid(c=0.0) -> System:
    mounts = [Mount(f"m{i}", [0.3 * sx, 0.4 * sy, -0.2], [2e5, 2e5, K / 4], damping=[0.0, 0.0, c])
              for i, (sx, sy) in enumerate(FOUR_MOUNT_CORNERS)]
    branches = [Maxwell(f"b{i}", f"m{i}", [0.0, 0.0, KB / 4], TAU) for i in range(4)]
    return System(RigidBody(M, [10.0, 8.0, 14.0]), mounts, maxwell=branches)


def test_receptance_is_the_standard_linear_solid():
    f = np.geomspace(0.5, 200.0, 400)
    s = 2j * np.pi * f
    closed = 1.0 / (M * s**2 + K + KB * TAU * s / (1 + TAU * s))
    for method in ("direct", "modal"):
        H = receptance(solid(), f, method=method).H[:, 2, 2]
        np.testing.assert_allclose(H, closed, rtol=RTOL_FRF_CLOSED_FORM)


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_step_response_and_relaxation_of_the_standard_linear_solid():
    force = 1.0e3
    excitation = Excitation(loads=[Load("step", [0.0, 0.0, 0.0], force=[0.0, 0.0, force], signal=Step(start=0.0))])
    settings = SimulationSettings(duration=0.5, sample_rate_hz=10_000.0)
    direct = simulate(solid(), excitation, settings)
    modal = superpose(solid(), excitation, direct.t)
    # X(s) = F / (s (M s^2 + K + KB tau s / (1 + tau s))): partial fractions over the cubic's roots.
    numerator, denominator = np.array([TAU, 1.0]), np.polymul([1.0, 0.0], [M * TAU, M, (K + KB) * TAU, K])
    residues, poles, _ = scipy.signal.residue(force * numerator, denominator)
    z = np.real(np.exp(np.outer(direct.t, poles)) @ residues)
    h = direct.t[1] - direct.t[0]
    decay = np.exp(-h / TAU)
    for history in (direct, modal):
        assert np.max(np.abs(history.q[:, 2] - z)) <= RTOL_DIRECT_EXACT * np.max(np.abs(z))
        # Relaxation: each branch's force is KB/4 times the deformation rate convolved with e^{-t/tau}
        # (trapezoid rule on the samples, error ~(h / tau)^2 / 12 = 5e-5).
        rate, convolved = history.qd[:, 2], np.zeros(history.t.size)
        for k in range(1, history.t.size):
            convolved[k] = decay * convolved[k - 1] + (KB / 4) * h / 2 * (decay * rate[k - 1] + rate[k])
        branch = history.maxwell_force[:, 0]
        assert np.max(np.abs(branch - convolved)) <= 2e-4 * np.max(np.abs(branch))


def augmented(system: System):
    """``x' = A x`` for ``x = [q, q', f]``, every branch row built here from its mount's position and axes."""
    Mm, C, Kk = (np.asarray(a) for a in (system.M, system.C, system.K))
    mounts = {m.name: m for m in system.mounts}
    rows, k, tau = [], [], []
    for branch in system.maxwell:
        mount = mounts[branch.mount]
        p = mount.position
        skew = np.array([[0.0, -p[2], p[1]], [p[2], 0.0, -p[0]], [-p[1], p[0], 0.0]])
        for a in np.flatnonzero(branch.stiffness):
            rows.append(mount.axes[a] @ np.hstack([np.eye(3), -skew]))
            k.append(branch.stiffness[a])
            tau.append(branch.tau)
    R, k, tau = np.array(rows), np.array(k), np.array(tau)
    Minv = np.linalg.inv(Mm)
    nb = k.size
    return np.block([[np.zeros((6, 6)), np.eye(6), np.zeros((6, nb))],
                     [-Minv @ Kk, -Minv @ C, -Minv @ R.T],
                     [np.zeros((nb, 6)), k[:, None] * R, -np.diag(1.0 / tau)]])


def visco_machine() -> System:
    """The skewed machine (inclined mounts, dashpots, full inertia tensor) with branches on three mounts."""
    system = skewed_machine()
    branches = [Maxwell("m1 fast", "m1", [2e4, 1e4, 9e4], 0.002), Maxwell("m1 slow", "m1", [0.0, 0.0, 6e4], 0.05),
                Maxwell("m2", "m2", [3e4, 0.0, 5e4], 0.01), Maxwell("m4", "m4", [1e4, 2e4, 1e5], 0.003)]
    return dataclasses.replace(system, maxwell=tuple(branches))


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_free_response_matches_the_exact_matrix_exponential():
    system = visco_machine()
    q0, qd0 = np.array([1e-3, -5e-4, 2e-3, 1e-3, -2e-3, 5e-4]), np.array([0.01, 0.0, -0.02, 0.0, 0.03, 0.01])
    excitation = Excitation(initial=InitialState(q=q0, qd=qd0))
    direct = simulate(system, excitation, SimulationSettings(duration=1.0, sample_rate_hz=1000.0))
    modal = superpose(system, excitation, direct.t)
    A = augmented(system)
    x0 = np.concatenate([q0, qd0, np.zeros(A.shape[0] - 12)])  # the branches start relaxed
    exact = np.stack([scipy.linalg.expm(A * t) @ x0 for t in direct.t])
    for history, rtol in ((direct, RTOL_DIRECT_EXACT), (modal, RTOL_MODAL_EXACT)):
        for name, columns in (("q", slice(0, 6)), ("qd", slice(6, 12)), ("maxwell_force", slice(12, None))):
            reference = exact[:, columns]
            error = np.max(np.abs(getattr(history, name) - reference), axis=0) / np.max(np.abs(reference), axis=0)
            assert np.all(error <= rtol), (name, error)
    assert modal.superposition.method == "complex" and "Maxwell" in modal.superposition.reason


@pytest.mark.slow  # 2 s each on the 2-core machine
@pytest.mark.parametrize("quantity", ["displacement", "velocity", "acceleration"])
def test_direct_and_superposition_agree_under_loads_and_ground_motion(quantity):
    system = visco_machine()
    scale = 1e-3 if quantity == "displacement" else 1.0
    excitation = Excitation(
        loads=[Load("shock", [0.2, 0.1, 0.3], force=[200.0, 0.0, 800.0], signal=HalfSine(start=0.05, duration=0.01))],
        ground=GroundMotion(quantity, [0.3, 0.2, 1.0], HalfSine(start=0.1, duration=0.04), scale=scale))
    direct = simulate(system, excitation, SimulationSettings(duration=1.0, sample_rate_hz=1000.0))
    modal = superpose(system, excitation, direct.t)
    for name in ("q", "qd", "maxwell_force"):
        a, b = getattr(direct, name), getattr(modal, name)
        error = np.max(np.abs(a - b), axis=0) / np.max(np.abs(a), axis=0)
        assert np.all(error <= RTOL_MODAL_DIRECT), (name, error)


def test_mount_forces_carry_the_branch_forces():
    system = solid()
    excitation = Excitation(initial=InitialState(q=[0.0, 0.0, 1e-3, 0.0, 0.0, 0.0], qd=[0.0, 0.0, 0.05, 0, 0, 0]))
    history = simulate(system, excitation, SimulationSettings(duration=0.2, sample_rate_hz=1000.0))
    forces = mount_forces(system, history)
    spring = (K / 4) * forces.deformation[0, :, 2]  # the mount's axes are the body's: w is z
    np.testing.assert_allclose(forces.local[0, :, 2], spring + history.maxwell_force[:, 0], rtol=1e-12, atol=1e-9)
    assert np.max(np.abs(history.maxwell_force[:, 0])) > 0.1 * np.max(np.abs(spring))


def test_frf_methods_and_poles_of_the_full_model():
    system = visco_machine()
    check = cross_check(system, np.linspace(0.5, 60.0, 600))
    assert check.max_relative_difference <= RTOL_FRF_METHODS and check.modal.basis == "complex modes"
    eigenvalues = np.linalg.eigvals(augmented(system))
    poles, _ = damped_modes(system.C, system.modes, system.branches)
    for pole in poles:
        assert np.min(np.abs(eigenvalues - pole)) <= 1e-9 * abs(pole)
    zeta = damping_ratios(system.C, system.modes, system.branches)
    np.testing.assert_allclose(zeta, -poles.real / np.abs(poles), rtol=1e-12)
    assert np.all(zeta > damping_ratios(system.C, system.modes))  # the branches dissipate in every mode


def test_modes_json_gives_the_poles_of_the_full_model(capsys):
    """``modes --json`` carries what its table shows: each mode's pole in the full visco-elastic model, an
    eigenvalue of the augmented state space built here; null without Maxwell branches."""
    scenario = "scenarios/equipment_elastomer.toml"
    assert main(["modes", scenario, "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    poles = data["full_model_poles"]
    f, fd, zeta = (np.array(poles[key]) for key in ("frequency_hz", "damped_frequency_hz", "damping_ratio"))
    assert f.shape == (6,) and np.all(f > np.array(data["frequency_hz"]))  # the branches stiffen every mode
    np.testing.assert_allclose(zeta, data["damping_ratio"], rtol=1e-12)
    np.testing.assert_allclose(fd, f * np.sqrt(1 - zeta**2), rtol=1e-12)
    eigenvalues = np.linalg.eigvals(augmented(prepare(load_scenario(scenario)).system))
    for pole in 2 * np.pi * (-zeta * f + 1j * fd):
        assert np.min(np.abs(eigenvalues - pole)) <= 1e-9 * abs(pole)
    assert main(["modes", scenario]) == 0
    rows = [row.split("|") for row in capsys.readouterr().out.split("\n\n")[1].splitlines()  # the modes table
            if row.startswith("|")]
    assert rows[0][6].strip() == "f full model [Hz]"
    shown = [float(row[6]) for row in rows[2:]]
    assert shown == [round(v, 4) for v in f]  # the table's "f full model [Hz]"
    assert main(["modes", "scenarios/bridge_beam.toml", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["full_model_poles"] is None


def test_store_round_trip(tmp_path):
    system = visco_machine()
    write_results(tmp_path / "r.h5", RunResults(system=system))
    loaded = load_results(tmp_path / "r.h5").system
    assert [(b.name, b.mount, b.tau) for b in loaded.maxwell] == [(b.name, b.mount, b.tau) for b in system.maxwell]
    np.testing.assert_array_equal(np.stack([b.stiffness for b in loaded.maxwell]),
                                  np.stack([b.stiffness for b in system.maxwell]))


def scaled_by_hand(system: System, stiffness_factor, position_offset) -> System:
    """``system`` with each mount's stiffness times its factors (3,) along its axes, moved by its offset, and each
    Maxwell branch's stiffness times its mount's factors: a variant built here, apart from the batch code."""
    factor = dict(zip(system.mount_names, stiffness_factor))
    offset = dict(zip(system.mount_names, position_offset))
    mounts = [dataclasses.replace(m, stiffness=m.stiffness * factor[m.name], position=m.position + offset[m.name])
              for m in system.mounts]
    branches = [dataclasses.replace(b, stiffness=b.stiffness * factor[b.mount]) for b in system.maxwell]
    return dataclasses.replace(system, mounts=tuple(mounts), maxwell=tuple(branches))


@pytest.fixture(scope="module")
def visco_variants():
    system = visco_machine()
    rng = np.random.default_rng(3)
    n = len(system.mounts)
    return system, make_variants(system, stiffness_factor=rng.uniform(0.6, 1.5, (3, n, 3)),
                                 position_offset=rng.normal(0.0, 0.03, (3, n, 3)))


@pytest.mark.long  # over 10 s on the 2-core machine
@pytest.mark.parametrize("engine", ["exact", "diffrax"])
def test_a_batch_of_visco_elastic_variants_is_the_exact_matrix_exponential_of_each(visco_variants, engine):
    # A free response: each variant's branches scaled with its mount axes' stiffness factors and moved with its
    # mounts (built here), its peaks from expm of the augmented state matrix built here.
    system, variants = visco_variants
    q0, qd0 = np.array([1e-3, -5e-4, 2e-3, 1e-3, -2e-3, 5e-4]), np.array([0.01, 0.0, -0.02, 0.0, 0.03, 0.01])
    excitation = Excitation(initial=InitialState(q=q0, qd=qd0))
    settings = SimulationSettings(duration=0.5, sample_rate_hz=1000.0)
    batches = [run_batch(system, variants, excitation, settings, engine=engine, chunk_size=size, cross_check=0)
               for size in (3, 2)]
    tolerance = RTOL_MODAL_EXACT if engine == "exact" else RTOL_DIRECT_EXACT
    for i in range(3):
        one = scaled_by_hand(system, variants.stiffness_factor[i], variants.position_offset[i])
        A = augmented(one)
        x0 = np.concatenate([q0, qd0, np.zeros(A.shape[0] - 12)])
        x = np.stack([scipy.linalg.expm(A * t) @ x0 for t in settings.times])
        expected = {"peak_q": np.max(np.abs(x[:, :6]), axis=0), "peak_qdd": np.max(np.abs(x @ A[6:12].T), axis=0)}
        for batch in batches:
            for name, peak in expected.items():
                error = np.abs(getattr(batch, name)[i] - peak) / peak
                assert np.all(error <= tolerance), (i, name, error)
    # Chunks change nothing (the exact engine: its arithmetic per variant; diffrax: the same solve vmapped).
    np.testing.assert_allclose(batches[0].peak_q, batches[1].peak_q, rtol=RTOL_BATCH_CHUNKS)
    # Each variant is another system: the comparison would be weak if they all answered alike (|q| peaks at the
    # start in some DOFs; |q''| moves with every variant's stiffness).
    assert np.all(np.ptp(batches[0].peak_qdd, axis=0) > 1e-3 * np.max(batches[0].peak_qdd, axis=0))


def test_variant_system_keeps_the_branches_scaled_and_moved(visco_variants):
    system, variants = visco_variants
    one = variant_system(system, variants, 1)
    by_hand = scaled_by_hand(system, variants.stiffness_factor[1], variants.position_offset[1])
    assert [b.name for b in one.maxwell] == [b.name for b in system.maxwell]
    for a, b in zip(one.maxwell, by_hand.maxwell):
        np.testing.assert_array_equal(a.stiffness, b.stiffness)
        assert a.tau == b.tau and a.mount == b.mount
    np.testing.assert_allclose(one.branches.rows, by_hand.branches.rows, rtol=0, atol=1e-15)
    np.testing.assert_allclose(augmented(one), augmented(by_hand), rtol=1e-14, atol=0)


@pytest.mark.long  # over 10 s on the 2-core machine
@pytest.mark.parametrize("engine", ["exact", "diffrax"])
def test_a_visco_elastic_batch_under_loads_equals_each_variant_alone(visco_variants, engine):
    # Loads, and ground motion (the exact engine: the ground's velocity drives each variant's own branches),
    # against superpose (exact) and simulate (diffrax) of each variant's own system; the cross-check
    # (simulate) agrees.
    system, variants = visco_variants
    ground = None if engine == "diffrax" else GroundMotion("velocity", [0.3, 0.2, 1.0],
                                                           HalfSine(start=0.1, duration=0.04), scale=0.2)
    excitation = Excitation(loads=[Load("shock", [0.2, 0.1, 0.3], force=[200.0, 0.0, 800.0],
                                        signal=HalfSine(start=0.05, duration=0.01))], ground=ground)
    settings = SimulationSettings(duration=0.5, sample_rate_hz=1000.0)
    batch = run_batch(system, variants, excitation, settings, engine=engine, chunk_size=2, histories=(1,))
    for i in range(3):
        one = variant_system(system, variants, i)
        alone = superpose(one, excitation, settings.times) if engine == "exact" else simulate(one, excitation, settings)
        tolerance = RTOL_BATCH_CHUNKS if engine == "exact" else RTOL_BATCH_DIRECT
        for name, peak in (("q", "peak_q"), ("qdd", "peak_qdd")):
            expected = np.max(np.abs(getattr(alone, name)), axis=0)
            error = np.abs(getattr(batch, peak)[i] - expected) / expected
            assert np.all(error <= tolerance), (i, name, error)
    assert batch.histories[1].maxwell_force.shape == (settings.times.size, system.branches.count)
    assert batch.cross_check.ok and batch.cross_check.worst < RTOL_BATCH_DIRECT


@pytest.mark.parametrize(("branch", "match"), [
    (dict(stiffness=[0.0, 0.0, -1.0], tau=0.01), r"^stiffness: expected 3 values >= 0 in N/m, not all zero, got \[0.0, 0.0, -1.0\]"),
    (dict(stiffness=[0.0, 0.0, 1e4], tau=0.0), r"^tau: expected a relaxation time in s > 0, got 0.0"),
    (dict(stiffness=[0.0, 0.0, 1e4], tau=0.01, mount="x"), r"maxwell\[0\]\.mount: expected the name of a mount"),
])
def test_bad_branches_are_refused(branch, match):
    mounts = [Mount(name, p, k) for name, p, k in THREE_MOUNTS]
    with pytest.raises(InputError, match=match):
        System(RigidBody(100.0, [4.0, 5.0, 6.0]), mounts, maxwell=[Maxwell(**({"name": "b", "mount": "a"} | branch))])


BASE = """name = "v"
[body]
mass = 100.0
inertia = [4.0, 5.0, 6.0]
[[mounts]]
name = "a"
position = [0.4, 0.3, -0.2]
stiffness = [2e5, 3e5, 8e5]
loss_factor = [0.1, 0.1, 0.0]
{extra}
[[mounts]]
name = "b"
position = [-0.5, 0.35, -0.25]
stiffness = [1e5, 1e5, 6e5]
[[mounts]]
name = "c"
position = [0.1, -0.45, -0.3]
stiffness = [3e5, 2e5, 9e5]
{damping}
"""


def scenario(tmp_path, extra="", damping="", rows=None):
    """The scenario, read and prepared (its fits made): what a run starts from."""
    if rows is not None:
        (tmp_path / "k.csv").write_text("f, K', eta\n" + "\n".join(rows) + "\n")
    return prepare(parse_scenario(BASE.format(extra=extra, damping=damping), source="v.toml", base_dir=tmp_path))


def measured(f_hz):
    """A three-branch elastomer: K' and loss factor rows."""
    k = 6e5 + sum(kb * 1j * 2 * np.pi * f_hz * t / (1 + 1j * 2 * np.pi * f_hz * t)
                  for kb, t in ((1e5, 0.03), (2e5, 0.003), (1e5, 0.0004)))
    return [f"{f:.8g}, {v.real:.10g}, {v.imag / v.real:.10g}" for f, v in zip(f_hz, k)]


def test_scenario_branches_fits_and_causal_loss_factors(tmp_path):
    extra = '[[mounts.maxwell]]\nstiffness = [1e4, 0.0, 5e4]\ntau = 0.01'
    sc = scenario(tmp_path, extra + '\n[mounts.dynamic_stiffness]\nfile = "k.csv"\naxis = "w"\nterms = 9',
                  '[damping]\nloss_factor_model = "maxwell"\nloss_factor_band_hz = [5.0, 80.0]',
                  rows=measured(np.geomspace(1.0, 500.0, 30)))
    system = sc.system
    assert not np.any(system.loss_factors) and [f.name for f in sc.viscoelastic] == ["a w", "a u", "a v"]
    fit = sc.viscoelastic[0]
    assert fit.modulus_error < 0.01 and fit.source == "k.csv"
    assert system.mounts[0].stiffness[2] == fit.long_term  # the fit's long-term stiffness replaces the given one
    # The converted loss factors keep the frequency domain close to the hysteretic model over the band.
    hysteretic = sc.viscoelastic[1]  # checked at the natural frequencies, within the band given
    assert 5.0 <= hysteretic.f_hz[0] and hysteretic.f_hz[-1] <= 80.0 and hysteretic.f_hz.size == 6
    assert hysteretic.modulus_error <= 0.05 and hysteretic.loss_factor_error <= 0.10


def test_a_loss_factor_band_must_cover_the_operating_frequencies(tmp_path):
    loads = "".join(f'[[loads]]\nname = "{n}"\npoint = [0.1, 0.0, 0.0]\nforce = [0.0, 0.0, 50.0]\n'
                    f'signal = {{ kind = "harmonic", f_hz = {f} }}\n' for n, f in (("in", 40.0), ("out", 120.0)))
    with pytest.raises(ScenarioError, match=r"damping\.loss_factor_band_hz: expected a band covering every natural and operating "
                       r"frequency \(10\.9-120 Hz\).*got \[5, 80\] Hz, without 120 Hz"):
        scenario(tmp_path, damping='[damping]\nloss_factor_model = "maxwell"\nloss_factor_band_hz = [5.0, 80.0]\n'
                 + loads)


@pytest.mark.parametrize(("extra", "damping", "match"), [
    ('[[mounts.maxwell]]\nstiffness = [0.0, 0.0, 1e4]\ntau = 0.01\nc = 3', "", r"mounts\[0\]\.maxwell\[0\]\.c: "),
    ('[[mounts.maxwell]]\nstiffness = [0.0, 0.0, 1e4]\ntau = -1', "", r"mounts\[0\]\.maxwell\[0\]\.tau: expected"),
    ('dynamic_stiffness = { file = "k.csv", axis = "u" }', "",
     r"mounts\[0\]\.dynamic_stiffness\.axis: expected an axis without a loss_factor"),
    ('dynamic_stiffness = { file = "k.csv", axis = "w", terms = 2 }', "",
     r"mounts\[0\]\.dynamic_stiffness: expected a Maxwell fit within 5 % in \|K\*\| and 1 deg in loss angle.*got "
     r"[0-9.]+ % and [0-9.]+ deg with 2 terms over 1-500 Hz of k.csv"),
    ('dynamic_stiffness = { file = "k.csv", axis = "q" }', "", r"mounts\[0\]\.dynamic_stiffness\.axis: expected 'u', 'v' or 'w', got 'q'"),
    ("", '[damping]\nloss_factor_model = "viscous"',
     r"damping\.loss_factor_model: expected 'causal', 'maxwell' or 'hysteretic', got 'viscous'"),
    ("", '[damping]\nloss_factor_model = "hysteretic"\nloss_factor_band_hz = [1.0, 10.0]',
     r'damping\.loss_factor_band_hz: expected loss_factor_model = "causal" or "maxwell".*got loss_factor_model = '
     r'"hysteretic"'),
    ("", '[damping]\nloss_factor_band_hz = [1.0, 10.0]',
     r"damping\.loss_factor_band_hz: expected a band covering every natural and operating frequency \(10\.9-49\.26 Hz\)"),
    ("", '[damping]\nloss_factor_model = "maxwell"\nloss_factor_band_hz = [10.0, 1.0]',
     r"damping\.loss_factor_band_hz: expected a band"),
])
def test_bad_visco_elastic_scenarios_are_refused(tmp_path, extra, damping, match):
    with pytest.raises(ScenarioError, match=match):
        scenario(tmp_path, extra, damping, rows=measured(np.geomspace(1.0, 500.0, 30)))


def test_a_maxwell_loss_model_needs_loss_factors(tmp_path):
    text = BASE.replace("loss_factor = [0.1, 0.1, 0.0]", "").format(extra="", damping='[damping]\n'
                                                                      'loss_factor_model = "maxwell"')
    with pytest.raises(ScenarioError, match=r"damping\.loss_factor_model: expected a mount with a loss_factor"):
        parse_scenario(text, source="v.toml", base_dir=tmp_path)


def test_a_bad_loss_factor_terms_names_its_key(tmp_path):
    with pytest.raises(ScenarioError, match=r"damping\.loss_factor_terms: expected"):
        scenario(tmp_path, damping='[damping]\nloss_factor_terms = -3')

"""Hysteretic bearings (Bouc-Wen, biaxial Park-Wen, friction pendulums): the direct solve against independent
answers (scipy solves of the same ODEs, the bilinear loop in closed form, the pendulum's period and loop area),
the energy balance, the linearizations and bad input."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import scipy.integrate

from sixdof import Mount, Rayleigh, RigidBody, System
from sixdof.analysis.contact import energy_balance
from sixdof.analysis.direct import SimulationSettings, simulate
from sixdof.analysis.response import mount_forces
from sixdof.errors import InputError, ScenarioError
from sixdof.excitation import Excitation, GroundMotion, InitialState
from sixdof.excitation.signals import Harmonic
from sixdof.io.scenario import parse_scenario
from sixdof.model.hysteresis import BoucWen

MASS, K, FY, RATIO = 1000.0, 1e6, 2e3, 0.1
#: The single-mass runs' agreement with scipy's DOP853 at rtol 1e-11: the direct solve's own tolerance (1e-6 of
#: the peak relative to the state scale) times the few hundred cycles' growth of the global error.
RTOL_SCIPY = 2e-6


def single_mass(law: BoucWen, stiffness=(K, K, 1e7)) -> System:
    """A point-like body on one mount at its CG: x, y, z decouple from the rotations."""
    body = RigidBody(mass=MASS, inertia=[100.0, 100.0, 100.0])
    mount = Mount(name="b", position=[0.0, 0.0, 0.0], stiffness=list(stiffness))
    return System(body=body, mounts=[mount], bouc_wen=[law])


def shaking(f_hz=2.0, amplitude=3.0, direction=(1.0, 0.0, 0.0), initial=None) -> Excitation:
    ground = GroundMotion(quantity="acceleration", direction=list(direction), signal=Harmonic(f_hz=f_hz),
                          scale=amplitude)
    return Excitation(ground=ground, initial=initial)


def wen_rate(z, rate, d_y, n, beta=0.5, gamma=0.5):
    """Wen's ``z'`` (uniaxial), written here apart from the package."""
    return rate / d_y * (1.0 - abs(z) ** n * (beta * np.sign(rate * z) + gamma))


@pytest.mark.slow  # 4 s each on the 2-core machine
@pytest.mark.parametrize("n", [1.0, 2.0])
def test_single_mass_bouc_wen_matches_a_scipy_solve_of_the_same_ode(n):
    system = single_mass(BoucWen(mount="b", axes=["u"], yield_force=[FY], post_yield_ratio=RATIO, exponent=n))
    excitation = shaking()
    history = simulate(system, excitation, SimulationSettings(duration=4.0, sample_rate_hz=500.0))
    d_y = FY / K

    def rhs(t, y):
        x, v, z = y
        force = RATIO * K * x + (1 - RATIO) * FY * z
        return [v, -force / MASS - 3.0 * np.sin(2 * np.pi * 2.0 * t), wen_rate(z, v, d_y, n)]

    ref = scipy.integrate.solve_ivp(rhs, (0.0, 4.0), [0.0, 0.0, 0.0], t_eval=history.t, method="DOP853",
                                    rtol=1e-11, atol=1e-14)
    x = history.q_relative[:, 0]
    assert np.abs(ref.y[2]).max() > 0.99  # driven well past yield
    assert np.abs(x - ref.y[0]).max() <= RTOL_SCIPY * np.abs(ref.y[0]).max()
    assert np.abs(history.hysteretic_state[:, 0] - ref.y[2]).max() <= 10 * RTOL_SCIPY
    force = mount_forces(system, history).local[0, :, 0]
    exact = RATIO * K * ref.y[0] + (1 - RATIO) * FY * ref.y[2]
    assert np.abs(force - exact).max() <= 10 * RTOL_SCIPY * np.abs(exact).max()
    balance = energy_balance(system, history)
    assert balance.ok and balance.dissipated[-1] > 0.5 * balance.work[-1]
    assert np.all(np.diff(balance.dissipated) >= -1e-9 * balance.energy_scale)  # hysteresis only dissipates


@pytest.mark.slow  # 10 s on the 2-core machine
def test_biaxial_park_wen_matches_a_scipy_solve_and_is_isotropic():
    """Ground shaking along x and an initial velocity along y: a two-dimensional orbit on one circular yield
    surface, against scipy's solve of Park-Wen's equations written here."""
    law = BoucWen(mount="b", axes=["u", "v"], yield_force=[FY, FY], post_yield_ratio=RATIO, exponent=2.0,
                  biaxial=True)
    system = single_mass(law)
    v0 = 0.15
    excitation = shaking(initial=InitialState(qd=[0.0, v0, 0.0, 0.0, 0.0, 0.0]))
    history = simulate(system, excitation, SimulationSettings(duration=3.0, sample_rate_hz=500.0))
    d_y = FY / K

    def rhs(t, y):
        d, v, z = y[:2], y[2:4], y[4:]
        force = RATIO * K * d + (1 - RATIO) * FY * z
        along = z @ v
        zd = (v - (0.5 * np.sign(along) + 0.5) * along * z) / d_y  # n = 2: |z|^(n-2) = 1
        return np.concatenate([v, -force / MASS - np.array([3.0 * np.sin(4 * np.pi * t), 0.0]), zd])

    ref = scipy.integrate.solve_ivp(rhs, (0.0, 3.0), [0, 0, 0, v0, 0, 0], t_eval=history.t, method="DOP853",
                                    rtol=1e-11, atol=1e-14)
    for dof in (0, 1):
        exact = ref.y[dof]
        assert np.abs(history.q_relative[:, dof] - exact).max() <= RTOL_SCIPY * np.abs(ref.y[:2]).max()
    assert np.hypot(*history.hysteretic_state.T).max() <= 1.0 + 1e-6  # on or inside the circle
    assert energy_balance(system, history).ok

    # Isotropy: shaken along the diagonal, the biaxial bearing answers as the uniaxial one along x.
    diagonal = simulate(system, shaking(direction=(2 ** -0.5, 2 ** -0.5, 0.0)),
                        SimulationSettings(duration=2.0, sample_rate_hz=500.0))
    uniaxial = simulate(single_mass(BoucWen(mount="b", axes=["u"], yield_force=[FY], post_yield_ratio=RATIO,
                                            exponent=2.0)), shaking(), SimulationSettings(duration=2.0,
                                                                                          sample_rate_hz=500.0))
    radial = diagonal.q_relative[:, :2] @ np.array([2 ** -0.5, 2 ** -0.5])
    assert np.abs(radial - uniaxial.q_relative[:, 0]).max() <= RTOL_SCIPY * np.abs(uniaxial.q_relative[:, 0]).max()


def bilinear_force(d, k, fy, a):
    """The bilinear (elastic - kinematic hardening) loop's force along a deflection history, in closed form: an
    elastic-perfectly-plastic spring (k (1 - a), yield (1 - a) Fy) beside a spring a k."""
    plastic = np.zeros_like(d)
    force = np.zeros_like(d)
    limit = fy / k
    for i in range(1, d.size):
        trial = plastic[i - 1] + d[i] - d[i - 1]
        plastic[i] = np.clip(trial, -limit, limit)
        force[i] = a * k * d[i] + (1 - a) * k * plastic[i]
    return force


@pytest.mark.slow  # 3 s on the 2-core machine
def test_large_exponent_tends_to_the_bilinear_loop():
    errors = []
    for n in (5.0, 25.0):
        system = single_mass(BoucWen(mount="b", axes=["u"], yield_force=[FY], post_yield_ratio=RATIO, exponent=n))
        history = simulate(system, shaking(f_hz=1.0, amplitude=2.0), SimulationSettings(duration=3.0,
                                                                                         sample_rate_hz=4000.0))
        d = history.q_relative[:, 0]
        force = mount_forces(system, history).local[0, :, 0]
        errors.append(np.abs(force - bilinear_force(d, K, FY, RATIO)).max() / FY)
    # Wen's transition narrows as 1/n: within 3 % of Fy at n = 25, and closer than at n = 5.
    assert errors[1] < 0.03 and errors[1] < 0.5 * errors[0]


def test_effective_linearization_is_the_secant_and_the_loop_damping():
    D = 0.05
    law = BoucWen(mount="b", axes=["u"], yield_force=[FY], post_yield_ratio=RATIO, linearization="effective",
                  design_displacement=D)
    system = single_mass(law)
    d_y = FY / K
    k_eff = RATIO * K + (1 - RATIO) * FY / D  # F(D) / D on the bilinear loop
    xi = 4 * (1 - RATIO) * FY * (D - d_y) / (2 * np.pi * k_eff * D ** 2)  # E_D / (2 pi K_eff D^2)
    assert system.stiffnesses[0, 0] == pytest.approx(k_eff, rel=1e-14)
    # The x mode's damping ratio is the loop's: c = 2 xi K_eff / omega at that mode's omega.
    omega = np.sqrt(k_eff / MASS)
    assert system.dampings[0, 0] == pytest.approx(2 * xi * k_eff / omega, rel=1e-12)
    initial = single_mass(BoucWen(mount="b", axes=["u"], yield_force=[FY], post_yield_ratio=RATIO))
    assert initial.stiffnesses[0, 0] == K and initial.dampings[0, 0] == 0.0


def test_rayleigh_damping_leaves_out_the_hysteretic_axes_unless_told():
    law = BoucWen(mount="b", axes=["u"], yield_force=[FY], post_yield_ratio=RATIO)
    base = single_mass(law)
    beta = 1e-3
    excluded = System(body=base.body, mounts=base.mounts, bouc_wen=[law], rayleigh=Rayleigh(alpha=0.0, beta=beta))
    included = System(body=base.body, mounts=base.mounts, bouc_wen=[law], rayleigh=Rayleigh(alpha=0.0, beta=beta),
                      rayleigh_excludes_hysteresis=False)
    assert excluded.C[0, 0] == 0.0 and excluded.C[1, 1] == pytest.approx(beta * K)
    assert included.C[0, 0] == pytest.approx(beta * K)


#: Four mounts at the corners of a square in the CG's plane: x, y, z translate apart from the rotations.
CORNER = """
[[mounts]]
name = "{name}"
position = [{x}, {y}, 0.0]
stiffness = [0.25e6, 0.25e6, 2.5e6]
{extra}
"""
HEAD = """
name = "isolated"
[body]
mass = 1000.0
inertia = [100.0, 100.0, 100.0]
[ground]
quantity = "acceleration"
direction = [1.0, 0.0, 0.0]
scale = 3.0
signal = { kind = "harmonic", f_hz = 2.0 }
[simulation]
duration = 1.0
sample_rate_hz = 1000.0
"""


class _Scenario:
    """``SCENARIO.format(extra=...)``: the four corner mounts, each with ``extra``."""

    @staticmethod
    def format(extra: str) -> str:
        corners = [CORNER.format(name=f"m{i}", x=x, y=y, extra=extra)
                   for i, (x, y) in enumerate([(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)])]
        return HEAD + "".join(corners)


SCENARIO = _Scenario()


@pytest.mark.parametrize(("extra", "field", "expected"), [
    ('hysteresis = { law = "bouc_wen", axes = ["u"], yield_force = [0.0], post_yield_ratio = 0.1 }',
     "mounts[0].hysteresis.yield_force", "yield force in N > 0"),
    ('hysteresis = { law = "bouc_wen", axes = ["u"], yield_force = [2e3], post_yield_ratio = 0.1, exponent = 0.5 }',
     "mounts[0].hysteresis.exponent", "n >= 1"),
    ('hysteresis = { law = "bouc_wen", axes = ["u"], yield_force = [2e3, 1e3], post_yield_ratio = 0.1 }',
     "mounts[0].hysteresis.yield_force", "one per listed axis"),
    ('hysteresis = { law = "wen", axes = ["u"], yield_force = [2e3], post_yield_ratio = 0.1 }',
     "mounts[0].hysteresis.law", "bouc_wen"),
    ('hysteresis = { law = "bouc_wen", axes = ["u"], yield_force = [2e3], post_yield_ratio = 0.1, '
     'linearization = "effective" }', "mounts[0].hysteresis.design_displacement", "design displacement"),
    ('hysteresis = { law = "bouc_wen", axes = ["u"], yield_force = [2e3], post_yield_ratio = 0.1, gamma = 0.9 }',
     "mounts[0].hysteresis.gamma", "|gamma| <= beta"),
    ("friction_pendulum = { radius = 2.0, mu = 0.05 }", "mounts[0].stiffness", "pendulum's N / R"),
])
def test_bad_hysteresis_input_is_one_error_naming_the_field(extra, field, expected):
    with pytest.raises(ScenarioError) as caught:
        parse_scenario(SCENARIO.format(extra=extra))
    assert caught.value.field == field and expected in caught.value.expected
    assert "\n" not in str(caught.value)


def test_a_friction_pendulum_on_a_mount_that_carries_no_load_is_refused():
    text = SCENARIO.format(extra="friction_pendulum = { radius = 2.0, mu = 0.05 }").replace(
        "stiffness = [0.25e6, 0.25e6, 2.5e6]", "stiffness = [0.0, 0.0, 0.0]\ndamping = [0.0, 0.0, 1.0]")
    with pytest.raises((ScenarioError, InputError)) as caught:
        parse_scenario(text)
    assert "carries" in caught.value.expected or "not all zero" in caught.value.expected


@pytest.mark.slow  # 4 s on the 2-core machine
def test_a_scenario_run_checks_hysteresis_by_energy_and_a_second_solve():
    import sixdof  # noqa: PLC0415 (the public run, as a user calls it)

    extra = 'hysteresis = { law = "bouc_wen", axes = ["u"], yield_force = [500.0], post_yield_ratio = 0.1 }'
    results = sixdof.run(parse_scenario(SCENARIO.format(extra=extra)))
    assert results.agreement is None  # the superposition of the linearization is not a check of hysteresis
    assert results.energy.ok and results.refined.ok
    assert results.response.hysteretic_state.shape == (results.response.t.size, 4)
    # Its superposition.png says which curve is which model, and that the difference is no failed check.
    from sixdof.plots import FIGURES  # noqa: PLC0415 (matplotlib: this test's figure only)

    draw = next(draw for name, _, _, draw in FIGURES if name == "superposition.png")
    fig = draw(results)
    heading = fig.get_suptitle()
    assert heading.startswith(f"{results.name}: hysteretic bearings (direct integration) vs their linearization")
    assert "\nnot a cross-check: the difference is the hysteresis" in heading
    assert {line.get_label() for line in fig.axes[0].get_lines()} >= {"direct integration (hysteretic)",
                                                                      "modal superposition (linearized)"}


G = 9.80665


def pendulums(radius: float, mu, yield_displacement: float = 5e-4) -> System:
    """A body on four friction pendulums in its CG's plane, at its static equilibrium under gravity along -z."""
    from sixdof.analysis.statics import at_equilibrium, gravity_statics  # noqa: PLC0415 (statics: used here alone)
    from sixdof.model.hysteresis import FrictionPendulum  # noqa: PLC0415

    body = RigidBody(mass=MASS, inertia=[400.0, 400.0, 700.0])
    corners = [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)]
    mounts = [Mount(name=f"p{i}", position=[x, y, 0.0], stiffness=[0.0, 0.0, 2.5e7]) for i, (x, y) in
              enumerate(corners)]
    laws = [FrictionPendulum(mount=m.name, radius=radius, mu=mu, yield_displacement=yield_displacement)
            for m in mounts]
    system = System(body=body, mounts=mounts, friction_pendulum=laws)
    return at_equilibrium(system, gravity_statics(system, G, [0.0, 0.0, -1.0]))


@pytest.mark.slow  # 4 s on the 2-core machine
def test_friction_pendulum_swings_with_the_period_of_its_radius():
    """Released from D = 0.1 m with little friction: the pendulum's period 2 pi sqrt(R / g), whatever the mass. (Near
    each turning point the bearing sticks over ~2 d_y with the stiffer mu N / d_y, which shortens the period by about
    d_y / D: 0.4 % with the default 0.5 mm, so a small d_y here.)"""
    radius = 2.0
    system = pendulums(radius, 0.002, yield_displacement=5e-5)
    assert system.hysteretic.static_load == pytest.approx(np.full(8, MASS * G / 4), rel=1e-9)
    excitation = Excitation(initial=InitialState(q=[0.1, 0.0, 0.0, 0.0, 0.0, 0.0]))
    history = simulate(system, excitation, SimulationSettings(duration=6.0, sample_rate_hz=1000.0))
    v = history.qd[:, 0]
    crossings = np.flatnonzero((v[:-1] > 0) != (v[1:] > 0))
    t = history.t[crossings] - v[crossings] * (history.t[crossings + 1] - history.t[crossings]) / (
        v[crossings + 1] - v[crossings])
    period = 2 * np.mean(np.diff(t))
    assert period == pytest.approx(2 * np.pi * np.sqrt(radius / G), rel=2e-3)
    # Coulomb friction takes 4 mu g / omega^2 = 4 mu R of amplitude per cycle off.
    peaks = np.abs(history.q[crossings, 0])
    assert np.mean(-np.diff(peaks[::2])) == pytest.approx(4 * 0.002 * radius, rel=0.05)
    assert energy_balance(system, history).ok


@pytest.mark.slow  # 5 s each on the 2-core machine
@pytest.mark.parametrize("yield_displacement", [2e-3, 2e-4])
def test_friction_pendulum_loop_area_tends_to_four_mu_n_d(yield_displacement):
    """The friction's loop (force less the pendulum's N d / R, against d) over a cycle from one turning point to the
    next: area mu N (L - 5 d_y) for a path of length L (Wen's n = 1 sticks over 2.5 d_y at each reversal), that is
    4 mu N D for a closed cycle of amplitude D as d_y / D -> 0."""
    mu, radius = 0.06, 1.5
    system = pendulums(radius, mu, yield_displacement)
    f_hz = 0.3
    history = simulate(system, shaking(f_hz=f_hz, amplitude=2.5), SimulationSettings(duration=3 / f_hz,
                                                                                     sample_rate_hz=1000.0))
    v = history.qd_relative[:, 0]
    turns = np.flatnonzero((v[:-1] > 0) & (v[1:] <= 0))  # the turning points at the largest d
    cycle = slice(turns[-2], turns[-1] + 1)
    d = history.q_relative[cycle, 0]
    N = MASS * G / 4
    friction = mount_forces(system, history).local[0, cycle, 0] - N / radius * d
    area = np.sum(0.5 * (friction[1:] + friction[:-1]) * np.diff(d))
    path = np.sum(np.abs(np.diff(d)))
    assert path > 80 * yield_displacement
    assert area == pytest.approx(mu * N * (path - 5 * yield_displacement), rel=1e-5)
    assert area == pytest.approx(mu * N * path, rel=6 * yield_displacement / path)  # 4 mu N D, D = path / 4


def test_velocity_dependent_friction_follows_constantinou():
    from sixdof.model.hysteresis import FrictionPendulum  # noqa: PLC0415

    law = FrictionPendulum(mount="p", radius=2.0, mu={"slow": 0.03, "fast": 0.09, "rate": 20.0})
    assert law.mu == (0.03, 0.09, 20.0)
    system = pendulums(2.0, {"slow": 0.03, "fast": 0.09, "rate": 20.0})
    h = system.hysteretic
    for speed in (0.0, 0.05, 1.0):
        p, q = h.coefficients(speed=speed)
        assert q[0] == pytest.approx(h.static_load[0] * (0.09 - 0.06 * np.exp(-20.0 * speed)), rel=1e-14)
        assert p[0] == pytest.approx(h.static_load[0] / 2.0, rel=1e-14)


def test_isolated_spectrum_iterates_to_the_design_displacement_a_hand_iteration_finds():
    """One isolated mass on four Bouc-Wen bearings (x alone: the spectrum along x), EN 1998-2's loop against the
    same fixed point iterated here by hand: T_eff = 2 pi sqrt(m / K_eff(D)), xi_eff(D) of the bilinear loop,
    D = S_e(T_eff, xi_eff) (T_eff / 2 pi)^2 with EN 1998-1's eta(xi) = sqrt(10 / (5 + 100 xi)) >= 0.55."""
    from sixdof.analysis.isolation import isolated_spectrum  # noqa: PLC0415
    from sixdof.excitation.spectra import EC8Spectrum, SpectrumSettings  # noqa: PLC0415

    extra = ('hysteresis = { law = "bouc_wen", axes = ["u", "v"], yield_force = [500.0, 500.0], '
             'post_yield_ratio = 0.1, biaxial = true, linearization = "effective", design_displacement = 0.02 }')
    scenario = parse_scenario(SCENARIO.format(extra=extra))
    system = scenario.system
    shape = EC8Spectrum(type=1, ground_type="C", ag=2.45)
    settings = SpectrumSettings(spectrum=shape, directions=["x"])
    loop = isolated_spectrum(system, settings)
    k, fy, a = 0.25e6, 500.0, 0.1
    d_y = fy / k
    D = 0.02
    for _ in range(200):
        k_eff = 4 * (a * k + (1 - a) * fy / D)
        xi = 4 * (1 - a) * fy * (D - d_y) / (2 * np.pi * (k_eff / 4) * D ** 2)
        T = 2 * np.pi * np.sqrt(MASS / k_eff)
        D_new = float(shape.horizontal(np.array([T]), xi)[0]) * (T / (2 * np.pi)) ** 2
        if abs(D_new - D) < 1e-12:
            break
        D = D_new
    # The converged analysis's bearing deflection along x (u), to the loop's tolerance (1e-3 on K_eff and xi, about
    # 2e-3 on D here, where K_eff changes as 0.6 D).
    converged = loop.response.combined_mount_deflection[:, 0]
    assert converged == pytest.approx(np.full(4, D), rel=2e-3)
    assert loop.change[-1] < 1e-3 and loop.design_displacement.shape[0] >= 3
    assert loop.response.mode_damping.max() == pytest.approx(xi, rel=5e-3)


@pytest.mark.slow  # 8 s on the 2-core machine
def test_the_bundled_lead_rubber_bridge():
    """scenarios/bridge_beam_lrb.toml: the time run checks itself (energy, second solve); the bearings' peak force
    is the loop's, Q_d + a k D past yield, at their peak deflection; the spectrum's isolation modes sit at
    T_eff = 2 pi sqrt(m / sum K_eff) of the converged design displacement, whose D is S_e(T_eff, xi_eff)
    (T_eff / 2 pi)^2 along x (the mode carries the whole mass)."""
    import sixdof  # noqa: PLC0415
    from sixdof.excitation.spectra import damping_correction  # noqa: PLC0415

    results = sixdof.run(Path(__file__).resolve().parents[1] / "scenarios" / "bridge_beam_lrb.toml")
    assert results.energy.ok and results.refined.ok and results.agreement is None
    h = results.system.hysteretic
    d = results.response.q_relative @ h.rows.T
    force = results.mount_forces.local[h.mount, :, h.axis].T
    k, fy, a = 2.05e6, 13.6e3, 0.1
    v = [e for e, name in enumerate(h.names) if name.endswith(" v")]
    peak = np.argmax(np.abs(d[:, v[0]]))
    D = abs(d[peak, v[0]])
    assert D > 5 * fy / k  # well past yield
    # Wen's n = 1 approaches the bilinear envelope exponentially: within 1 % of it this far past yield.
    assert abs(force[peak, v[0]]) == pytest.approx((1 - a) * fy + a * k * D, rel=1e-2)
    loop, spectrum = results.isolation, results.spectrum
    # Along y (the beam's axis) the isolation mode is a translation (along x it rocks with ry, the CG 1 m up).
    k_eff = loop.stiffness[-1][[i for i, n in enumerate(loop.axes) if n.endswith(" v")]].sum()
    T_eff = 2 * np.pi * np.sqrt(results.system.body.mass / k_eff)
    mode = int(np.argmax(spectrum.effective_mass[1]))
    assert spectrum.period[mode] == pytest.approx(T_eff, rel=1e-3)
    xi = loop.system_damping[-1]
    assert spectrum.mode_damping[mode] == xi
    shape = results.scenario.response_spectrum.spectrum
    S_d = float(shape.horizontal(np.array([T_eff]), xi)[0]) * (T_eff / (2 * np.pi)) ** 2
    assert damping_correction(xi) < 0.8  # the lead's damping counts
    assert spectrum.combined_mount_deflection[0, 1] == pytest.approx(S_d, rel=5e-3)


@pytest.mark.long  # 20 s on the 2-core machine: lift-off events on every rocking cycle
def test_friction_pendulums_that_lift_off_with_velocity_dependent_friction_balance_their_energy():
    """Four pendulums under the CG with tension = false and Constantinou's friction, shaken until the body rocks:
    the run's energy balance (the pendulums' load changing with the rocking) and its second solve hold."""
    import sixdof  # noqa: PLC0415

    corner = """
[[mounts]]
name = "p{i}"
position = [{x}, {y}, -0.3]
stiffness = [0.0, 0.0, 2.5e7]
damping = [0.0, 0.0, 2e3]
tension = false
friction_pendulum = {{ radius = 1.5, mu = {{ slow = 0.04, fast = 0.08, rate = 20.0 }} }}
"""
    text = HEAD.replace('f_hz = 2.0 }', 'f_hz = 0.8, duration = 3.0 }').replace("scale = 3.0", "scale = 4.0").replace(
        "duration = 1.0", "duration = 4.0").replace("inertia = [100.0, 100.0, 100.0]", "inertia = [400.0, 400.0, 700.0]")
    text += "".join(corner.format(i=i, x=x, y=y) for i, (x, y) in enumerate([(1, 1), (1, -1), (-1, 1), (-1, -1)]))
    results = sixdof.run(parse_scenario(text))
    assert results.system.hysteretic.static_load == pytest.approx(np.full(8, MASS * G / 4), rel=1e-9)
    assert results.energy.ok and results.refined.ok
    assert np.abs(results.response.q_relative[:, 0]).max() > 100 * 5e-4  # sliding, far past d_y


def test_sweeps_and_designs_refuse_hysteretic_bearings_rather_than_linearize_them_silently():
    from sixdof.analysis.batch.variants import check_batchable  # noqa: PLC0415

    system = single_mass(BoucWen(mount="b", axes=["u"], yield_force=[FY], post_yield_ratio=RATIO))
    with pytest.raises(InputError) as caught:
        check_batchable(system)
    assert "hysteretic bearings" in caught.value.expected and "b u" in str(caught.value.got)


def test_modes_json_lists_each_bearing_axis_at_its_linearization(capsys):
    import json  # noqa: PLC0415

    from sixdof.cli import main  # noqa: PLC0415

    path = Path(__file__).resolve().parents[1] / "scenarios" / "bridge_beam_lrb.toml"
    assert main(["modes", str(path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    D, k, fy, a = 0.1, 2.05e6, 13.6e3, 0.1
    assert out["linearization"] == ["effective"] * 8
    assert out["linearized_stiffness"] == pytest.approx([a * k + (1 - a) * fy / D] * 8, rel=1e-12)


def test_a_friction_triple_is_checked_as_the_table_is():
    from sixdof.model.hysteresis import FrictionPendulum  # noqa: PLC0415

    for mu in ([0.04, 1.5, 20.0], [0.0, 0.08, 20.0], [0.04, 0.08, -1.0]):
        with pytest.raises(InputError) as caught:
            FrictionPendulum(mount="p", radius=2.0, mu=mu)
        assert caught.value.field == "mu"

"""Response-spectrum analysis (issue 48, points 4 and 7): the EN 1998-1 spectra against the code's formulas worked
by hand, the CQC against Der Kiureghian's coefficients for two close modes of a body built so that its modes are
known in closed form, the single-mode limit, the effective masses, the 100-30 rule, tabulated spectra, the
effective-linearization loop against a hand fixed-point iteration of a bilinear isolator, bad input, and a
scenario run end to end through the store."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sixdof import InputError, parse_scenario
from sixdof.analysis.isolation import effective_linearization_loop
from sixdof.analysis.spectrum import combine_directions, cqc_coefficients, response_spectrum
from sixdof.errors import SolverError
from sixdof.excitation.spectra import EC8Spectrum, SpectrumSettings, TabulatedSpectrum, damping_correction
from sixdof.model.parts import Mount, RigidBody
from sixdof.model.system import System
from tolerances import RTOL_LINALG

MASS = 1000.0
CORNERS = [(0.5, 0.4), (0.5, -0.4), (-0.5, 0.4), (-0.5, -0.4)]  # in the CG's plane: translations uncoupled


def _body_on(k_u, k_v, k_w=4e5, angle=0.0, z=0.0, corners=CORNERS, mass=MASS):
    """A body on four identical mounts whose u, v axes are turned by ``angle`` about z: its u and v translations
    are modes of frequencies sqrt(4 k / m) when the mounts lie in the CG's plane (z = 0)."""
    c, s = math.cos(angle), math.sin(angle)
    axes = [[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]]
    mounts = [Mount(name=f"m{i}", position=[x, y, z], stiffness=[k_u, k_v, k_w], axes=axes)
              for i, (x, y) in enumerate(corners)]
    return System(body=RigidBody(mass=mass, inertia=np.diag([100.0, 120.0, 150.0])), mounts=mounts)


def _stiffness_for(f_hz, mass=MASS):
    """Each of four mounts' stiffness [N/m] for a translation mode at ``f_hz``."""
    return (2 * math.pi * f_hz) ** 2 * mass / 4


# --- EN 1998-1 spectra, by hand from eqs. (3.2)-(3.16) and Tables 3.2-3.4 ---------------------------------------

def test_type_1_ground_c_at_its_corner_periods_and_in_each_branch():
    # Table 3.2, C: S 1.15, TB 0.2, TC 0.6, TD 2.0; ag = 2 m/s^2; ag S = 2.3, plateau 2.3 x 2.5 = 5.75.
    spectrum = EC8Spectrum(type=1, ground_type="C", ag=2.0)
    T = [0.0, 0.1, 0.2, 0.4, 0.6, 1.0, 2.0, 3.0]
    hand = [2.3, 2.3 * (1 + 0.1 / 0.2 * 1.5), 5.75, 5.75, 5.75, 5.75 * 0.6 / 1.0, 5.75 * 0.6 / 2.0,
            5.75 * 0.6 * 2.0 / 9.0]
    assert spectrum.horizontal(T) == pytest.approx(hand, rel=1e-14)


def test_type_2_ground_d_with_an_importance_factor():
    # Table 3.3, D: S 1.8, TB 0.1, TC 0.3, TD 1.2; ag = 1.2 x 1.5 = 1.8; ag S = 3.24, plateau 8.1.
    spectrum = EC8Spectrum(type=2, ground_type="D", ag=1.5, importance=1.2)
    T = [0.0, 0.05, 0.1, 0.3, 0.6, 1.2, 2.0]
    hand = [3.24, 3.24 * (1 + 0.5 * 1.5), 8.1, 8.1, 8.1 * 0.3 / 0.6, 8.1 * 0.3 / 1.2, 8.1 * 0.3 * 1.2 / 4.0]
    assert spectrum.horizontal(T) == pytest.approx(hand, rel=1e-14)
    assert spectrum.design_ag == pytest.approx(1.8, rel=1e-15)


def test_the_damping_correction_at_5_and_10_percent_and_its_floor():
    assert damping_correction(0.05) == pytest.approx(1.0, rel=1e-15)
    assert damping_correction(0.10) == pytest.approx(math.sqrt(10 / 15), rel=1e-15)
    assert damping_correction(0.30) == 0.55  # sqrt(10 / 35) = 0.5345, below the floor
    plateau = EC8Spectrum(type=1, ground_type="C", ag=2.0).horizontal(0.4, xi=0.10)
    assert plateau == pytest.approx(5.75 * math.sqrt(10 / 15), rel=1e-14)


def test_the_design_spectrum_and_its_lower_bound():
    # q = 3: 2.3 x 2/3 at T = 0, 2.3 x 2.5 / 3 = 1.9167 on the plateau, never below 0.2 ag = 0.4 beyond TC.
    spectrum = EC8Spectrum(type=1, ground_type="C", ag=2.0, behaviour_factor=3.0)
    T = [0.0, 0.1, 0.4, 1.5, 3.0]
    plateau = 2.3 * 2.5 / 3
    hand = [2.3 * 2 / 3, 2.3 * (2 / 3 + 0.5 * (2.5 / 3 - 2 / 3)), plateau, plateau * 0.6 / 1.5, 0.4]
    assert plateau * 0.6 * 2.0 / 9.0 < 0.4  # the bound is what acts at 3 s
    assert spectrum.horizontal(T, xi=0.2) == pytest.approx(hand, rel=1e-14)  # no damping correction with q


def test_the_vertical_spectrum_and_its_design_form_at_q_1_5():
    # Table 3.4, type 1: avg = 0.9 x 2 = 1.8; TB 0.05, TC 0.15, TD 1.0; plateau 1.8 x 3.0 = 5.4.
    elastic = EC8Spectrum(type=1, ground_type="C", ag=2.0)
    T = [0.0, 0.05, 0.15, 0.5, 1.0, 2.0]
    hand = [1.8, 5.4, 5.4, 5.4 * 0.15 / 0.5, 5.4 * 0.15, 5.4 * 0.15 / 4.0]
    assert elastic.pseudo_acceleration(T, 0.05, "z") == pytest.approx(hand, rel=1e-14)
    # q = 3 is taken as 1.5 vertically (3.2.2.5(5)): plateau 1.8 x 2.5 / 1.5 = 3.0; type 2: avg 0.45 ag.
    design = EC8Spectrum(type=2, ground_type="C", ag=2.0, behaviour_factor=3.0)
    assert design.vertical(0.1) == pytest.approx(0.9 * 2.5 / 1.5, rel=1e-14)


# --- the analysis --------------------------------------------------------------------------------------------

def _ec8(**analysis):
    return SpectrumSettings(spectrum=EC8Spectrum(type=1, ground_type="C", ag=2.0), **analysis)


def _se(T, xi=0.05):
    """Type 1, ground C, ag 2 m/s^2 by hand (the branches used here)."""
    eta = max(math.sqrt(10 / (5 + 100 * xi)), 0.55)
    top = 2.3 * 2.5 * eta
    if T <= 0.6:
        return top
    return top * 0.6 / T if T <= 2.0 else top * 0.6 * 2.0 / T**2


def test_one_excited_translation_mode_peaks_at_the_displacement_spectrum():
    system = _body_on(_stiffness_for(0.8), _stiffness_for(2.0))
    result = response_spectrum(system, _ec8(directions=("x",)))
    T = 1 / 0.8
    sd = _se(T) * (T / (2 * math.pi)) ** 2
    assert result.peak_q[0, 0] == pytest.approx(sd, rel=RTOL_LINALG)
    assert result.base_shear[0] == pytest.approx([MASS * _se(T), 0.0, 0.0], rel=RTOL_LINALG, abs=1e-9)
    assert result.mount_force[0, :, 0] == pytest.approx(_stiffness_for(0.8) * sd, rel=RTOL_LINALG)
    assert result.mount_deflection[0, :, 0] == pytest.approx(sd, rel=RTOL_LINALG)


def test_cqc_of_two_close_modes_against_a_hand_computation():
    """Mount axes turned 30 degrees: translations along u (1.0 Hz) and v (1.05 Hz), both excited by ground along
    x. Per mode, x moves by cos^2 or sin^2 times S_De, y by +-cos sin S_De: x adds the cross term, y subtracts it."""
    angle, xi = math.radians(30.0), 0.05
    system = _body_on(_stiffness_for(1.0), _stiffness_for(1.05), angle=angle)
    result = response_spectrum(system, _ec8(directions=("x",)))
    w1, w2 = 2 * math.pi * 1.0, 2 * math.pi * 1.05
    r = w2 / w1
    rho = 8 * xi**2 * (1 + r) * r**1.5 / ((1 - r**2) ** 2 + 4 * xi**2 * r * (1 + r) ** 2)
    # 8 (0.05^2) 2.05 1.05^1.5 / (0.1025^2 + 4 (0.05^2) 1.05 2.05^2) = 0.044113 / 0.054633: strongly correlated
    assert rho == pytest.approx(0.8075, abs=1e-4)
    d1, d2 = _se(1.0) / w1**2, _se(1 / 1.05) / w2**2
    c, s = math.cos(angle), math.sin(angle)
    x1, x2, y1, y2 = c * c * d1, s * s * d2, c * s * d1, -s * c * d2
    hand_x = math.sqrt(x1**2 + x2**2 + 2 * rho * x1 * x2)
    hand_y = math.sqrt(y1**2 + y2**2 + 2 * rho * y1 * y2)
    assert result.peak_q[0, 0] == pytest.approx(hand_x, rel=RTOL_LINALG)
    assert result.peak_q[0, 1] == pytest.approx(hand_y, rel=RTOL_LINALG)
    # SRSS of the same modes misses the correlation: y 2.3 times too large here.
    srss = response_spectrum(system, _ec8(directions=("x",), combination="srss"))
    assert srss.peak_q[0, 1] == pytest.approx(math.hypot(y1, y2), rel=RTOL_LINALG)
    assert srss.peak_q[0, 1] > 2 * hand_y


def test_the_general_cqc_coefficient_reduces_to_the_equal_damping_one_and_is_symmetric():
    w = np.array([1.0, 1.3, 4.0])
    rho = cqc_coefficients(w, 0.07)
    r = w[None, :] / w[:, None]
    equal = 8 * 0.07**2 * (1 + r) * r**1.5 / ((1 - r**2) ** 2 + 4 * 0.07**2 * r * (1 + r) ** 2)
    assert rho == pytest.approx(equal, rel=1e-13)
    unequal = cqc_coefficients(w, [0.02, 0.15, 0.05])
    assert unequal == pytest.approx(unequal.T, rel=1e-13)
    # Der Kiureghian's form written out for modes 1 and 2: r = 1.3, xi_i = 0.02, xi_j = 0.15.
    zi, zj, r = 0.02, 0.15, 1.3
    hand = 8 * math.sqrt(zi * zj) * (zi + r * zj) * r**1.5 / (
        (1 - r**2) ** 2 + 4 * zi * zj * r * (1 + r**2) + 4 * (zi**2 + zj**2) * r**2)
    assert unequal[0, 1] == pytest.approx(hand, rel=1e-13)


def test_well_separated_modes_combine_as_srss():
    system = _body_on(_stiffness_for(0.7), _stiffness_for(3.5), angle=math.radians(40.0))
    cqc = response_spectrum(system, _ec8(directions=("x",)))
    srss = response_spectrum(system, _ec8(directions=("x",), combination="srss"))
    r = 3.5 / 0.7
    rho = 8 * 0.05**2 * (1 + r) * r**1.5 / ((1 - r**2) ** 2 + 4 * 0.05**2 * r * (1 + r) ** 2)
    assert rho < 0.005
    # |CQC^2 - SRSS^2| = 2 rho |R1 R2| <= rho (R1^2 + R2^2): within rho / 2 in the root.
    assert cqc.peak_q[0, :2] == pytest.approx(srss.peak_q[0, :2], rel=rho / 2)


def test_effective_masses_sum_to_the_mass_in_every_translation():
    # Mounts 0.3 m below the CG and off-centre: translations and rotations couple in every mode.
    corners = [(0.6, 0.3), (0.5, -0.45), (-0.4, 0.5), (-0.55, -0.35)]
    system = _body_on(2e5, 1.5e5, k_w=6e5, angle=0.3, z=-0.3, corners=corners)
    result = response_spectrum(system, _ec8(directions=("x", "y", "z")))
    assert result.effective_mass.sum(axis=1) == pytest.approx([MASS] * 3, rel=RTOL_LINALG)
    assert np.count_nonzero(result.effective_mass[0] > 1e-6 * MASS) >= 2  # shared between modes
    assert result.mass_share == pytest.approx([1.0] * 3, rel=RTOL_LINALG)
    # Each mode's displacement is Gamma S_De phi: the combined peak of a DOF is no larger than the sum of its modes'.
    assert np.all(result.peak_q <= np.abs(result.modal_q).sum(axis=1) * (1 + 1e-12))


def test_the_100_30_rule_on_a_hand_case():
    assert combine_directions([[3.0], [2.0]], "100-30") == pytest.approx([3.6])  # max(3 + 0.6, 0.9 + 2)
    assert combine_directions([[1.0], [2.0], [3.0]], "100-30") == pytest.approx([3.9])  # 3 + 0.3 (1 + 2)
    assert combine_directions([[3.0], [4.0]], "srss") == pytest.approx([5.0])
    system = _body_on(_stiffness_for(0.8), _stiffness_for(1.6), angle=math.radians(25.0))
    result = response_spectrum(system, _ec8(directional="100-30"))
    x, y = result.peak_q[:, 0]
    assert result.combined_q[0] == pytest.approx(max(x + 0.3 * y, 0.3 * x + y), rel=1e-14)


def test_a_tabulated_spectrum_is_interpolated_and_refused_outside_its_periods(tmp_path):
    (tmp_path / "sa.csv").write_text("period_s,sa\n0.1,2.0\n1.0,4.0\n3.0,1.0\n", encoding="utf-8")
    scenario = parse_scenario(_scenario('file = "sa.csv"\ndirections = ["x"]'), base_dir=tmp_path)
    result = response_spectrum(scenario.system, scenario.response_spectrum)
    T = 1 / 0.8
    sa = 4.0 + (T - 1.0) / 2.0 * (1.0 - 4.0)
    assert result.spectral_acceleration[0, 0] == pytest.approx(sa, rel=1e-14)
    assert result.peak_q[0, 0] == pytest.approx(sa * (T / (2 * math.pi)) ** 2, rel=RTOL_LINALG)
    short = TabulatedSpectrum(periods=[0.5, 3.0], values=[1.0, 1.0], source="short.csv")
    with pytest.raises(InputError, match=r"short.csv gives 0.5 to 3 s.*a mode of period 0\.\d+ s"):
        response_spectrum(scenario.system, SpectrumSettings(spectrum=short))
    (tmp_path / "back.csv").write_text("0.1,2.0\n1.0,4.0\n0.9,1.0\n", encoding="utf-8")
    with pytest.raises(InputError, match=r"spectrum.file.*0.9 on line 3 of back.csv, after 1 on line 2"):
        parse_scenario(_scenario('file = "back.csv"'), base_dir=tmp_path)


def _scenario(spectrum: str) -> str:
    mounts = "".join(f'[[mounts]]\nname = "m{i}"\nposition = [{x}, {y}, 0.0]\nstiffness = '
                     f"[{_stiffness_for(0.8)}, {_stiffness_for(2.0)}, 4e5]\n" for i, (x, y) in enumerate(CORNERS))
    return (f'name = "spectrum_case"\n[body]\nmass = {MASS}\ninertia = [100.0, 120.0, 150.0]\n{mounts}'
            f"[spectrum]\n{spectrum}\n")


_EC8 = 'code = "ec8"\ntype = 1\nground_type = "C"\nag = 2.0'


@pytest.mark.parametrize(("extra", "message"), [
    ('code = "ec8"\ntype = 1\nground_type = "F"\nag = 2.0', r"spectrum.ground_type: expected 'A', 'B', 'C', 'D' or 'E', got 'F'"),
    ('code = "ec8"\ntype = 1\nground_type = "S1"\nag = 2.0', r"spectrum.ground_type: .*S1 and S2 need special"),
    ('code = "ec8"\ntype = 3\nground_type = "C"\nag = 2.0', r"spectrum.type: expected 1 or 2.*got 3"),
    ('code = "ec8"\ntype = 1\nground_type = "C"\nag = 0.0', r"spectrum.ag: expected .*agR > 0.*got 0.0"),
    (f'{_EC8}\ndirections = ["x", "w"]', r"spectrum.directions\[1\]: expected 'x', 'y' or 'z', got 'w'"),
    (f"{_EC8}\nbehaviour_factor = 0.5", r"spectrum.behaviour_factor: expected a behaviour factor q >= 1.*got 0.5"),
    (f'{_EC8}\nfile = "sa.csv"', r"spectrum: expected either code = \"ec8\" or file.*got both"),
    ("damping = 0.05", r"spectrum: expected either code = \"ec8\" or file.*got neither"),
    ('code = "ec7"\ntype = 1\nground_type = "C"\nag = 2.0', r"spectrum.code: expected 'ec8'.*got 'ec7'"),
    (f"{_EC8}\ndampng = 0.1", r"spectrum.dampng: .*an unknown key; did you mean 'damping'\?"),
    (f'{_EC8}\ncombination = "abs"', r"spectrum.combination: expected 'cqc' or 'srss'.*got 'abs'"),
    (f"{_EC8}\ndamping = 1.2", r"spectrum.damping: expected a viscous damping ratio in \[0, 1\).*got 1.2"),
    ('file = "sa.csv"\nground_type = "C"', r"spectrum.ground_type: expected code = \"ec8\".*file = 'sa.csv'"),
    ('code = "ec8"\ntype = 1\nground_type = "C"', r"spectrum.ag: expected a value \(required key\)"),
])
def test_bad_spectrum_tables_are_refused_in_one_line(extra, message):
    with pytest.raises(InputError, match=message) as caught:
        parse_scenario(_scenario(extra))
    assert "\n" not in str(caught.value)


def test_a_body_free_in_a_dof_and_bad_mode_damping_are_refused():
    system = _body_on(_stiffness_for(0.8), _stiffness_for(2.0))
    with pytest.raises(InputError, match=r"mode_damping: expected 6 damping ratios in \[0, 1\)"):
        response_spectrum(system, _ec8(), mode_damping=[0.05] * 5)
    free = System(body=system.body, mounts=[Mount(name="one", position=[0.0, 0.0, 0.0], stiffness=[1e5, 1e5, 1e5])])
    with pytest.raises(InputError, match=r"system: expected a body restrained in every DOF.*rx, ry, rz"):
        response_spectrum(free, _ec8())


# --- the effective-linearization loop ------------------------------------------------------------------------

QD, KD, DY = 250.0, 2500.0, 0.005  # per mount: characteristic strength [N], post-yield stiffness [N/m], yield [m]


def _bilinear(D):
    """Closed-form bilinear isolator: K_eff = Qd / D + Kd, xi_eff = 2 Qd (D - Dy) / (pi K_eff D^2)."""
    k = QD / D + KD
    return k, 2 * QD * (D - DY) / (math.pi * k * D**2)


def test_the_effective_linearization_matches_a_hand_fixed_point_iteration():
    def linearize(D):
        stiffness = [_bilinear(d)[0] for d in D]
        mounts = [Mount(name=f"m{i}", position=[x, y, 0.0], stiffness=[k, 1e5, 4e5])
                  for i, ((x, y), k) in enumerate(zip(CORNERS, stiffness))]
        system = System(body=RigidBody(mass=MASS, inertia=np.diag([100.0, 120.0, 150.0])), mounts=mounts)
        return system, [_bilinear(d)[1] for d in D]

    settings = SpectrumSettings(spectrum=EC8Spectrum(type=1, ground_type="C", ag=3.0), directions=("x",))
    loop = effective_linearization_loop(linearize, settings, [(m, 0) for m in range(4)], [0.1] * 4)
    # By hand: D -> K_eff, xi_eff -> T = 2 pi sqrt(m / 4 K_eff) -> D = Se(T, xi_eff) (T / 2 pi)^2.
    D, previous, steps = 0.1, None, 0
    while True:
        k, xi = _bilinear(D)
        steps += 1
        if previous is not None and max(abs(k - previous[0]) / previous[0], abs(xi - previous[1]) / previous[1]) < 1e-3:
            break
        previous = (k, xi)
        T = 2 * math.pi * math.sqrt(MASS / (4 * k))
        D = 1.5 * _se(T, xi) * (T / (2 * math.pi)) ** 2  # ag 3 is 1.5 times _se's 2
    T = 2 * math.pi * math.sqrt(MASS / (4 * k))
    assert loop.design_displacement.shape == (steps, 4)
    assert loop.design_displacement[-1] == pytest.approx([D] * 4, rel=RTOL_LINALG)
    assert loop.stiffness[-1] == pytest.approx([k] * 4, rel=RTOL_LINALG)
    assert loop.system_damping[-1] == pytest.approx(xi, rel=RTOL_LINALG)
    assert loop.effective_period[-1] == pytest.approx(T, rel=RTOL_LINALG)
    response = loop.response
    assert response.mode_damping[int(np.argmax(response.effective_mass[0]))] == pytest.approx(xi, rel=RTOL_LINALG)
    assert response.peak_q[0, 0] == pytest.approx(1.5 * _se(T, xi) * (T / (2 * math.pi)) ** 2, rel=RTOL_LINALG)
    assert 3 <= steps <= 30 and 0.05 < xi < 0.4  # a real iteration, with the isolators' damping in play
    with pytest.raises(SolverError, match=r"did not converge in 2 iterations.*tolerance 0.001"):
        effective_linearization_loop(linearize, settings, [(m, 0) for m in range(4)], [0.1] * 4, max_iterations=2)


# --- end to end ----------------------------------------------------------------------------------------------

@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_a_scenario_with_a_spectrum_runs_stores_and_reads_back(tmp_path):
    from sixdof import run_scenario
    from sixdof.io.store import load_results

    path = tmp_path / "case.toml"
    path.write_text(_scenario(f'{_EC8}\ndirections = ["x", "y", "z"]\ndirectional = "100-30"'), encoding="utf-8")
    results, folder = run_scenario(path, tmp_path / "out", log=lambda *_: None, progress=False)
    assert (folder / "spectrum.png").exists()
    assert "Response spectrum" in (folder / "summary.md").read_text(encoding="utf-8")
    stored = load_results(folder / "results.h5").spectrum
    T = 1 / 0.8
    assert stored.direction == ("x", "y", "z")
    assert stored.peak_q[0, 0] == pytest.approx(_se(T) * (T / (2 * math.pi)) ** 2, rel=RTOL_LINALG)
    for name in ("peak_q", "combined_q", "combined_mount_force", "combined_base_shear", "effective_mass", "curve"):
        assert np.array_equal(getattr(stored, name), getattr(results.spectrum, name)), name
    assert stored.directional == "100-30" and stored.spectrum.startswith("EN 1998-1:2004 elastic spectrum")
    # sixdof plot draws a spectrum run's figures again, as the run drew them.
    from sixdof.cli import main

    assert main(["plot", str(folder / "results.h5"), "--out", str(tmp_path / "redrawn")]) == 0
    drawn = sorted(p.name for p in folder.glob("*.png"))
    assert "spectrum.png" in drawn and sorted(p.name for p in (tmp_path / "redrawn").glob("*.png")) == drawn
    assert (tmp_path / "redrawn" / "spectrum.png").read_bytes() == (folder / "spectrum.png").read_bytes()


def test_the_figure_marks_each_responding_mode():
    from sixdof.plots import plot_spectrum

    system = _body_on(_stiffness_for(1.0), _stiffness_for(1.05), angle=math.radians(30.0))
    fig = plot_spectrum(response_spectrum(system, _ec8(directions=("x", "z"))), name="case")
    ax = fig.axes[0]
    labels = [t.get_text() for t in ax.texts]
    assert any(label.startswith("modes 1 (x)") or label == "mode 1 (x)" for label in labels), labels
    assert ax.get_xlabel() == "period T [s]" and "m/s²" in ax.get_ylabel()

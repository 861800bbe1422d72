"""Transmissibility and isolation at the operating frequencies (issue 49, items 1 and 3): the curves and the
efficiency against the single-DOF closed form, the isolation region's start against the natural frequencies
and modal effective masses, transmissibility.png's content read from the figure, and the isolation summary
that ``sixdof run`` prints first and ``summary.md`` starts with."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from matplotlib.patches import Rectangle

from figures import frozen_tick_difference
from sixdof.analysis.isolation_summary import (
    EXCITED_FRACTION,
    has_operating,
    isolation_summary,
    participation,
    run_isolation_summary,
)
from sixdof.errors import InputError
from sixdof.io.console import run_text
from sixdof.io.isolation_report import ISOLATION_SUMMARY
from sixdof.io.report import summary_markdown
from sixdof.plots import figure_names, plot_transmissibility
from sixdof.plots.transmissibility import LABELS
from systems import four_mount, sdof
from tolerances import RTOL_LINALG

MASS, STIFFNESS = 120.0, 4.0e5
F_N = math.sqrt(STIFFNESS / MASS) / (2 * math.pi)
SCENARIOS = Path(__file__).resolve().parents[1] / "scenarios"


def closed_form(r, zeta):
    """Force (and absolute motion) transmissibility of a mass on a spring and dashpot at ``r = f / f_n``."""
    return np.sqrt(1 + (2 * zeta * r) ** 2) / np.sqrt((1 - r**2) ** 2 + (2 * zeta * r) ** 2)


@pytest.mark.parametrize("zeta", [0.02, 0.1, 0.3])
def test_a_single_dof_has_the_closed_form_transmissibility_and_efficiency(zeta):
    system = sdof(MASS, STIFFNESS, 2 * zeta * math.sqrt(STIFFNESS * MASS))
    r = np.geomspace(0.05, 20.0, 400)
    operating = np.array([0.5, 2.5]) * F_N  # one below resonance, one well above it
    applied = np.array([[0, 0, 1e3, 0, 0, 0], [0, 0, 1e3j, 0, 0, 0]])  # the same pattern (a quarter period apart)
    summary = isolation_summary(system, system.modes, r * F_N, operating, applied, [0.0, 0.0, 1.0], operating)
    (load,), motion = summary.loads, summary.motion
    assert load.kind == "force" and motion.kind == "motion"
    for curve in (load, motion):  # the absolute motion's ratio is the force's, for a single DOF
        np.testing.assert_allclose(curve.values, closed_form(r, zeta), rtol=RTOL_LINALG)
        np.testing.assert_allclose(curve.operating_hz, operating)
        np.testing.assert_allclose(curve.efficiency, 1 - closed_form(np.array([0.5, 2.5]), zeta), rtol=RTOL_LINALG)
        assert curve.efficiency[0] < 0 < curve.efficiency[1]  # amplified below sqrt(2), isolated above
        # Only the z mode is excited (the five others are free rigid-body motions the load does not drive).
        z_mode = int(np.argmax(system.modes.frequency_hz))
        assert curve.excited_modes == (z_mode,)
        assert curve.isolation_hz == pytest.approx(math.sqrt(2) * F_N, rel=RTOL_LINALG)
    # |T| = 1 exactly at sqrt(2) f_n whatever the damping: the region's start.
    at = isolation_summary(system, system.modes, [math.sqrt(2) * F_N], [F_N], applied[:1]).loads[0]
    assert at.values[0] == pytest.approx(1.0, rel=RTOL_LINALG)


def test_the_isolation_region_starts_above_the_modes_the_load_excites():
    # Pitch inertia such that the mounts' shear couples x and ry strongly (17 % of the x mass in the upper mode).
    system = four_mount(m=500.0, J=(200.0, 200.0, 300.0), k=(2e5, 3e5, 8e5), damping=(300.0, 300.0, 600.0))
    modes = system.modes
    f = np.geomspace(0.5, 200.0, 50)
    # A vertical force at the CG of the doubly symmetric body drives the bounce mode alone: sqrt(2) f_z.
    bounce = isolation_summary(system, modes, f, [30.0], [[0, 0, 1.0, 0, 0, 0]]).loads[0]
    f_z = math.sqrt(4 * 8e5 / 500.0) / (2 * math.pi)
    assert modes.frequency_hz[list(bounce.excited_modes)] == pytest.approx([f_z], rel=RTOL_LINALG)
    assert bounce.isolation_hz == pytest.approx(math.sqrt(2) * f_z, rel=RTOL_LINALG)
    # A lateral force at the CG: the shares are the modal effective-mass fractions along x (computed apart by
    # the modal analysis), and the region starts above the highest mode holding 5 % or more of them.
    lateral = isolation_summary(system, modes, f, [30.0], [[1.0, 0, 0, 0, 0, 0]]).loads[0]
    fractions = modes.effective_mass[0] / 500.0
    np.testing.assert_allclose(lateral.participation, fractions, rtol=1e-9, atol=1e-12)
    excited = np.flatnonzero(fractions >= EXCITED_FRACTION)
    assert lateral.excited_modes == tuple(excited) and len(excited) == 2  # x coupled with ry (mounts below the CG)
    assert lateral.isolation_hz == pytest.approx(math.sqrt(2) * modes.frequency_hz[excited].max(), rel=RTOL_LINALG)
    # A rotating load's shares add its two phases' and sum to 1.
    shares = participation(modes, system.M, [0, 1.0, 1.0j, 0.3, 0, 0])
    assert shares.sum() == pytest.approx(1.0, rel=RTOL_LINALG)
    with pytest.raises(InputError, match="applied"):
        isolation_summary(system, modes, f, [30.0, 40.0], [[1.0, 0, 0, 0, 0, 0]])


def test_on_maxwell_mounts_the_region_starts_above_the_full_models_resonances():
    # Elastomer mounts stiffer at their resonances than at rest: the undamped modes of the long-term stiffness lie
    # 11-15 % below the peaks; the region (and the marks) start from where the curve peaks, the full model's poles.
    from sixdof.io.scenario import load_scenario
    from sixdof.workflows.prepare import prepare

    system = prepare(load_scenario(SCENARIOS / "equipment_elastomer.toml")).system
    modes = system.modes
    f = np.geomspace(2.0, 60.0, 6000)
    summary = isolation_summary(system, modes, f, [48.33], [[0, 0, 1.0, 0, 0, 0]])
    bounce = summary.loads[0]
    r = int(np.argmax(bounce.participation))  # the vertical force drives the bounce mode
    peak = f[np.argmax(bounce.values)]
    assert summary.natural_hz[r] == pytest.approx(peak, rel=0.01)
    assert modes.frequency_hz[r] < 0.9 * peak
    assert bounce.isolation_hz == pytest.approx(math.sqrt(2) * summary.natural_hz[list(bounce.excited_modes)].max(),
                                                rel=RTOL_LINALG)
    # Without branches the natural frequencies are the modes' own.
    plain = four_mount(m=500.0, k=(2e5, 3e5, 8e5), damping=(300.0, 300.0, 600.0))
    np.testing.assert_array_equal(isolation_summary(plain, plain.modes, f, [30.0], [[0, 0, 1.0, 0, 0, 0]]).natural_hz,
                                  plain.modes.frequency_hz)


def test_a_torque_and_a_ground_motion_get_their_own_panels():
    system = four_mount(m=500.0, k=(2e5, 3e5, 8e5), damping=(300.0, 300.0, 600.0))
    f_z = math.sqrt(4 * 8e5 / 500.0) / (2 * math.pi)  # the bounce mode, decoupled: a single DOF
    zeta = 4 * 600.0 / (2 * math.sqrt(4 * 8e5 * 500.0))
    f = np.geomspace(0.1, 10.0, 200) * f_z
    torque = [[0, 0, 0, 0, 50.0, 0]]  # about y at the CG: no force applied, the moments' ratio
    summary = isolation_summary(system, system.modes, f, [3 * f_z], torque, [0, 0, 1.0], [2 * f_z])
    assert [c.kind for c in summary.curves] == ["moment", "motion"]
    assert summary.loads[0].values[0] == pytest.approx(1.0, rel=1e-2)  # quasi-static: the mounts carry it all
    fig = plot_transmissibility(summary, system.modes)
    assert [ax.get_ylabel() for ax in fig.axes] == [LABELS["moment"], LABELS["motion"]]
    assert fig.axes[-1].get_xlabel() == "frequency [Hz]" and fig.axes[0].get_xlabel() == ""
    (motion,) = [line for line in fig.axes[1].get_lines() if line.get_label() == "CG / ground translation"]
    np.testing.assert_allclose(motion.get_ydata(), closed_form(f / f_z, zeta), rtol=RTOL_LINALG)
    (note,) = [t.get_text() for t in fig.axes[1].texts if t.get_text().startswith("operating")]
    assert note.endswith(f"isolation {100 * (1 - closed_form(2.0, zeta)):.1f} %")
    assert summary.motion.isolation_hz == pytest.approx(math.sqrt(2) * f_z, rel=RTOL_LINALG)


@pytest.fixture(scope="module")
def unbalanced(tmp_path_factory):
    """machine_unbalance, its mounts given a 4 mm deflection limit along w (to see a margin)."""
    from sixdof.workflows.run import run

    text = (SCENARIOS / "machine_unbalance.toml").read_text()
    text = text.replace("damping = [", "max_deflection = [inf, inf, 0.004]\ndamping = [")
    path = tmp_path_factory.mktemp("unbalance") / "machine_unbalance.toml"
    path.write_text(text)
    return run(path)


@pytest.mark.long
def test_transmissibility_png_marks_the_operating_frequency_its_efficiency_and_the_isolation_region(unbalanced):
    assert has_operating(unbalanced) and "transmissibility.png" in figure_names(unbalanced)
    summary = run_isolation_summary(unbalanced)
    (curve,) = summary.loads
    steady = unbalanced.steady_state
    # The curve read off at the operating frequency is the steady state's transmissibility.
    np.testing.assert_allclose(curve.at_operating, steady.transmissibility, rtol=RTOL_LINALG)
    fig = plot_transmissibility(summary, unbalanced.modes, name="machine_unbalance")
    (ax,) = fig.axes
    assert ax.get_xscale() == ax.get_yscale() == "log"
    assert ax.get_xlabel() == "frequency [Hz]"
    assert ax.get_ylabel() == LABELS["force"] == "force transmissibility |F_foundation / F_applied| [1]"
    (drawn,) = [line for line in ax.get_lines() if line.get_label() == "force on the foundation / applied force"]
    np.testing.assert_allclose(drawn.get_ydata(), curve.values)
    f_op = steady.f_hz[0]
    verticals = [line for line in ax.get_lines() if line.get_linestyle() == "-." and line.get_color() == "tab:red"]
    assert [line.get_xdata()[0] for line in verticals] == [f_op]
    efficiency = f"isolation {100 * steady.isolation_efficiency[0]:.1f} %"
    (note,) = [t.get_text() for t in ax.texts if t.get_text().startswith("operating")]
    assert note == f"operating {f_op:.4g} Hz\n|T| = {steady.transmissibility[0]:.3g}, {efficiency}"
    (span,) = [p for p in ax.patches if p.get_label().startswith("isolation region")]
    highest = max(unbalanced.modes.frequency_hz[list(curve.excited_modes)])
    low, high = (span.get_x(), span.get_x() + span.get_width()) if isinstance(span, Rectangle) else (
        span.get_xy()[:, 0].min(), span.get_xy()[:, 0].max())
    assert low == pytest.approx(math.sqrt(2) * highest, rel=RTOL_LINALG) and high == curve.f_hz[-1]
    assert low < f_op  # 24.67 Hz is isolated
    assert fig.texts[0].get_text() == "machine_unbalance: transmissibility and isolation at the operating frequencies"
    # render()'s frozen ticks draw the figure matplotlib's own tick objects draw (as test_plots checks the others).
    assert frozen_tick_difference(lambda: plot_transmissibility(summary, unbalanced.modes)).max() <= 1.01 / 255


@pytest.mark.long
def test_the_run_text_and_summary_start_with_the_isolation_summary(unbalanced):
    steady = unbalanced.steady_state
    lines = run_text(unbalanced).splitlines()
    assert lines[2] == f"{ISOLATION_SUMMARY}:"
    assert lines[3].startswith("Natural frequencies against the operating frequencies")
    assert lines[4].split("|")[1:-1] == [" mode # ", " f_n [Hz] ", " dominant DOF ", " excited ", " r = 24.67 Hz / f_n "]
    modes = unbalanced.modes
    first = lines[6].split("|")
    assert float(first[2]) == pytest.approx(modes.frequency_hz[0], rel=1e-4)
    assert float(first[5]) == pytest.approx(steady.f_hz[0] / modes.frequency_hz[0], rel=1e-2)
    cells = {row[1].strip(): [c.strip() for c in row[2:-1]] for row in (line.split("|") for line in lines)
             if len(row) > 2}
    assert cells["isolation efficiency (force)"] == [f"{100 * steady.isolation_efficiency[0]:.1f} %"]
    assert cells["force on the foundation [N]"] == [f"{steady.transmitted_force[0]:.4g}"]
    assert cells["isolation region from [Hz] (force)"] == [f"{run_isolation_summary(unbalanced).loads[0].isolation_hz:.4g} (in it)"]
    # Mount margins against the 4 mm limit along w: 1 - |peak w| / limit.
    check = unbalanced.mount_check
    peak = abs(check.peak_deflection[0, 2])
    (row,) = [line for line in lines if line.startswith(f"| {check.names[0]} ")][:1]
    assert f"{1e3 * peak:.4g} (w)" in row and f"{100 * (1 - peak / 0.004):.0f} %" in row
    (point,) = [line for line in lines if line.startswith("| top_corner ")][:1]
    assert f"{np.max(np.abs(unbalanced.points['top_corner'].acceleration)):.4g}" in point
    # The details and solver checks come after, in their own section.
    assert lines.index("Details and solver checks:") > lines.index(point)
    markdown = summary_markdown(unbalanced).splitlines()
    assert markdown[:5] == ["# machine_unbalance", "", unbalanced.scenario.description, "", f"## {ISOLATION_SUMMARY}"]
    assert markdown.index(f"## {ISOLATION_SUMMARY}") < markdown.index("## Natural frequencies")

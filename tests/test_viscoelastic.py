"""Generalized Maxwell mount models: the complex stiffness against its closed form, fits that recover a known
model, the causal model nearest a constant loss factor against the Kramers-Kronig trade-off, bad data refused,
and the figure."""

import numpy as np
import pytest
from matplotlib.figure import Figure

from sixdof.errors import InputError
from sixdof.model.viscoelastic import constant_loss_model, fit_maxwell, maxwell_stiffness, read_dynamic_stiffness
from sixdof.plots.viscoelastic import plot_dynamic_stiffness
from tolerances import RTOL_FRF_CLOSED_FORM

# A fit to data of a model whose relaxation times lie on the fit's grid is exact: nnls on ~60 equations of
# order-one entries, so round-off (measured ~4e-15).
RTOL_FIT_EXACT = 1e-8
# Worst modulus [-] and loss angle [deg] errors of fits to a 3-branch model (peak loss factor ~0.3) whose
# relaxation frequencies lie at geometric midpoints of the fit's grid, the worst place for them, over two
# decades: with the default 2 terms per decade (5) measured 1.3e-2 and 0.69 deg, with 4 per decade (9)
# 8.5e-4 and 0.031 deg.
OFF_GRID_ERRORS = {None: (2e-2, 1.0), 9: (2e-3, 0.1)}
# The errors a fit reports against those recomputed here from its parameters: a few float64 operations.
RTOL_REPORTED = 1e-12


def closed_form(f_hz, long_term, stiffness, tau):
    """Storage and loss stiffness [N/m] of a generalized Maxwell model, written out branch by branch."""
    wt = 2 * np.pi * np.asarray(f_hz)[:, None] * tau
    return long_term + np.sum(stiffness * wt**2 / (1 + wt**2), axis=1), np.sum(stiffness * wt / (1 + wt**2), axis=1)


def test_one_branch_against_closed_form():
    k0, k, tau = 2e5, 8e5, 1e-3
    corner = 1 / (2 * np.pi * tau)  # w tau = 1
    at_corner = maxwell_stiffness(corner, k0, [k], [tau])
    assert at_corner.real == pytest.approx(k0 + k / 2, rel=RTOL_FRF_CLOSED_FORM)
    assert at_corner.imag == pytest.approx(k / 2, rel=RTOL_FRF_CLOSED_FORM)
    limits = maxwell_stiffness([0.0, 1e-9 * corner, 1e12 * corner], k0, [k], [tau])
    assert limits[0] == k0
    np.testing.assert_allclose(limits[1:].real, [k0, k0 + k], rtol=RTOL_FRF_CLOSED_FORM)
    np.testing.assert_allclose(limits[1:].imag, [k * 1e-9, k * 1e-12], rtol=RTOL_FRF_CLOSED_FORM)  # k / (w tau) far up
    f = np.geomspace(1.0, 1e4, 7)
    storage, loss = closed_form(f, k0, [k], [tau])
    np.testing.assert_allclose(maxwell_stiffness(f, k0, [k], [tau]), storage + 1j * loss, rtol=RTOL_FRF_CLOSED_FORM)
    assert maxwell_stiffness(np.ones((2, 3)), k0, [k], [tau]).shape == (2, 3)


def test_fit_recovers_a_model_on_its_grid():
    f = np.geomspace(5.0, 500.0, 30)
    tau = 1 / (2 * np.pi * np.geomspace(5.0, 500.0, 5))
    k = np.array([1e5, 3e5, 0.0, 2e5, 5e4])
    storage, loss = closed_form(f, 4e5, k, tau)
    fit = fit_maxwell(f, storage, loss / storage, 5)
    np.testing.assert_allclose(fit.tau, tau, rtol=RTOL_FRF_CLOSED_FORM)
    assert fit.long_term == pytest.approx(4e5, rel=RTOL_FIT_EXACT)
    np.testing.assert_allclose(fit.stiffness, k, rtol=RTOL_FIT_EXACT, atol=RTOL_FIT_EXACT * k.max())
    assert fit.modulus_error < RTOL_FIT_EXACT and fit.loss_angle_error_deg < RTOL_FIT_EXACT
    assert fit.band_hz == (5.0, 500.0)


@pytest.mark.parametrize("terms", OFF_GRID_ERRORS)
def test_fit_reproduces_a_model_off_its_grid(terms):
    f = np.geomspace(5.0, 500.0, 30)
    grid = np.geomspace(5.0, 500.0, terms or 5)  # terms=None over two decades: 1 + 2 per decade
    tau = 1 / (2 * np.pi * np.sqrt(grid[:-1] * grid[1:])[[0, 2, 3]])
    storage, loss = closed_form(f, 4e5, np.array([2e5, 3e5, 1e5]), tau)
    fit = fit_maxwell(f, storage, loss / storage, terms)
    np.testing.assert_allclose(fit.tau, 1 / (2 * np.pi * grid), rtol=RTOL_FRF_CLOSED_FORM)
    modulus_error, angle_error_deg = OFF_GRID_ERRORS[terms]
    assert modulus_error / 100 < fit.modulus_error < modulus_error  # not exact: the data are off the grid
    assert fit.loss_angle_error_deg < angle_error_deg
    assert np.all(fit.stiffness >= 0) and fit.long_term >= 0


@pytest.mark.parametrize("decades", [1, 2])
@pytest.mark.parametrize("eta", [0.1, 0.2])
def test_constant_loss_model_against_kramers_kronig(eta, decades):
    k, band = 1e6, (10.0, 10.0 * 10**decades)
    model = constant_loss_model(k, eta, band)
    assert model.band_hz == pytest.approx(band) and model.f_hz.size == 20 * decades + 1
    np.testing.assert_array_equal(model.storage, k)
    storage, loss = closed_form(model.f_hz, model.long_term, model.stiffness, model.tau)
    modulus_error = np.max(np.abs(np.hypot(storage, loss) / (k * np.hypot(1, eta)) - 1))
    angle_error = np.max(np.abs(np.arctan2(loss, storage) - np.arctan(eta)))
    assert model.modulus_error == pytest.approx(modulus_error, rel=RTOL_REPORTED)
    assert model.loss_angle_error_deg == pytest.approx(np.degrees(angle_error), rel=RTOL_REPORTED)

    delta = np.arctan(eta)
    rise = 10 ** (2 * delta / np.pi * decades)  # |K| over the band of the constant-phase (fractional) spring
    assert modulus_error < (rise - 1) / (rise + 1)  # better in |K| than the best-scaled fractional spring ...
    assert angle_error < delta  # ... and in loss angle than a pure spring
    assert model.long_term > 0.5 * k  # the static stiffness stays with the long-term spring


def test_the_fits_table_names_the_fits_beyond_a_measured_table_s_limits():
    import dataclasses

    from sixdof.io.report import viscoelastic_table

    close = dataclasses.replace(constant_loss_model(1e6, 0.02, (10.0, 100.0)), name="a w")
    wide = dataclasses.replace(constant_loss_model(1e6, 0.2, (1.0, 1000.0)), name="b u")
    assert close.modulus_error < 0.05 and close.loss_angle_error_deg < 1 and wide.modulus_error > 0.05
    assert "Note" not in viscoelastic_table([close])
    text = viscoelastic_table([close, wide])
    table, note = text.split("\n\n")  # a paragraph of its own, not a row of the Markdown table
    assert note.startswith("Note: b u miss what they model by up to ")
    assert f"{100 * wide.modulus_error:.3g} % in |K*| and {wide.loss_angle_error_deg:.3g} deg" in note.replace("\n", " ")


def write(tmp_path, rows, header="f [Hz], K' [N/m], loss factor [-]"):
    path = tmp_path / "mount.csv"
    path.write_text("\n".join([header, *rows]) + "\n")
    return path


def test_read_dynamic_stiffness(tmp_path):
    path = write(tmp_path, ["# measured at 20 degC", "10, 1.0e6, 0.10", "", "100, 1.2e6, 0.12", "1000, 1.5e6, 0.15"])
    f, storage, loss = read_dynamic_stiffness(path, "mounts[0].dynamic_stiffness.file")
    np.testing.assert_array_equal(f, [10, 100, 1000])
    np.testing.assert_array_equal(storage, [1.0e6, 1.2e6, 1.5e6])
    np.testing.assert_array_equal(loss, [0.10, 0.12, 0.15])
    fit = fit_maxwell(f, storage, loss)
    assert fit.stiffness.size == 3 and fit.band_hz == (10.0, 1000.0)


FIELD = r"mounts\[0\]\.dynamic_stiffness\.file: expected "


@pytest.mark.parametrize(("rows", "match"), [
    (["10, 1e6, 0.1", "100, -2e6, 0.1"], r"storage stiffness K' > 0 N/m, got line 3 of .*mount.csv: \[100.0, -2000000.0"),
    (["10, 1e6, 0.1", "10, 1e6, 0.1"], r"strictly increasing frequencies, got line 3 of "),
    (["100, 1e6, 0.1", "10, 1e6, 0.1"], r"strictly increasing frequencies, got line 3 of "),
    (["0, 1e6, 0.1", "10, 1e6, 0.1"], r"frequencies > 0 Hz, got line 2 of "),
    (["10, 1e6, 0.1"], r"at least 2 rows, got a single point in .*mount.csv"),
    ([], r"at least 2 rows, got no data rows in "),
    (["10, 1e6, 0.1", "100, 1e6, -0.01"], r"loss factor >= 0, got line 3 of "),
    (["10, 1e6, 0.1", "100, 1e6, abc"], r"loss factor, got line 3 of .*mount.csv, field 3: ' abc'$"),
    (["10, 1e6, 0.1", "100, 1e6"], r"loss factor, got line 3 of .*mount.csv: 2 fields$"),
    (["10, 1e6, 0.1", "100, 1e6, 0.1, 7"], r"loss factor, got line 3 of .*mount.csv: 4 fields$"),
    (["10, 1e6, 0.1", "100, inf, 0.1"], r"loss factor, got line 3 of .*mount.csv, field 2: ' inf'$"),
])
def test_bad_tables_refused(tmp_path, rows, match):
    with pytest.raises(InputError, match=FIELD + r"a UTF-8 CSV file .*" + match):
        read_dynamic_stiffness(write(tmp_path, rows), "mounts[0].dynamic_stiffness.file")


def test_unreadable_files_refused(tmp_path):
    with pytest.raises(InputError, match=FIELD + r"an existing, readable CSV file, got '.*nope.csv'"):
        read_dynamic_stiffness(tmp_path / "nope.csv", "mounts[0].dynamic_stiffness.file")
    binary = tmp_path / "binary.csv"
    binary.write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(InputError, match=FIELD + r"a UTF-8 CSV file, got .*binary.csv: 'utf-8' codec can't decode byte 0xff on line 1"):
        read_dynamic_stiffness(binary, "mounts[0].dynamic_stiffness.file")


def test_bad_fit_arguments_refused():
    f, storage, loss = np.array([10.0, 100.0, 1000.0]), np.full(3, 1e6), np.full(3, 0.1)
    with pytest.raises(InputError, match=r"mount\.terms: expected at most 3 Maxwell branches \(one per data point\), got 4"):
        fit_maxwell(f, storage, loss, 4, field="mount")
    for terms in (0, 2.0, True):
        with pytest.raises(InputError, match=rf"dynamic_stiffness\.terms: expected a positive number .*got {terms}"):
            fit_maxwell(f, storage, loss, terms)
    with pytest.raises(InputError, match=r"dynamic_stiffness\.storage: expected storage stiffness K' > 0 N/m, got "
                                         r"storage\[1\] = -1e\+06"):
        fit_maxwell(f, storage * [1, -1, 1], loss)
    with pytest.raises(InputError, match=r"dynamic_stiffness\.f_hz: expected strictly increasing frequencies, got "
                                         r"f_hz\[2\] = 10"):
        fit_maxwell([10.0, 100.0, 10.0], storage, loss)
    with pytest.raises(InputError, match=r"dynamic_stiffness\.loss_factor: expected loss factor >= 0"):
        fit_maxwell(f, storage, -loss)
    with pytest.raises(InputError, match=r"dynamic_stiffness: expected .*one length >= 2 \(a single point cannot be "
                                         r"fitted\), got lengths \[1, 1, 1\]"):
        fit_maxwell([10.0], [1e6], [0.1])
    with pytest.raises(InputError, match=r"dynamic_stiffness\.f_hz: expected a 1-D array of finite frequencies in Hz"):
        fit_maxwell([10.0, np.nan, 1000.0], storage, loss)
    with pytest.raises(InputError, match=r"terms: expected a positive number of Maxwell branches, got 0"):
        constant_loss_model(1e6, 0.1, (10.0, 100.0), terms=0)
    with pytest.raises(InputError, match=r"check_hz: expected frequencies within the band 10-100 Hz, got 5, 200 Hz"):
        constant_loss_model(1e6, 0.1, (10.0, 100.0), check_hz=[5.0, 20.0, 200.0])
    with pytest.raises(InputError, match=r"band_hz: expected a band \[low, high\] in Hz with 0 < low < high"):
        constant_loss_model(1e6, 0.1, (100.0, 10.0))
    with pytest.raises(InputError, match=r"loss_factor: expected a loss factor >= 0, got -0.1"):
        constant_loss_model(1e6, -0.1, (10.0, 100.0))


def test_dynamic_stiffness_figure():
    measured = constant_loss_model(1e6, 0.15, (5.0, 500.0))
    fig = plot_dynamic_stiffness([("constant η = 0.15", measured),
                                  ("one decade", constant_loss_model(1e6, 0.15, (5.0, 50.0)))], title="mounts")
    assert isinstance(fig, Figure) and fig._suptitle.get_text() == "mounts"
    top, bottom = fig.axes
    assert top.get_shared_x_axes().joined(top, bottom) and bottom.get_xscale() == "log"
    assert top.get_yscale() == "log" and bottom.get_yscale() == "linear"
    assert top.get_ylabel() == "storage stiffness K' [N/m]" and "loss factor" in bottom.get_ylabel()
    assert bottom.get_xlabel() == "frequency f [Hz]"
    (legend,) = fig.legends  # below the axes, where it hides no curve
    texts = [t.get_text() for t in legend.get_texts()]
    assert len(texts) == 2 and texts[0].endswith(f"worst errors {100 * measured.modulus_error:.2g} % in |K*|, "
                                                 f"{100 * measured.loss_factor_error:.2g} % in loss factor")
    assert "loss angle" not in texts[0] and "constant loss factor at the natural and operating frequencies" in top.get_title()
    line, markers = top.lines[0], top.lines[1]  # the first fit: its model, then its data
    assert line.get_xdata()[0] == pytest.approx(2.5) and line.get_xdata()[-1] == pytest.approx(1000.0)
    np.testing.assert_allclose(line.get_ydata(), measured.dynamic_stiffness(line.get_xdata()).real, rtol=1e-12)
    np.testing.assert_array_equal(markers.get_xdata(), measured.f_hz)
    assert markers.get_color() == line.get_color() != top.lines[2].get_color()
    with pytest.raises(InputError, match=r"fits: expected a non-empty sequence of \(label, .*MaxwellFit\) pairs"):
        plot_dynamic_stiffness([measured])


def test_a_high_loss_factor_keeps_its_damping_in_the_causal_model():
    """eta = 1 over 1:4 cannot be held causally to the targets, but the minimax model keeps most of it (its
    complex stiffness evaluated here from its branches): the modulus bounds are the annular sector's, not a
    bound that grows with the loss factor's own slack (which had left 0.16-0.23)."""
    check = np.geomspace(5.0, 20.0, 5)
    fit = constant_loss_model(1e5, 1.0, (2.5, 40.0), check_hz=check)
    w = 2j * np.pi * check[:, None]
    k = fit.long_term + np.sum(fit.stiffness * w * fit.tau / (1 + w * fit.tau), axis=1)
    assert np.all(k.imag / k.real > 0.6)
    assert fit.loss_factor_error == pytest.approx(np.max(np.abs(k.imag / k.real - 1)), rel=1e-9)


def test_mount_axes_of_one_loss_factor_share_one_fit_scaled_by_their_stiffness():
    """The causal model of k (1 + i eta) is k times that of 1 + i eta: axes of one loss factor and any stiffness
    get one fit, scaled, with the same relative errors; a lone fit of each axis gives the same model."""
    from sixdof.model.parts import Mount, RigidBody
    from sixdof.model.system import System
    from sixdof.model.viscoelastic import causal_loss_factors, checked_frequencies, loss_band

    mounts = [Mount(n, p, k, loss_factor=[0.1, 0.1, 0.1]) for n, p, k in
              (("a", [0.4, 0.3, -0.2], [2e5, 3e5, 8e5]), ("b", [-0.5, 0.35, -0.25], [1e5, 1e5, 6e5]),
               ("c", [0.1, -0.45, -0.3], [3e5, 2e5, 9e5]))]
    system = System(RigidBody(50.0, [3.0, 4.0, 5.0]), mounts)
    _, fits = causal_loss_factors(system)
    assert len(fits) == 9 and len({(f.modulus_error, f.loss_factor_error) for f in fits}) == 1
    lone = constant_loss_model(6e5, 0.1, loss_band(system), check_hz=checked_frequencies(system))
    (b_w,) = [f for f in fits if f.name == "b w"]
    np.testing.assert_allclose(b_w.dynamic_stiffness(lone.f_hz), lone.dynamic_stiffness(lone.f_hz), rtol=1e-6)

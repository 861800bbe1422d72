"""The modal results against time histories: H1 estimates of each mode's FRF from random runs, and
free decays from each damped (complex) mode shape (see :func:`sixdof.validation.validate`)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure

from sixdof.errors import InputError, Plain
from sixdof.plots.common import figure, margins, panel_grid, plot_long, require, title
from sixdof.validation import ValidationReport

if TYPE_CHECKING:  # sixdof.validation loads scipy.signal (about a second): imported where drawn
    from sixdof.validation import ValidationReport


def _by_mode(report: ValidationReport, field: str, expected: str) -> tuple[list, dict]:
    """The report's ``field`` sorted by mode, and the validation table's row (ModeCheck) of each mode."""
    require(report, "report", ValidationReport, "a sixdof.validation.ValidationReport")
    items = sorted(getattr(report, field), key=lambda item: item.mode)
    if not items:
        raise InputError(f"report.{field}", expected, Plain("none"))
    return items, {int(row.mode): row for row in report.rows}


def plot_validation_frf(report: ValidationReport, *, name: str = "", fig: Figure | None = None) -> Figure:
    """H1 estimate (random run) against the model FRF of each mode's modal coordinate, one panel
    per mode over its band, with the natural frequency and the estimate's peak marked and the
    coherence below.

    Parameters
    ----------
    report : sixdof.validation.ValidationReport
        Its ``random_runs`` (one per mode: band [Hz], H1 estimate and coherence, held model FRF,
        both in kg^1/2 m/N) are drawn; its ``rows`` give the natural frequency, the H1 peak [Hz]
        and the median H1 error of each mode.
    name : str
        Name of the run, put before the title.
    fig : matplotlib.figure.Figure, optional
        An empty figure to draw into, given the layout's size (:func:`~sixdof.plots.common.figure`); default a new
        one. Layout: one column per mode (its FRF estimate above its coherence), up to a few columns a row.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    sixdof.errors.InputError
        When the report has no random runs.
    """
    runs, rows = _by_mode(report, "random_runs", "at least one random run")
    columns, grid = panel_grid(len(runs))
    # The top margin holds the figure's title above the first row's two-line panel titles.
    fig = figure(fig, (5.0 * columns, 4.6 * grid + 0.35))
    fig.suptitle(title(name, "modal FRFs: H1 estimate from a random force vs the model"), fontsize=12)
    cells = fig.add_gridspec(grid, columns)
    margins(fig, left=1.0, right=0.15, top=0.95, bottom=0.5, wspace=1.15, hspace=1.2, columns=columns, rows=grid,
            target=cells)
    for k, run in enumerate(runs):
        mode = int(run.mode)
        f = run.estimated.f_hz
        H1, coherence, model = (np.asarray(values).reshape(len(f), -1)[:, 0]
                                for values in (run.estimated.H1, run.estimated.coherence, run.model))
        band = run.band_hz
        keep = (f > 0) if band is None else (f >= band[0]) & (f <= band[1])
        cell = cells[k // columns, k % columns].subgridspec(2, 1, height_ratios=[3, 1], hspace=0.08)
        mag = fig.add_subplot(cell[0])
        coh = fig.add_subplot(cell[1], sharex=mag)
        mag.tick_params(labelbottom=False)
        mag.semilogy(f[keep], np.abs(H1[keep]), color="tab:grey", marker=".", markersize=4, linewidth=0.6,
                     label="H1 estimate")
        if run.model_curve is not None:  # the model on its own fine grid; at the estimate's bins a peak is a polygon
            mag.semilogy(run.model_f_hz, np.abs(run.model_curve), color="black", linewidth=1.2, label="model")
        else:
            mag.semilogy(f[keep], np.abs(model[keep]), color="black", linewidth=1.2, label="model")
        heading = f"mode {mode}"
        if mode in rows:
            row = rows[mode]
            mag.axvline(row.f_model_hz, color="tab:blue", linestyle=":", linewidth=1.0, label="natural frequency")
            mag.axvline(row.f_peak_model_hz, color="black", linestyle="--", linewidth=0.8, label="model peak")
            mag.axvline(row.f_peak_estimated_hz, color="tab:red", linestyle="--", linewidth=0.8,
                        label="H1 peak (interpolated)")
            # The peak check compares the H1 peak with the model's peak (damped), not the natural frequency.
            heading += (f": model peak {row.f_peak_model_hz:.3f} Hz, H1 peak {row.f_peak_estimated_hz:.3f} Hz"
                        f"\nmedian $|H_1 - H_{{model}}| / |H_{{model}}|$ = {row.h1_median_error:.1e}")
        mag.set_title(heading, fontsize=10)
        mag.set_ylabel(f"$|\\eta_{{{mode}}} / F|$ [kg$^{{1/2}}$ m/N]")
        mag.grid(True, which="both", alpha=0.25)
        coh.plot(f[keep], coherence[keep], color="tab:green", linewidth=0.9)
        coh.set_ylim(0, 1.05)
        coh.set_ylabel("coherence [1]")
        coh.set_xlabel("frequency f [Hz]")
        coh.grid(True, alpha=0.25)
        if band is not None:
            mag.set_xlim(band[0], band[1])  # a peak marker outside the band must not squeeze it
        if k == 0:
            mag.legend(fontsize=7)
    return fig


def plot_free_decays(report: ValidationReport, *, name: str = "", fig: Figure | None = None) -> Figure:
    """Free decay of each mode's modal coordinate after release from its shape, with the located
    extrema and the fitted exponential envelope; estimated vs model damped frequency and damping in
    each title.

    Parameters
    ----------
    report : sixdof.validation.ValidationReport
        Its ``decays`` (one per mode: times [s], modal coordinate eta [kg^1/2 m] and the decay
        estimate) are drawn; its ``rows`` give the model's damped frequency [Hz] and damping ratio.
    name : str
        Name of the run, put before the title.
    fig : matplotlib.figure.Figure, optional
        An empty figure to draw into, given the layout's size (:func:`~sixdof.plots.common.figure`); default a new
        one. Layout: one panel per mode's free decay, up to a few columns a row.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    sixdof.errors.InputError
        When the report has no free decays.
    """
    decays, rows = _by_mode(report, "decays", "at least one free decay")
    n = len(decays)
    columns, grid = panel_grid(n)
    fig = figure(fig, (5.0 * columns, 3.6 * grid + 0.25))
    fig.suptitle(title(name, "free decay from each damped mode shape: modal coordinate "
                       "$\\eta_r = \\phi_r^T M q$"), fontsize=12)
    margins(fig, left=1.0, right=0.15, top=0.85, bottom=0.5, wspace=1.1, hspace=0.95, columns=columns, rows=grid)
    axes = fig.subplots(grid, columns, squeeze=False).ravel()
    for ax, decay in zip(axes, decays):
        mode = int(decay.mode)
        estimate = decay.estimate
        t, eta = np.asarray(decay.history.t), np.asarray(decay.eta)
        peak = float(np.max(np.abs(eta))) if eta.size else 0.0
        exponent = 3 * int(np.floor(np.log10(peak) / 3)) if peak > 0 else 0  # engineering: 10^-3, 10^-6...
        unit = 10.0 ** exponent
        plot_long(ax, t, eta / unit, color="tab:blue", linewidth=1.0, label="simulated η")
        te, ve = np.asarray(estimate.extrema_t), np.asarray(estimate.extrema_value)
        ax.plot(te, ve / unit, "o", color="tab:red", markersize=3, label="extrema")
        if len(te):
            omega_d = 2 * np.pi * estimate.f_damped_hz
            sigma = estimate.zeta * omega_d / np.sqrt(1.0 - estimate.zeta ** 2)
            amplitude = np.exp(np.mean(np.log(np.abs(ve)) + sigma * te))
            for sign in (-1, 1):
                plot_long(ax, t, sign * amplitude * np.exp(-sigma * t) / unit, color="black", linestyle="--",
                          linewidth=0.8, label="fitted envelope" if sign > 0 else None)
        heading = (f"mode {mode}, fitted: $f_d$ {estimate.f_damped_hz:.5g} Hz, $\\zeta$ {estimate.zeta:.4f}"
                   if len(te) else f"mode {mode}: no decaying oscillation to fit (FAIL)")
        if mode in rows:
            row = rows[mode]
            heading += f"\nmodel: $f_d$ {row.f_damped_model_hz:.5g} Hz, $\\zeta$ {row.zeta_model:.4f}"
        ax.set_title(heading, fontsize=9)
        ax.set_xlabel("time t [s]")
        scale = f"10$^{{{exponent}}}$ " if exponent else ""
        ax.set_ylabel(f"$\\eta_{{{mode}}}$ [{scale}kg$^{{1/2}}$ m]")
        ax.grid(True, alpha=0.3)
        ax.set_xlim(t[0], t[-1])
    axes[0].legend(fontsize=7, loc="upper right")
    for ax in axes[n:]:
        ax.set_visible(False)
    return fig

"""The random-vibration figure: the input PSD with its RMS, and the response acceleration PSDs."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from sixdof.analysis.random import RandomResponse, RandomTimeCheck
from sixdof.analysis.statics import STANDARD_GRAVITY
from sixdof.dofs import AXES, DOFS
from sixdof.plots.common import (
    DOF_DIRECTIONS,
    figure,
    margins,
    merge_identical,
    plain_frequencies,
    plain_log_ticks,
    require,
    title,
)


def plot_random(random: RandomResponse, *, name: str = "", fig: Figure | None = None) -> Figure:
    """Input PSD (top, its RMS in the title) and the absolute acceleration PSDs of the CG's translations and of
    each body point along its most excited axis (bottom), log-log, with each curve's RMS in the legend.

    Parameters
    ----------
    random : sixdof.analysis.random.RandomResponse
    name : str
        Name of the run, put before the title.
    fig : matplotlib.figure.Figure, optional
        An empty figure to draw into, given the layout's size (:func:`~sixdof.plots.common.figure`); default a new
        one. Layout: the input PSD above the body's response PSDs.

    Returns
    -------
    matplotlib.figure.Figure
    """
    require(random, "random", RandomResponse, "a sixdof.analysis.random.RandomResponse")
    f = random.f_hz
    fig = figure(fig, (10, 8))
    fig.suptitle(title(name, "random vibration: input and response acceleration PSDs"), fontsize=12)
    margins(fig, left=1.0, right=0.3, top=0.75, bottom=0.6, hspace=0.9, rows=2)
    top, bottom = fig.subplots(2, 1, sharex=True)
    if random.input_kind == "force":
        top.loglog(f, random.input_psd, color="black", linewidth=1.4)
        top.set_ylabel("force PSD [N²/Hz]")
        top.set_title(f"input: force, RMS {random.input_rms:.4g} N, PSD peak {np.max(random.input_psd):.3g} N²/Hz",
                      fontsize=10)
    else:
        top.loglog(f, random.input_psd / STANDARD_GRAVITY**2, color="black", linewidth=1.4)
        top.set_ylabel("ground acceleration PSD [g²/Hz]")
        top.set_title(f"input: ground acceleration, {random.input_rms / STANDARD_GRAVITY:.3g} grms, "
                      f"PSD peak {np.max(random.input_psd) / STANDARD_GRAVITY**2:.3g} g²/Hz", fontsize=10)
    curves = [(random.qdd_psd[:, i], f"centre of gravity {DOF_DIRECTIONS[i]}", random.qdd_rms[i]) for i in range(3)
              if np.any(random.qdd_psd[:, i] > 0)]
    for name_, psd, rms in zip(random.points, random.point_acceleration_psd, random.point_acceleration_rms):
        axis = int(np.argmax(rms))
        curves.append((psd[:, axis], f"{name_} along {AXES[axis]}", rms[axis]))
    for psd, label, rms in merge_identical(curves):
        cg = label.startswith("centre of gravity")  # the body's own curves solid, the points' dashed
        bottom.loglog(f, psd / STANDARD_GRAVITY**2, linewidth=1.1, linestyle="-" if cg else "--",
                      label=f"{label}: {rms / STANDARD_GRAVITY:.3g} grms")
    if random.input_kind != "force" and bottom.get_lines():  # the isolation: response against input
        bottom.loglog(f, random.input_psd / STANDARD_GRAVITY**2, color="0.55", linewidth=1.0, linestyle=":",
                      label=f"input: {random.input_rms / STANDARD_GRAVITY:.3g} grms")
    bottom.set_ylabel("acceleration PSD [g²/Hz]")
    bottom.set_xlabel("frequency f [Hz]")
    bottom.set_title("response: absolute acceleration", fontsize=10)
    if bottom.get_lines():
        bottom.legend(fontsize=8, loc="lower left")
        # Eight decades below the largest response (an isolator's fall over the band); a weakly excited
        # DOF's tail would stretch the axis to 1e-16.
        peak = max(float(np.max(line.get_ydata())) for line in bottom.get_lines())
        bottom.set_ylim(peak * 1e-8, peak * 3)
    for ax in (top, bottom):
        ax.grid(True, which="both", alpha=0.25)
        ax.set_xlim(f[0], f[-1])
    plain_frequencies(bottom)
    # 0.01, 0.02, 0.04 g²/Hz rather than 10^-2 beside 4 x 10^-2; within about a decade 1-2-5 labels one or two
    # ticks, not a 0.04 plateau: 3 and 4 too.
    low, high = top.get_ylim()
    plain_log_ticks(top.yaxis, (1, 2, 3, 4, 5) if high <= 20 * low else (1, 2, 5))
    return fig


def plot_random_check(check, *, name: str = "", fig: Figure | None = None) -> Figure:
    """The random response against a time history: for each excited acceleration (the CG's DOFs, each point
    along its most excited axis; at most six), the record's Welch PSD over the FRFs' expected Welch PSD with
    the estimate's 90 % interval (chi-square), and both RMS values with their z in the panel's title.

    Parameters
    ----------
    check : sixdof.analysis.random.RandomTimeCheck
    name : str
        Name of the run, put before the title.
    fig : matplotlib.figure.Figure, optional
        An empty figure to draw into, given the layout's size (:func:`~sixdof.plots.common.figure`); default a new
        one. Layout: one row per point checked (the record's Welch PSD over the expected one).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from scipy.stats import chi2  # noqa: PLC0415 (scipy.stats, only for the time check's band)

    require(check, "check", RandomTimeCheck, "a sixdof.analysis.random.RandomTimeCheck")
    rms = {n.removeprefix("rms:"): j for j, n in enumerate(check.judged) if n.startswith("rms:")}
    curves = [(check.qdd_welch[:, i], f"centre of gravity {DOF_DIRECTIONS[i]}",
               (f"qdd:{dof}", check.qdd_expected[:, i], i < 3)) for i, dof in enumerate(DOFS) if f"qdd:{dof}" in rms]
    for p, point in enumerate(check.points):
        excited = [a for a in range(3) if f"point:{point}:{AXES[a]}" in rms]
        if excited:
            axis = max(excited, key=lambda a: check.frequency_rms[rms[f"point:{point}:{AXES[a]}"]])
            curves.append((check.point_welch[p, :, axis], f"{point} along {AXES[axis]}",
                           (f"point:{point}:{AXES[axis]}", check.point_expected[p, :, axis], True)))
    # Responses that are one (points moving with the CG) share a panel.
    panels = [(label, key, welch, expected, translation)
              for welch, label, (key, expected, translation) in merge_identical(curves)][:6]
    columns = 1 if len(panels) <= 3 else 2
    rows = max(1, -(-len(panels) // columns))
    fig = figure(fig, (10, 2.0 + 2.6 * rows))
    worst = check.worst
    fig.suptitle(title(name, f"random response against a {check.duration_s:.3g} s time history: {check.verdict} "
                             f"(largest |z| {abs(check.z[worst]):.2f}, limit {check.z_limit:.2f})"), fontsize=12)
    margins(fig, left=1.0, right=0.3, top=0.8, bottom=0.6, wspace=1.0, hspace=0.75, columns=columns, rows=rows)
    axes = np.atleast_1d(fig.subplots(rows, columns, sharex=True, squeeze=False)).ravel()
    nu = check.degrees_of_freedom
    low, high = chi2.ppf(0.05, nu) / nu, chi2.ppf(0.95, nu) / nu
    f = check.f_hz
    for ax, (label, key, welch, expected, translation) in zip(axes, panels):
        scale, unit = (1 / STANDARD_GRAVITY**2, "g²/Hz") if translation else (1.0, "(rad/s²)²/Hz")
        ax.fill_between(f, expected * low * scale, expected * high * scale, color="0.8", linewidth=0,
                        label="90 % interval of the estimate")
        ax.loglog(f, welch * scale, color="tab:blue", linewidth=0.9, label="time record (Welch)")
        ax.loglog(f, expected * scale, color="black", linewidth=1.2, label="from the FRFs")
        j = rms[key]
        rms_scale, unit_rms = (1 / STANDARD_GRAVITY, "grms") if translation else (1.0, "rad/s² RMS")
        ax.set_title(f"{label}: {rms_scale * check.frequency_rms[j]:.4g} (FRFs), {rms_scale * check.time_rms[j]:.4g} "
                     f"(record) {unit_rms}; z-score {check.z[j]:+.2f}", fontsize=9)
        ax.set_ylabel(f"acceleration PSD [{unit}]")
        peak = float(np.max(expected * scale))
        ax.set_ylim(peak * 1e-8, peak * 3)  # the isolators' eight decades over the band
        ax.grid(True, which="both", alpha=0.25)
    for ax in axes[len(panels):]:
        ax.set_visible(False)
    for ax in axes[len(panels) - columns:len(panels)]:  # the lowest visible panel of each column
        ax.set_xlabel("frequency f [Hz]")
        ax.xaxis.set_tick_params(labelbottom=True)
    level = check.qdd_expected.max(axis=1)
    band = check.band_hz or f[level > 1e-12 * level.max()][[0, -1]]  # a file from before band_hz: where it acts
    axes[0].set_xlim(*band)  # beyond the PSD's band the record holds only leakage and the solve's round-off
    plain_frequencies(axes[0])
    axes[0].legend(fontsize=8, loc="upper right")  # a response PSD falls above its first resonance
    return fig

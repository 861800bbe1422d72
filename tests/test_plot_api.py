"""The figure API (issue 49): every public plot function takes ``ax=`` (one panel) or ``fig=`` (several, its
layout stated in its docstring), draws there from the typed results alone, and returns the figure it drew in."""

import dataclasses
import functools
import inspect
from pathlib import Path

import numpy as np
import pytest
from matplotlib.figure import Figure

import sixdof
from sixdof import plots

SCENARIOS = Path(sixdof.__file__).parent / "scenarios"
#: Public plot functions drawing one panel: they take ``ax=``; every other takes ``fig=``.
SINGLE_PANEL = {"plot_ke_distribution", "plot_mac", "plot_spectrum", "plot_srs", "plot_stability"}
#: Multi-panel functions that fit their panels to a caller's figure, at its size, without their title; the others lay
#: their rows out in inches and give the caller's figure their size.
FITTED = {"plot_frf_overlay", "plot_mode_shapes", "plot_transmissibility", "plot_update_history"}
PLOT_FUNCTIONS = sorted(name for name in plots.__all__ if name.startswith("plot_"))


@functools.cache
def _run_parts() -> dict:
    """The typed results of one small run (tests/store_cases.py), shared by the figures of a run."""
    from store_cases import run_parts

    return run_parts()


@functools.cache
def _tap_test() -> tuple:
    """The bundled tap test, its scenario and the modes identified from it."""
    from sixdof.validation.identify import identify_modes

    tap = sixdof.load_scenario(SCENARIOS / "machine_tap_test.toml")
    test = sixdof.load_test(SCENARIOS / "machine_tap_test.uff", tap)
    return tap, test, identify_modes(test.f_hz, test.H, test.quantity, band_hz=(2.0, 40.0), max_order=24)


def _point_accelerations():
    from sixdof.analysis.response import points_motion

    response = _run_parts()["response"]
    return (points_motion(response, {"corner": [0.3, 0.2, 0.1]}), response.t), {}


def _transmissibility():
    from sixdof.analysis.isolation_summary import isolation_summary
    from systems import four_mount

    box = four_mount(m=500.0, k=(2e5, 3e5, 8e5), damping=(300.0, 300.0, 600.0))
    return (isolation_summary(box, box.modes, np.geomspace(0.5, 50.0, 200), [3.0], [[0, 0, 100.0, 0, 0, 0]]),
            box.modes), {}


def _random():
    from sixdof.analysis.random import PSD, RandomInput, random_response
    from systems import small_box

    psd = PSD(f_hz=[2.0, 20.0, 60.0], value=[0.01, 0.04, 0.02], unit="g^2/Hz")
    return (random_response(small_box(), RandomInput(input="ground_acceleration", direction=[0.0, 0.6, 0.8], psd=psd),
                            {"corner": [0.3, 0.2, 0.1]}),), {}


def _random_check():
    from sixdof.validation.random_time import random_time_check
    from systems import small_box
    from test_random_time import _force_on_the_box

    force, settings = _force_on_the_box(duration=30.0)
    return (random_time_check(small_box(zeta=0.04), force, {"corner": [0.3, 0.2, 0.1]}, settings),), {}


def _srs():
    from sixdof.analysis.srs import ShockSpectra

    return (ShockSpectra(f_hz=np.geomspace(10.0, 2000.0, 40), points=np.ones((1, 3, 40)), names=("board",), q=10.0,
                         input=np.full(40, 2.0)),), {}


def _spectrum():
    from sixdof.analysis.spectrum import response_spectrum
    from systems import small_box
    from test_spectrum import _ec8

    return (response_spectrum(small_box(), _ec8(directions=("x", "z"))),), {}


def _hysteresis():
    from test_hysteresis import SCENARIO as HYSTERETIC

    extra = 'hysteresis = { law = "bouc_wen", axes = ["u"], yield_force = [500.0], post_yield_ratio = 0.1 }'
    hysteretic = sixdof.run(sixdof.parse_scenario(HYSTERETIC.format(extra=extra)))
    return (hysteretic.system, hysteretic.response, hysteretic.mount_forces), {}


def _records():
    from test_records_run import scenario_text

    with pytest.warns(UserWarning):  # two records, fewer than EN 1998-1 asks
        records = sixdof.run(sixdof.parse_scenario(scenario_text("{ count = 2, duration = 14.0, dt = 0.02 }",
                                                                 "behaviour_factor = 1.5\n")))
    return (records.spectrum_records, records.records_check), {}


def _loss_model():
    from sixdof.model.viscoelastic import constant_loss_model

    return constant_loss_model(1e6, 0.15, (5.0, 500.0))


def _mac():
    from sixdof.validation.correlation import channel_shapes, correlate_modes

    tap, test, identified = _tap_test()
    modes = tap.system.modes
    return (correlate_modes(identified.modes.frequency_hz, identified.modes.damping_ratio, identified.modes.shapes,
                            modes.frequency_hz, np.full(6, 0.02), channel_shapes(test.response_rows(), modes.shapes)),
            ), {}


def _frf_overlay():
    tap, test, _ = _tap_test()
    w = 2 * np.pi * test.f_hz[:, None, None]
    system = tap.system
    model_H = -w**2 * (test.response_rows() @ np.linalg.inv(system.K - w**2 * system.M + 1j * w * system.C)
                       @ test.load_columns())
    return (test, model_H), {}


def _update_history():
    from sixdof.plots.correlation import UpdateHistory

    return (UpdateHistory(np.array([0, 0, 1, 1, -1]), np.array([1.0, 0.3, 0.2, 0.1, 0.05]),
                          np.column_stack([np.linspace(1.0, 0.9, 5), np.linspace(0.0, 0.006, 5)]),
                          ("rear v", "cg_offset x"), [1.0, 0.0], ("1", "m"), "modal objective"),), {}


def _from_run(*keys, **named):
    """Arguments taken from the small run's parts by name (``t`` is the response's time)."""
    def build():
        parts = _run_parts()
        pick = {**parts, "t": parts["response"].t}
        return tuple(pick[key] for key in keys), {name: parts.get(key) for name, key in named.items()}
    return build


#: How to build the arguments of every public plot function, from small systems' typed results: each built only
#: when its figure is drawn, so that the quick loop draws the cheap ones without the slow ones' solves.
INPUTS = {
    "plot_mode_shapes": _from_run("modes", "system"),
    "plot_ke_distribution": _from_run("modes"),
    "plot_time_histories": _from_run("response", events="events"),
    "plot_superposition": _from_run("response", "superposition", "agreement"),
    "plot_mount_forces": _from_run("mount_forces", "t"),
    "plot_mount_loads": _from_run("mount_check", "t"),
    "plot_mount_shear": _from_run("mount_check", "t"),
    "plot_point_accelerations": _point_accelerations,
    "plot_bode": _from_run("frf", "modes"),
    "plot_point_frfs": _from_run("frf_extras", "modes"),
    "plot_transmissibility": _transmissibility,
    "plot_validation_frf": _from_run("validation"),
    "plot_free_decays": _from_run("validation"),
    "plot_random": _random,
    "plot_random_check": _random_check,
    "plot_srs": _srs,
    "plot_spectrum": _spectrum,
    "plot_hysteresis": _hysteresis,
    "plot_records": _records,
    "plot_dynamic_stiffness": lambda: (([("constant loss factor 0.15", _loss_model())],), {}),
    "plot_mount_fits": lambda: (([dataclasses.replace(_loss_model(), name="A u")],), {}),
    "plot_stability": lambda: ((_tap_test()[2],), {"H": _tap_test()[1].H, "f_hz": _tap_test()[1].f_hz}),
    "plot_mac": _mac,
    "plot_frf_overlay": _frf_overlay,
    "plot_update_history": _update_history,
}


def test_every_public_plot_function_takes_ax_or_fig_and_returns_a_figure():
    """A new plot function without ``ax=`` or ``fig=`` fails here (and in the test below, which needs its inputs)."""
    assert len(PLOT_FUNCTIONS) >= 24
    for name in PLOT_FUNCTIONS:
        function = getattr(plots, name)
        parameters = inspect.signature(function).parameters
        wanted = "ax" if name in SINGLE_PANEL else "fig"
        assert wanted in parameters and parameters[wanted].default is None, name
        assert inspect.signature(function).return_annotation in (Figure, "Figure"), name
        assert f"    {wanted} : matplotlib." in function.__doc__, name  # documented: the layout it draws, for fig
    assert set(INPUTS) == set(PLOT_FUNCTIONS)  # each one is drawn below


#: Figures whose inputs take a solve of 2-3 s on the 2-core machine (a hysteretic run, two records, a random check).
SLOW_INPUTS = {"plot_hysteresis", "plot_random_check", "plot_records"}


@pytest.mark.parametrize("name", [pytest.param(name, marks=pytest.mark.slow) if name in SLOW_INPUTS else name
                                  for name in PLOT_FUNCTIONS])
def test_each_plot_function_draws_into_the_given_axes_or_figure(name):
    args, kwargs = INPUTS[name]()
    function = getattr(plots, name)
    alone = function(*args, **kwargs)
    assert isinstance(alone, Figure) and alone.axes
    # A fitted layout's margins are in inches: it is given a figure of its own size; the others any size.
    given = Figure(figsize=alone.get_size_inches() if name in FITTED else (6.0, 4.0))
    if name in SINGLE_PANEL:
        ax = given.add_subplot()
        assert function(*args, ax=ax, **kwargs) is given
        assert ax.has_data() or ax.images or ax.collections, name
        assert given.axes[0] is ax  # drawn there, not into new axes (a colour bar may come beside it)
    else:
        assert function(*args, fig=given, **kwargs) is given
        assert len(given.axes) == len(alone.axes), name  # the same panels as its own figure
        if name not in FITTED:
            assert tuple(given.get_size_inches()) == tuple(alone.get_size_inches()), name
    if name not in SINGLE_PANEL | FITTED:  # no longer empty: refused, naming fig
        with pytest.raises(sixdof.InputError, match=r"fig: expected an empty matplotlib Figure"):
            function(*args, fig=given, **kwargs)


def test_a_figure_drawn_into_must_be_an_empty_figure():
    from sixdof.plots.common import figure

    with pytest.raises(sixdof.InputError, match=r"fig: expected an empty matplotlib Figure \(the plot lays out its "
                                                r"own panels\), got a figure with 1 axes"):
        full = Figure()
        full.add_subplot()
        figure(full, (4, 3))
    with pytest.raises(sixdof.InputError, match=r"fig: expected a matplotlib.figure.Figure \(or None for a new one\)"):
        figure("figure", (4, 3))
    assert tuple(figure(Figure(), (4.0, 3.0)).get_size_inches()) == (4.0, 3.0)

"""sixdof: forced, damped vibration of a rigid body with six degrees of freedom on elastic mounts.

The public API is re-exported here, each name imported from its module on first use: ``import sixdof``
loads neither JAX, SciPy, h5py nor matplotlib, so that the ``sixdof`` command starts at once and
library users pay only for what they call.

JAX runs in float64: the first computation that needs JAX imports it from :mod:`sixdof._jax`, which
switches ``jax_enable_x64`` on for the whole process (your own JAX code in it then defaults to float64
too). JAX's float32 default would silently give sixdof's per-DOF accuracy away.
"""

from sixdof._lazy import lazy_names

__version__ = "0.1.0"

#: Public name -> module that defines it (relative to the package), imported when the name is first used.
_PUBLIC = {
    # Labels and errors.
    "DOFS": "dofs",
    "DOF_UNITS": "dofs",
    "InputError": "errors",
    "ScenarioError": "errors",
    "NotPrepared": "io.scenario",
    "SolverError": "errors",
    # The model and scenarios.
    "Maxwell": "model.parts",
    "Mount": "model.parts",
    "Rayleigh": "model.parts",
    "RigidBody": "model.parts",
    "System": "model.system",
    "Scenario": "io.scenario",
    "load_scenario": "io.scenario",
    "parse_scenario": "io.scenario",
    # Excitation.
    "Excitation": "excitation",
    "Load": "excitation",
    "Unbalance": "excitation",
    "GroundMotion": "excitation",
    "InitialState": "excitation",
    "ModeRelease": "excitation",
    "SIGNAL_KINDS": "excitation",
    "HalfSine": "excitation",
    "Harmonic": "excitation",
    "Haversine": "excitation",
    "Ramp": "excitation",
    "Random": "excitation",
    "Step": "excitation",
    "Sweep": "excitation",
    "Table": "excitation",
    # Analyses and their results.
    "Modes": "model.modes",
    "modal_analysis": "model.modes",
    "Statics": "analysis.statics",
    "gravity_statics": "analysis.statics",
    "SimulationSettings": "analysis.direct",
    "simulate": "analysis.direct",
    "TimeHistory": "results",
    "RunResults": "results",
    "to_xarray": "results",
    "mount_forces": "analysis.response",
    "point_motion": "analysis.response",
    "mount_check": "analysis.mountcheck",
    "MountCheck": "analysis.mountcheck",
    "MountLimitWarning": "analysis.mountcheck",
    "superpose": "analysis.superposition",
    "compare": "analysis.compare",
    "compare_motion": "analysis.compare",
    "receptance": "analysis.frf",
    "point_frf": "analysis.frf",
    "force_transmissibility": "analysis.frf",
    "ground_transmissibility": "analysis.frf",
    "validate": "validation",
    "design_metrics": "analysis.design",
    "response_spectrum": "analysis.spectrum",
    "ResponseSpectrum": "analysis.spectrum",
    "effective_linearization_loop": "analysis.isolation",
    "SpectrumSettings": "excitation.spectra",
    "EC8Spectrum": "excitation.spectra",
    "TabulatedSpectrum": "excitation.spectra",
    "sensitivities": "analysis.design",
    # End to end and files.
    "run": "workflows.run",
    "save": "workflows.run",
    "run_scenario": "workflows.run",
    "prepare": "workflows.prepare",
    "ResultsStream": "io.stream",
    "optimize_scenario": "workflows.optimize",
    "correlation_run": "workflows.correlate",
    "save_correlation": "workflows.correlate",
    "load_results": "io.store",
    "load_test": "io.testfile",
    "TestData": "validation.testdata",
    "write_results": "io.store",
}

__all__ = list(_PUBLIC)


__getattr__, __dir__ = lazy_names(__name__, _PUBLIC, __all__)

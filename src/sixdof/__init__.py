"""sixdof: forced, damped vibration of a rigid body with six degrees of freedom on elastic mounts.

The public API is re-exported here. Names from the heavier modules (the diffrax solver, HDF5 files)
are imported on first use, so ``import sixdof`` stays quick and never loads pyplot or h5py.
"""

from importlib import import_module

from sixdof.analysis.modal import Modes, modal_analysis
from sixdof.analysis.statics import Statics, gravity_statics
from sixdof.dofs import DOF_UNITS, DOFS
from sixdof.errors import InputError, ScenarioError, SolverError
from sixdof.io.scenario import Scenario, load_scenario, parse_scenario
from sixdof.model.system import Mount, Rayleigh, RigidBody, System

__version__ = "0.1.0"

# name -> module that defines it, imported when the name is first used.
_LAZY = {
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
    "SimulationSettings": "analysis.direct",
    "TimeHistory": "results",
    "RunResults": "results",
    "to_xarray": "results",
    "simulate": "analysis.direct",
    "mount_forces": "analysis.response",
    "point_motion": "analysis.response",
    "mount_check": "analysis.mountcheck",
    "MountCheck": "analysis.mountcheck",
    "MountLimitWarning": "analysis.mountcheck",
    "superpose": "analysis.superposition",
    "compare": "analysis.compare",
    "receptance": "analysis.frf",
    "point_frf": "analysis.frf",
    "force_transmissibility": "analysis.frf",
    "ground_transmissibility": "analysis.frf",
    "validate": "validation",
    "run_scenario": "workflows",
    "load_results": "io.store",
    "write_results": "io.store",
}

__all__ = [
    "DOFS",
    "DOF_UNITS",
    "InputError",
    "ScenarioError",
    "SolverError",
    "Modes",
    "modal_analysis",
    "Mount",
    "Rayleigh",
    "RigidBody",
    "System",
    "Scenario",
    "load_scenario",
    "parse_scenario",
    "Statics",
    "gravity_statics",
    *_LAZY,
]


def __getattr__(name: str):
    if name in _LAZY:
        value = getattr(import_module(f".{_LAZY[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'sixdof' has no attribute {name!r}")

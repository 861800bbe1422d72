"""sixdof: forced, damped vibration of a rigid body with six degrees of freedom on elastic mounts.

The public API is re-exported here. Names from the heavier modules (the diffrax solver, HDF5 files)
are imported on first use, so ``import sixdof`` stays quick and never loads pyplot or h5py.
"""

from importlib import import_module

from .dofs import DOF_UNITS, DOFS
from .errors import InputError, ScenarioError, SolverError
from .modal import Modes, modal_analysis
from .model import Mount, Rayleigh, RigidBody, System
from .scenario import Scenario, load_scenario, parse_scenario
from .statics import Statics, gravity_statics

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
    "SimulationSettings": "direct",
    "TimeResponse": "direct",
    "simulate": "direct",
    "mount_forces": "response",
    "point_motion": "response",
    "superpose": "superposition",
    "compare": "superposition",
    "receptance": "frf",
    "point_frf": "frf",
    "force_transmissibility": "frf",
    "ground_transmissibility": "frf",
    "validate": "validate",
    "run_scenario": "run",
    "load_results": "store",
    "write_results": "store",
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

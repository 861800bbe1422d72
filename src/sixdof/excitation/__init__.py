"""What acts on the body: time signals (:mod:`.signals`) and loads, ground motion and initial state
(:mod:`.loads`); the baseline correction of recorded ground accelerations (:mod:`.baseline`)."""

from sixdof.excitation.baseline import BASELINE_METHODS, integrate_record, polynomial_baseline
from sixdof.excitation.loads import (
    GROUND_QUANTITIES,
    LOAD_KINDS,
    Excitation,
    GroundMotion,
    InitialState,
    Load,
    ModeRelease,
    Unbalance,
)
from sixdof.excitation.signals import (
    SIGNAL_KINDS,
    HalfSine,
    Harmonic,
    Haversine,
    Ramp,
    Random,
    Signal,
    Step,
    Sweep,
    Table,
    make_signal,
)

__all__ = [
    "SIGNAL_KINDS", "LOAD_KINDS", "GROUND_QUANTITIES", "Signal", "Harmonic", "Sweep", "HalfSine",
    "Haversine", "Step", "Ramp", "Table", "Random", "make_signal", "Load", "Unbalance",
    "GroundMotion", "InitialState", "ModeRelease", "Excitation", "BASELINE_METHODS", "integrate_record",
    "polynomial_baseline",
]

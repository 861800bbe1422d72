"""Modal results validated against time histories: estimators (:mod:`.estimation`) and the
free-decay and random-force experiment (:mod:`.experiment`)."""

from sixdof.validation.estimation import (
    DecayEstimate,
    EstimatedFRF,
    decay_estimate,
    effective_averages,
    estimate_frf,
    h1_random_error,
    held_model_frf,
    peak_frequency,
)
from sixdof.validation.experiment import (
    Check,
    FreeDecay,
    ModeCheck,
    RandomRun,
    ValidationReport,
    ValidationSettings,
    validate,
)

__all__ = [
    "Check", "DecayEstimate", "EstimatedFRF", "FreeDecay", "ModeCheck", "RandomRun", "ValidationReport",
    "ValidationSettings", "decay_estimate", "effective_averages", "estimate_frf", "h1_random_error",
    "held_model_frf", "peak_frequency", "validate",
]

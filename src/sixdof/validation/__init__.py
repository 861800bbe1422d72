"""Modal results validated against time histories: estimators (:mod:`.estimation`), the free-decay and
random-force experiment (:mod:`.experiment`; :mod:`.runs` runs it), the random response's check
(:mod:`.random_time`), and the test's side: measured motion projected onto the six DOFs (:mod:`.projection`),
test modes paired with the model's by MAC (:mod:`.correlation`), and the modal identification of measured
FRFs (:mod:`.identify`, pLSCF + LSFD).

Names load on first use: :mod:`.estimation` imports scipy.signal (about 0.7 s), which a run that validates
nothing must not pay for (``sixdof.validation.random_time`` is imported by every run whose ``[random]`` has
a time check).
"""

from sixdof._lazy import lazy_names

_PUBLIC = {
    "DecayEstimate": "estimation", "EstimatedFRF": "estimation", "decay_estimate": "estimation",
    "effective_averages": "estimation", "estimate_frf": "estimation", "h1_random_error": "estimation",
    "held_model_frf": "estimation", "peak_frequency": "estimation", "MultiReferenceFRF": "estimation",
    "check_resolution": "estimation", "estimate_frfs": "estimation",
    "BodyProjection": "projection", "project_to_body": "projection",
    "Correlation": "correlation", "correlate_modes": "correlation",
    "mac": "correlation", "pair_modes": "correlation",
    "Check": "experiment", "FreeDecay": "experiment", "ModeCheck": "experiment", "RandomRun": "experiment",
    "ValidationReport": "experiment", "ValidationSettings": "experiment", "validate": "runs",
    "Identification": "identify", "IdentifiedModes": "identify", "StabilityDiagram": "identify",
    "identify_modes": "identify",
}

__all__ = sorted(_PUBLIC)


__getattr__, __dir__ = lazy_names(__name__, _PUBLIC, __all__)

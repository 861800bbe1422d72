"""The result classes a results file may hold, registered (:func:`sixdof.results.result_type`) by importing the
modules that define them: a file is read back into its classes whatever the process imported before.

Each module that loads no heavy library on import is imported here; the batch engine's (JAX) and the
validation's (SciPy) only when a file names one of their classes (:func:`registered`), so that reading and
drawing a run's file loads neither (``sixdof plot`` of a run never loads JAX: tested).
"""

from __future__ import annotations

from collections.abc import Callable

import sixdof.analysis.compare  # noqa: F401
import sixdof.analysis.contact  # noqa: F401
import sixdof.analysis.design  # noqa: F401
import sixdof.analysis.frf  # noqa: F401
import sixdof.analysis.isolation  # noqa: F401
import sixdof.analysis.mountcheck  # noqa: F401
import sixdof.analysis.random  # noqa: F401
import sixdof.analysis.records  # noqa: F401
import sixdof.analysis.response  # noqa: F401
import sixdof.analysis.severity  # noqa: F401
import sixdof.analysis.spectrum  # noqa: F401
import sixdof.analysis.srs  # noqa: F401
import sixdof.analysis.statics  # noqa: F401
import sixdof.analysis.steady  # noqa: F401
import sixdof.model.modes  # noqa: F401
import sixdof.model.system  # noqa: F401
import sixdof.model.viscoelastic  # noqa: F401
import sixdof.validation.testdata  # noqa: F401
from sixdof.results import result_class


def registered(ref: type | str | Callable[[], type]) -> type:
    """The result class a field names (:func:`sixdof.results.result_class`), the heavy modules imported first,
    one after the other until it is found, when it is one of theirs."""
    for register in (lambda: None, *_HEAVY):
        register()
        try:
            return result_class(ref)
        except LookupError:
            pass
    return result_class(ref)  # not even there: its error


def _validation() -> None:
    """Register the validation's ValidationReport (its module loads SciPy)."""
    import sixdof.validation.experiment  # noqa: F401, PLC0415 (it loads JAX or SciPy: only for a file that names its classes)


def _batch() -> None:
    """Register the batch engine's BatchResult (a sweep's) and the direct solve's SimulationSettings (their
    modules load JAX)."""
    import sixdof.analysis.batch  # noqa: F401, PLC0415 (it loads JAX or SciPy: only for a file that names its classes)
    import sixdof.analysis.direct  # noqa: F401, PLC0415 (it loads JAX or SciPy: only for a file that names its classes)


def _update() -> None:
    """Register the model update's UpdateResult (its module loads JAX to update, not to be read, but imports the
    design layer's JAX model)."""
    import sixdof.design.update  # noqa: F401, PLC0415 (it loads JAX or SciPy: only for a file that names its classes)


def _records() -> None:
    """Register the spectrum-compatible records' results (SpectrumCompatibleRecords, RecordCheck, RecordPeaks: their
    modules load JAX, through the excitation package and the direct solve)."""
    import sixdof.analysis.matching  # noqa: F401, PLC0415 (it loads JAX or SciPy: only for a file that names its classes)
    import sixdof.analysis.record_peaks  # noqa: F401, PLC0415 (it loads JAX or SciPy: only for a file that names its classes)


#: The heavy modules' registrations, the lighter first: a validation's file is read without JAX.
_HEAVY = (_validation, _batch, _update, _records)

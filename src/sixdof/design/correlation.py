"""What ``sixdof correlate`` found, as ``correlation.h5`` stores it: a test against a model, and the update.

:class:`CorrelationRun` gathers the parts the numerics return (the measured data, its H1 estimate for time
data, the identified modes, their projection onto the six body DOFs, the correlation with the model and, with
an update, the updated model's); nothing here computes. It lives in the design layer because the update
(:mod:`sixdof.design.update`) is one of its parts; the workflow :mod:`sixdof.workflows.correlate` builds it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from sixdof.frozen import Frozen
from sixdof.results import Result, label, part, quantity, result_type
from sixdof.validation.correlation import Correlation
from sixdof.validation.identify import Identification
from sixdof.validation.projection import BodyProjection
from sixdof.validation.testdata import TestData, frf_units

__all__ = ["CorrelationRun"]


@result_type
@dataclass(frozen=True, eq=False, kw_only=True)
class CorrelationRun(Frozen, Result):
    """A test correlated with a model, and with ``[update]`` and ``--update`` the model updated to it.

    Attributes
    ----------
    name : str
        The scenario's.
    test : TestData
        The measured data as read (FRFs, or time histories).
    measured : TestData
        The FRFs correlated: ``test`` itself, or for time data its H1 estimate on the same channels.
    estimate : sixdof.validation.estimation.MultiReferenceFRF or None
        For time data: the H1 estimate, its multiple coherence and averaging.
    identification : Identification
        The modes identified from ``measured`` (poly-reference LSCF and LSFD) and their stability diagram.
    projection : BodyProjection
        The identified shapes as six body DOFs, and the share of each mode's motion no rigid body makes.
    rigid : ndarray of bool, shape (m_test,)
        The identified modes correlated with the rigid-body model: those whose projection residual is at most
        ``rigid_residual``; the others (flexible modes of the body, in the band) are reported, not paired.
    rigid_residual : float
        That limit [1].
    correlation : Correlation
        The rigid test modes against the model's modes.
    model_H : ndarray, shape (nf, n_out, n_ref), complex
        The model's FRF on the test's channels, in the test's quantity (SI units, as ``TestData.H``).
    update : sixdof.design.update.UpdateResult or None
        The update, when asked for.
    correlation_updated : Correlation or None
        The rigid test modes against the updated model's modes.
    updated_H : ndarray or None
        The updated model's FRF on the test's channels (SI units, as ``model_H``).
    updated_text : str
        The updated scenario (TOML), ``""`` without an update.
    notes : tuple of str
        What the run noticed (resolution, flexible modes, undetermined variables).
    provenance : mapping of str to str
        ``scenario_text``, and once read back every root attribute.
    """

    test: TestData = part(TestData, group="test")
    measured: TestData = part(TestData, group="measured")
    identification: Identification = part(Identification, group="identification")
    projection: BodyProjection = part(BodyProjection, group="projection")
    correlation: Correlation = part(Correlation, group="correlation")
    rigid: np.ndarray = quantity("1", ("test_mode",), encode=lambda a: np.asarray(a, np.int8),
                                 decode=lambda a: np.asarray(a, bool),
                                 description="1: an identified mode correlated with the rigid-body model")
    model_H: np.ndarray = quantity(lambda run: frf_units(run.measured), ("f_hz", "output", "reference"),
                                   name="model/H", description="the model's FRF on the test's channels")
    rigid_residual: float = label(decode=float)
    name: str = label(name="scenario_name", default="")
    estimate: Any = part("MultiReferenceFRF", group="estimate", default=None)
    update: Any = part("UpdateResult", group="update", default=None)
    correlation_updated: Correlation | None = part(Correlation, group="correlation_updated", default=None)
    updated_H: np.ndarray | None = quantity(lambda run: frf_units(run.measured), ("f_hz", "output", "reference"),
                                            name="updated/H", default=None,
                                            description="the updated model's FRF on the test's channels")
    updated_text: str = label(default="")
    notes: tuple[str, ...] = label(default=(), encode=lambda n: "\n".join(n),
                                   decode=lambda s: tuple(str(s).split("\n")) if s else ())
    provenance: Any = field(default_factory=dict)

    @property
    def final(self) -> Correlation:
        """The correlation that judges the run: the updated model's when there is one."""
        return self.correlation if self.correlation_updated is None else self.correlation_updated

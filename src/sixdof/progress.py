"""Progress of long computations, on stderr, drawn between units of work (never inside a compiled solve).

One meter for every long command: the direct solve's simulated time, a sweep's variants, a validation's
runs. ``progress`` arguments take None or False (none), True (tqdm where it is installed, else a line of
text redrawn in place), ``"text"`` or ``"tqdm"``.
"""

from __future__ import annotations

import importlib.util
import sys
from typing import Any

from sixdof.errors import InputError

KINDS = ("text", "tqdm")


class Meter:
    """``done`` of ``total`` ``unit`` (counted from ``origin``), shown by :meth:`show` and finished by :meth:`close`;
    of kind None, silent (so that callers need not ask whether progress is shown)."""

    def __init__(self, kind: str | None, total: float, unit: str, description: str, origin: float = 0.0) -> None:
        self.kind, self.total, self.unit, self.description, self.origin = kind, float(total), unit, description, origin
        self.bar = None
        if kind == "tqdm":
            from tqdm.auto import tqdm

            number = "{n:.4g}/{total:.4g}" if unit == "s" else "{n:.0f}/{total:.0f}"
            self.bar = tqdm(total=self.total, unit=unit, desc=description,
                            bar_format="{l_bar}{bar}| " + number + " " + unit + " [{elapsed}<{remaining}{postfix}]")

    def show(self, reached: float, note: str = "") -> None:
        """Show ``reached`` (in the meter's unit, from ``origin``), and ``note`` after it (a rate...)."""
        if self.kind is None:
            return
        done = reached - self.origin
        if self.bar is not None:
            if note:
                self.bar.set_postfix_str(note, refresh=False)
            self.bar.update(done - self.bar.n)
        else:
            amount = f"{done:.4g} / {self.total:.4g}" if self.unit == "s" else f"{int(done)} / {int(self.total)}"
            print(f"\r{self.description}: {amount} {self.unit} ({done / self.total if self.total else 1:.0%})"
                  + (f", {note}" if note else ""), end="", file=sys.stderr, flush=True)

    def close(self, note: str = "") -> None:
        """Show the whole as done and end the line."""
        if self.kind is None:
            return
        self.show(self.origin + self.total, note)
        if self.bar is not None:
            self.bar.close()
        else:
            print(file=sys.stderr, flush=True)


def meter(progress: Any, total: float, unit: str, description: str, origin: float = 0.0) -> Meter:
    """The :class:`Meter` that ``progress`` asks for (see the module); a silent one for None or False."""
    if progress is None or progress is False:
        return Meter(None, total, unit, description, origin)
    if progress is True:
        progress = "tqdm" if importlib.util.find_spec("tqdm") else "text"
    if progress not in KINDS:
        raise InputError("progress", "None, True, 'text' or 'tqdm'", progress)
    return Meter(progress, total, unit, description, origin)


__all__ = ["KINDS", "Meter", "meter"]

"""Every kind of fault in one table: what it does, and which fields of a fault it reads.

Adding a fault kind touches only this file: one :class:`FaultKind` in :data:`KINDS`.  The
world file accepts exactly these kinds, each with only the fields it reads
(:mod:`sim.worldfile` validates against the table), and the injector applies them
(:mod:`sim.faults`).  A kind does one or both of:

* change the scan being built (``on_scan``): faults active at a scan's time edit it in
  the order they are listed, so the result does not depend on when or how often it is
  asked for;
* place an obstacle in the world once its start time has come (``places``).

This module imports nothing of the world file at run time (the world file imports it).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from content.i18n import _

if TYPE_CHECKING:
    from sim.lidar import Lidar
    from sim.worldfile import Box, Circle, Fault


@dataclass
class ScanDraft:
    """A scan while the active faults change it."""

    ranges: np.ndarray
    """One float32 reading per beam."""
    length: int
    """How many readings go out (more than the beams repeats them)."""
    lidar: Lidar
    dropped: bool = False
    """Nothing goes out at all."""

    @property
    def beams(self) -> int:
        return len(self.ranges)


BeamPicker = Callable[[float], np.ndarray]
"""The beams a fault hits for a share of them, drawn reproducibly (world seed, fault's
index, scan time)."""

ScanEffect = Callable[[ScanDraft, "Fault", BeamPicker], None]


@dataclass(frozen=True)
class FaultKind:
    """One kind of fault: its doc, the fields it reads, and what it does."""

    doc: str
    fields: tuple[str, ...]
    """The fault's fields a world file may give for this kind (``kind`` aside)."""
    on_scan: ScanEffect | None = None
    places: Callable[[Fault], Box | Circle | None] | None = None
    check: Callable[[Fault], str | None] | None = None
    """What the types cannot say: an error message about the fault, or None."""


def _beams_read(value: Callable[[Lidar], float]) -> ScanEffect:
    """A share (``fraction``) of the beams reads ``value``."""

    def effect(scan: ScanDraft, fault: Fault, pick: BeamPicker) -> None:
        scan.ranges[pick(fault.fraction)] = value(scan.lidar)

    return effect


def _empty(scan: ScanDraft, fault: Fault, pick: BeamPicker) -> None:
    scan.length = 0


def _wrong_length(scan: ScanDraft, fault: Fault, pick: BeamPicker) -> None:
    if scan.length:  # an empty scan stays empty
        # Never the right length by accident: the point is the disagreement.
        scan.length = fault.length if fault.length != scan.beams else scan.beams - 1


def _dropout(scan: ScanDraft, fault: Fault, pick: BeamPicker) -> None:
    scan.dropped = True


def _one_obstacle(fault: Fault) -> str | None:
    if (fault.box is None) == (fault.circle is None):
        return _("an obstacle fault needs exactly one of box or circle")
    return None


_SPAN = ("start", "end")
_PER_BEAM = (*_SPAN, "fraction")

KINDS: dict[str, FaultKind] = {
    "nan": FaultKind("a share of the beams reads NaN", _PER_BEAM,
                     on_scan=_beams_read(lambda lidar: np.nan)),
    "inf": FaultKind("a share of the beams reads +inf", _PER_BEAM,
                     on_scan=_beams_read(lambda lidar: np.inf)),
    "neg_inf": FaultKind("a share of the beams reads -inf", _PER_BEAM,
                         on_scan=_beams_read(lambda lidar: -np.inf)),
    "below_min": FaultKind("a share of the beams reads half of range_min", _PER_BEAM,
                           on_scan=_beams_read(lambda lidar: lidar.range_min / 2)),
    "above_max": FaultKind("a share of the beams reads 1 m beyond range_max", _PER_BEAM,
                           on_scan=_beams_read(lambda lidar: lidar.range_max + 1.0)),
    "empty": FaultKind("scans have no ranges at all", _SPAN, on_scan=_empty),
    "wrong_length": FaultKind("scans have `length` ranges instead of one per beam",
                              (*_SPAN, "length"), on_scan=_wrong_length),
    "dropout": FaultKind("the lidar publishes nothing", _SPAN, on_scan=_dropout),
    "obstacle": FaultKind("`box` or `circle` appears at `start` and stays",
                          ("start", "box", "circle"),
                          places=lambda fault: fault.box or fault.circle,
                          check=_one_obstacle),
}
"""Every fault kind by name, in the order the docs list them."""


def kind_names() -> str:
    """The kinds for docs and messages: ``nan, inf, ... or obstacle``."""
    names = list(KINDS)
    return ", ".join(names[:-1]) + " or " + names[-1] if len(names) > 1 else "".join(names)

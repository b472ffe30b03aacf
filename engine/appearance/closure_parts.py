"""What closure parts are made of and how they are described: materials, parts, gaps.

Design rule: the values shared by :mod:`engine.appearance.closures` (closures sized from the
finish) and :mod:`engine.appearance.closure_shapes` (the chains of each kind) live here, so that
neither imports the other back. Units mm; metals as complex indices at 652, 564 and 443 nm (the
R, G, B rows).
"""
from __future__ import annotations

from dataclasses import dataclass

from ..model.design import BumpTile

RGB = tuple[float, float, float]
#: Air left between a closure and the glass it rests on (mm).
GAP_MM = 0.05
#: Air between a skirt or a cork and the cylinder of glass it surrounds or fills (mm): in a
#: film of air much thinner than this between parallel glass and metal, rays caught at grazing
#: incidence bounce until rounding puts one on the wrong side (measured: 7 medium mismatches
#: in 150 000 rays at 0.05 mm, none at 0.3 mm); invisible at the scale of a cap.
SKIRT_GAP_MM = 0.3
#: Aluminium's complex refractive index n + ik at 652, 564 and 443 nm (R, G, B).
ALUMINIUM_N: RGB = (1.57, 1.07, 0.61)
ALUMINIUM_K: RGB = (7.74, 6.78, 5.37)
#: Lacquer tints over aluminium (linear RGB transmission, seen through twice).
GOLD_LACQUER: RGB = (1.0, 0.72, 0.32)
BARE_METAL: RGB = (1.0, 1.0, 1.0)
PLASTIC_IOR = 1.49
CORK_COLOUR: RGB = (0.45, 0.28, 0.14)


@dataclass(frozen=True)
class ClosureMaterial:
    """What a closure part is made of.

    ``kind`` ``"conductor"``: ``eta`` and ``k`` the complex index per RGB row, ``tint`` the
    lacquer's colour multiplying the Fresnel reflectance. ``kind`` ``"plastic"``: a smooth
    dielectric of index ``eta[0]`` over a diffuse base of colour ``tint``. ``roughness`` is a
    GGX alpha for the surface (0: polished).
    """

    kind: str
    eta: RGB
    k: RGB
    tint: RGB
    roughness: float = 0.0


@dataclass(frozen=True)
class PartRelief:
    """A bump band on a closure part: ``tile`` says what (kind, repeat, depth, ...), ``v0..v1``
    where along the part's chain (mm of arc length from its start) at reference radius
    ``radius`` (mm)."""

    tile: BumpTile
    v0: float
    v1: float
    radius: float


@dataclass(frozen=True)
class ClosurePart:
    """One revolved solid of a closure: a closed meridian ``chain`` (axis to axis, material on
    the left), its ``material`` and the ``reliefs`` on its surface."""

    name: str
    chain: tuple
    material: ClosureMaterial
    reliefs: tuple[PartRelief, ...] = ()


def cap_material(cap) -> ClosureMaterial:
    """The cap's own material: lacquered aluminium or plastic of ``cap.color``."""
    if cap.material == "metal":
        return ClosureMaterial("conductor", ALUMINIUM_N, ALUMINIUM_K, tuple(cap.color), 0.05)
    return ClosureMaterial("plastic", (PLASTIC_IOR,) * 3, (0.0, 0.0, 0.0), tuple(cap.color), 0.1)


CORK = ClosureMaterial("plastic", (1.5, 1.5, 1.5), (0.0, 0.0, 0.0), CORK_COLOUR, 0.5)

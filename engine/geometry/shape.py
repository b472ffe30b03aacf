"""The bottle's shape as the designer defines it: cross-section kind, sections, wall and base.

Design rule: ``BottleShape`` is an immutable value holding only what the designer chose
(millimetres). Everything derived from it (inner sections, surfaces, meshes, volumes) is
computed by other modules and may be cached by the caller keyed on the shape (it hashes).

Section names per cross-section kind:

=================  =======================================================================
``round``          ``profile``: the one section, revolved about the z axis
``rounded_square`` ``u`` (half-width at theta = 0), ``v`` (radius on the diagonal, theta = 45 deg)
``rounded_rect``   ``half_width`` (x), ``half_depth`` (y), ``corner`` (corner radius)
``oval``           ``half_width`` (x semi-axis), ``half_depth`` (y semi-axis)
``outline``        ``core`` (the plan outline's scale k, may reach 0), ``round`` (its rounding
                   c > 0): the section ``k P (+) disc(c)`` of the free plan outline ``plan``
                   (:mod:`engine.geometry.plan`, ../shared/oracle/SPEC_outline.md)
=================  =======================================================================
"""
from __future__ import annotations

from dataclasses import dataclass, field

from .crosssection import cross_section_of
from .section import Section

SECTION_NAMES = {
    "round": ("profile",),
    "rounded_square": ("u", "v"),
    "rounded_rect": ("half_width", "half_depth", "corner"),
    "oval": ("half_width", "half_depth"),
    "outline": ("core", "round"),
}


@dataclass(frozen=True)
class BottleShape:
    """Sections, cross-section kind and glass thicknesses (mm) of one bottle.

    ``wall_thickness`` is the uniform wall (mm); ``wall_per_segment`` optionally gives one
    thickness per wall segment of the (first) section and then overrides it. ``base_thickness``
    is the height of the inner base above z = 0 (mm, >= wall). ``rotation_deg`` turns a
    non-round bottle about +z (counter-clockwise seen from above). ``plan`` is the free plan
    outline of an ``outline`` bottle (:class:`engine.geometry.plan.PlanOutline`), ``None`` for
    every other kind.
    """

    cross_section: str
    sections: tuple[tuple[str, Section], ...]
    wall_thickness: float = 3.0
    base_thickness: float = 6.0
    rotation_deg: float = 0.0
    wall_per_segment: tuple[float, ...] | None = field(default=None)
    plan: object = field(default=None)

    def __post_init__(self):
        if self.cross_section not in SECTION_NAMES:
            raise ValueError(f"unknown cross-section {self.cross_section!r}; "
                             f"expected one of {', '.join(SECTION_NAMES)}")
        secs = tuple((str(k), v) for k, v in (self.sections.items() if isinstance(self.sections, dict)
                                              else self.sections))
        names = tuple(k for k, _ in secs)
        want = SECTION_NAMES[self.cross_section]
        if sorted(names) != sorted(want):
            raise ValueError(f"a {self.cross_section} bottle needs sections {', '.join(want)}; got {', '.join(names) or 'none'}")
        object.__setattr__(self, "sections", tuple(sorted(secs, key=lambda kv: want.index(kv[0]))))
        for name in ("wall_thickness", "base_thickness", "rotation_deg"):
            object.__setattr__(self, name, float(getattr(self, name)))
        if self.wall_per_segment is not None:
            object.__setattr__(self, "wall_per_segment", tuple(float(w) for w in self.wall_per_segment))
        if (self.plan is not None) != (self.cross_section == "outline"):
            raise ValueError("an outline bottle needs its plan outline, and only an outline bottle has one")

    def section(self, name: str) -> Section:
        """The section called ``name`` (see the module table)."""
        for k, v in self.sections:
            if k == name:
                return v
        raise KeyError(f"a {self.cross_section} bottle has no section {name!r}")

    @property
    def xs(self):
        """The :class:`~engine.geometry.crosssection.CrossSection` to ask about this bottle's
        horizontal sections (an outline's carries :attr:`plan`)."""
        return cross_section_of(self)

    @property
    def r_mouth(self) -> float:
        """Outer radius of the (round) mouth, mm: every kind's sections meet in a circle there."""
        return self.xs.round_radius([sec.r_top for _, sec in self.sections])

    @property
    def primary(self) -> Section:
        """The first section (``profile`` or ``u`` or ``half_width``): height, mouth."""
        return self.sections[0][1]

    @property
    def z_top(self) -> float:
        """Height of the mouth (mm)."""
        return self.primary.z_top

    def with_section(self, name: str, section: Section) -> "BottleShape":
        """A new shape with section ``name`` replaced."""
        self.section(name)
        secs = tuple((k, section if k == name else v) for k, v in self.sections)
        return BottleShape(self.cross_section, secs, self.wall_thickness, self.base_thickness,
                           self.rotation_deg, self.wall_per_segment, self.plan)

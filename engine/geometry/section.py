"""A vertical section: a chain of segments in the (r, z) half-plane, base centre to mouth.

Design rule: ``Section`` is an immutable value. ``segments[0]`` starts on the axis (r = 0);
the chain runs outwards along the base, then up the wall to the mouth. ``smooth[i]`` says
whether the designer asked for tangency (C1/G1) at the joint between segment ``i`` and
``i + 1``; by default every joint but the base corner (joint 0) is smooth, as in
../shared/oracle/SPEC.md section 4.1. Validation lives in :mod:`engine.geometry.validate`.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from .segments import Segment, segment_from_dict


@dataclass(frozen=True)
class Section:
    """An ordered chain of segments (mm) with the designer's tangency requests per joint."""

    segments: tuple[Segment, ...]
    smooth: tuple[bool, ...] = field(default=None)  # type: ignore[assignment]

    def __post_init__(self):
        segs = tuple(self.segments)
        object.__setattr__(self, "segments", segs)
        if self.smooth is None:
            sm = tuple(i > 0 for i in range(max(len(segs) - 1, 0)))
        else:
            sm = tuple(bool(s) for s in self.smooth)
            if len(sm) != max(len(segs) - 1, 0):
                raise ValueError(f"a section of {len(segs)} segments has {max(len(segs) - 1, 0)} joints, "
                                 f"got {len(sm)} smoothness flags")
        object.__setattr__(self, "smooth", sm)

    def __len__(self) -> int:
        return len(self.segments)

    @property
    def z_top(self) -> float:
        """Height of the mouth (mm): the end of the last segment."""
        return self.segments[-1].p1[1]

    @property
    def r_top(self) -> float:
        """Outer radius at the mouth (mm)."""
        return self.segments[-1].p1[0]

    def replace_segment(self, index: int, seg: Segment) -> "Section":
        """A new section with segment ``index`` replaced (no validation)."""
        segs = list(self.segments)
        segs[index] = seg
        return Section(tuple(segs), self.smooth)

    def to_dicts(self) -> list[dict]:
        """The segments as SPEC/project dictionaries."""
        return [s.to_dict() for s in self.segments]

    @classmethod
    def from_dicts(cls, items, smooth=None) -> "Section":
        """Build from a list of segment dictionaries; raises ``ValueError`` naming the segment."""
        if not isinstance(items, (list, tuple)) or not items:
            raise ValueError("a section needs a non-empty list of segments")
        segs = []
        for i, d in enumerate(items):
            try:
                segs.append(segment_from_dict(d))
            except (ValueError, TypeError) as exc:
                raise ValueError(f"segment {i}: {exc}") from None
        return cls(tuple(segs), None if smooth is None else tuple(smooth))

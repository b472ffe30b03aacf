"""Editing a section: the geometry behind the section editor's drags, table edits and tools.

Design rule: every edit is a pure function of frozen values (``Section -> Section``, mm) that
keeps the chain connected and the designer's smooth joints tangent where it can; the widgets
only turn mouse and keyboard input into these calls and draw the result. Validation of the
result stays with :mod:`engine.geometry.validate`. Modules: :mod:`.curves` (moved, deformed and
tangent segments), :mod:`.joints` (joint moves that keep the finish, typed joint positions,
radii, the editor's handles), :mod:`.tangency` (arcs tangent to their neighbours), :mod:`.tools`
(split, delete, insert, convert, smoothness); :mod:`.plan_tools` edits an outline bottle's plan
outline the same way (``PlanOutline -> PlanOutline``: joints, arcs, corners, symmetry, presets).
"""
from .curves import (arc_tangent_at, deform_end, deform_start, scaled_radially, section_polyline,
                     translated)
from .joints import (Handle, handles_of, joint_name, move_arc_centre, move_joint, place_joint,
                     propose_drag, set_arc_radius, set_ellipse_radii)
from .tools import convert_segment, delete_segment, insert_line_after, set_smooth, split_segment

__all__ = ["Handle", "arc_tangent_at", "convert_segment", "deform_end", "deform_start",
           "delete_segment", "handles_of", "insert_line_after", "joint_name", "move_arc_centre",
           "move_joint", "place_joint",
           "propose_drag", "scaled_radially", "section_polyline", "set_arc_radius",
           "set_ellipse_radii", "set_smooth", "split_segment", "translated"]

"""The scene model: :class:`~engine.model.design.Design`, the whole design as one frozen value;
:class:`~engine.model.scene.Scene`, the observable holder the GUI edits and the tracer
snapshots; the rules a design's values obey: :mod:`engine.model.check` (ranges and sizes) and
:mod:`engine.model.fill` (where a liquid may stand, and the one volume -> height); what is
derived from a design for people: :mod:`engine.operations.trade` (trade numbers) and
:mod:`engine.model.advice` (warnings, a name that states the fill); and the design in a
designer's terms: :mod:`engine.model.orbit` (the camera as an orbit) and
:mod:`engine.model.tint` (colour by thickness).
"""

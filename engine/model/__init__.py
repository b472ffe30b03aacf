"""The scene model: :class:`~engine.model.design.Design`, the whole design as one frozen value;
:class:`~engine.model.scene.Scene`, the observable holder the GUI edits and the tracer
snapshots; and the rules a design's values obey: :mod:`engine.model.check` (ranges and sizes)
and :mod:`engine.model.fill` (where a liquid may stand, and the one volume -> height).
"""

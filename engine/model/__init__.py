"""The scene model: :class:`~engine.model.design.Design`, the whole design as one frozen value,
and :class:`~engine.model.scene.Scene`, the observable holder the GUI edits and the tracer
snapshots.
"""

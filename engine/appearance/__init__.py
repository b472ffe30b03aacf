"""Surface appearance: labels, bump tiles, closures.

Design rule: everything here is derived, Qt-free and deterministic: from a frozen
:class:`engine.model.design.Design` (and its embedded assets) it computes what the tracer and
the window draw. Bump tiles become rows of numbers for the compiled relief functions of
:mod:`engine.tracer.kernels.bumps` (:mod:`.bump_tables`), relief images become slope textures
(:mod:`.relief_image`), and a closure becomes meridian chains of section segments with a
material each (:mod:`.closures`), sized from the finish so that it follows the neck.
"""

"""Surface appearance: what covers the glass and how it lies on it.

Design rule: this package owns everything about what sits on the bottle's surface except the
ray tracing itself and its table formats: labels (images decoded to linear RGBA, finish
regions, the exact map of a label onto the outer wall and its flat die-line), where bump tiles
lie, closures sized from the finish. It is plain Python and numpy (no Qt); :mod:`engine.tracer`
packs what it produces into the kernels' rows and is never imported from here.

==========================  ===================================================================
module                      holds
==========================  ===================================================================
``images``                  artwork and mask files -> linear float32 RGBA, checked, cached
``regions``                 chroma keys and masks -> uint8 region index maps
``girth``                   arc length around a cross-section (round, rounded square/rect, oval)
``surface``                 the outer wall in label terms: arc length along a round section,
                            girth and slant of non-round walls, the tracer's ``(theta, h)``
``frame``                   one label's exact map between ``(theta, h)`` and artwork ``(s, t)``
``placement``               whether a label lies on the glass (for ``check_design``)
``flatten``                 least-distortion (as-rigid-as-possible) flattening of a grid, strain
``decal``                   a label's decal: footprint, (s, t) grid, strain (the tracer packs it)
``dieline``                 the flat shape a printer cuts, area, largest strain, warnings
``report``                  one label's area, die-line, largest strain and warnings (CLI, panel)
``dieline_files``           the die-line as SVG, PDF or DXF, to scale with dimensions
``presets``                 finish optics (foil n, k) and presets of coefficients and finishes
``bands``                   where a bump tile's band lies (bottle or cap), how a thread is drawn
``relief_image``            relief images (height, colour code, normal maps), decoded and checked
``threads``                 how a thread is drawn (relief or true geometry) and laid on its band
``closures``                a closure as meridian chains of section segments with a material
``closure_parts``           what closures are made of: materials, parts, reliefs, gaps (values)
``closure_shapes``          the profile of each closure kind, sized from the finish
``cap_surfaces``            prints on the closure: its flat top and straight skirt, checks
``finish_check``            relief images and the closure's fit, for ``check_design``
==========================  ===================================================================
"""

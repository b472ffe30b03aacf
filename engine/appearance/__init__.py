"""Surface appearance: what covers the glass and how it lies on it.

Design rule: this package owns everything about what sits on the bottle's surface except the
ray tracing itself: labels now (images decoded to linear RGBA, finish regions, the exact map of
a label onto the outer wall and its flat die-line, the tables the tracer reads), bump tiles and
closures. It is plain Python and numpy (no Qt); :mod:`engine.tracer`
reads the data it produces and never the other way round.

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
``decal``                   the tracer's table per label: footprint, (s, t) grid, strain
``dieline``                 the flat shape a printer cuts, area, largest strain, warnings
``report``                  one label's area, die-line, largest strain and warnings (CLI, panel)
``dieline_files``           the die-line as SVG, PDF or DXF, to scale with dimensions
``compiled``                every label of a design packed into flat arrays for the kernels
``presets``                 finish optics (foil n, k) and presets of coefficients and finishes
``label_cli``               ``glassbench labels / dieline / label add``
``bump_tables``              bump tiles -> rows of numbers for the compiled relief functions
``relief_image``            relief images (height, colour code, normal maps) -> slope textures
``threads``                 the SPI/GPI finish table and thread sizes
``closures``                a closure as meridian chains of section segments with a material
``closure_parts``           what closures are made of: materials, parts, reliefs, gaps (values)
``closure_shapes``          the profile of each closure kind, sized from the finish
``cap_surfaces``            prints on the closure: its flat top and straight skirt, checks, tables
``finish_check``            relief images and the closure's fit, for ``check_design``
``commands``                ``glassbench cap / bump``
==========================  ===================================================================
"""

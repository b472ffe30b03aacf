"""Handing a design on to people who do not run glassbench: CAD solids, a glTF scene, a review
page, the glass plant's drawing.

Design rule: every export here is a pure function of a :class:`~engine.model.design.Design`
(and its assets) that writes through :func:`engine.io.atomic.replacing`, reads what it wrote
back before it replaces anything, and reports progress through an optional
``progress(fraction, message)`` callback, so the command line and the window share one code
path. Nothing here imports Qt; OpenCascade (``cadquery-ocp``) is imported only by the CAD
modules, and Node packages (the glTF validator, ``<model-viewer>``) are files the setup script
installs into ``web/node_modules``.

==================  ===================================================================
module              holds
==================  ===================================================================
``occ_profile``     section segments -> exact OpenCascade edges (lines, circles, ellipses;
                    offset ellipse arcs as B-splines within a tolerance), revolved solids
``cad_nonround``    non-round walls as B-spline patches fitted to the exact surface
``cad``             the glass, liquid and closure solids, exported and checked
``cad_write``       named solids written as STEP / IGES (XDE document) or BREP
``cad_check``       reading a CAD file back: validity, closedness, volumes per body
``gltf_build``      a small glTF 2.0 / GLB builder (buffers, accessors, textures)
``gltf_scene``      the complete scene: glass, liquid, labels, closure, camera
``gltf_labels``     label and print sheets: meshes over the surface, textures with alpha
``share``           the self-contained review page folder
``web``             where the Node packages are and how to run the glTF validator
``drawing``         the glass plant's drawing: layout of views, dimensions, table, notes
``drawing_views``   the views' curves at true size and the figures they are dimensioned by
``drawing_table``   the table, the notes and the title block, in words
``drawing_page``    one page as data: model and paper coordinates, dimensions, texts
``drawing_write``   the page written as PDF, SVG (matplotlib) or DXF (ezdxf)
==================  ===================================================================

The command line's side of these is :mod:`engine.cli.export`.
"""

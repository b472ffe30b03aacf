"""The records the kernels hand each other: named tuples instead of long positional signatures.

Design rule: numba passes a named tuple as the plain tuple it is (the same machine code), so a
kernel takes a record where it needs a group of values and reads fields by name. Records of
arrays are built once per render on the Python side (:mod:`engine.tracer.context`); records of
scalars are made per hit inside the kernels. Units mm; directions are unit vectors.

=================  ============================================================================
``Geometry``       the render objects' tables (:mod:`engine.tracer.tables.render_objects`): what the
                   exact intersectors search
``Scene``          a geometry with its media (``(ior, sigma_r, sigma_g, sigma_b)``, 1/mm) and
                   materials (``mat_i`` kinds, ``mat_f`` parameters, :mod:`.materials`)
``Scratch``        a worker's solver space: roots (16,), critical points (5,), band stack (64, 2)
``Work``           a worker's whole scratch: the tree's stack, the children of a hit, ``Scratch``
``Cutoffs``        where a sample's tree stops
``Pixels``         the samples a tile call traces, and ``PixelSums`` what it writes per pixel
``Hit``            the nearest true crossing of a ray: distance, object, part (segment or slab
                   row), the object's oriented unit normal there (object ``-1``: a miss)
``Interaction``    a branch at a surface: the point, the oriented geometric normal, the incoming
                   direction, the object, its part and material, the media on the ray's
                   (``inc``) and the far (``trn``) side
``Scattered``      what a surface did to a branch (:func:`.surface.scatter`)
``LabelTables``    the labels of a render (:mod:`engine.tracer.tables.labels`) and the record
                   buffers of a relabel
``FinishTables``   reliefs, frosting, the closure's light and the ground's caustics
                   (:mod:`engine.tracer.tables.finishes`, :mod:`engine.tracer.tables.caustics`)
=================  ============================================================================
"""
from __future__ import annotations

from collections import namedtuple

Geometry = namedtuple("Geometry", ("seg", "tab", "slab_f", "slab_i", "obj_i", "obj_f"))
Scene = namedtuple("Scene", ("geom", "media", "mat_i", "mat_f"))
Scratch = namedtuple("Scratch", ("roots", "crit", "ivals"))
Work = namedtuple("Work", ("stk_f", "stk_i", "stk_u", "kids", "order", "scratch"))
Hit = namedtuple("Hit", ("t", "obj", "part", "nx", "ny", "nz"))
#: The samples a tile call traces: pixel columns and rows, first sample and count of each.
Pixels = namedtuple("Pixels", ("cols", "rows", "first", "count"))
#: Per pixel of a tile call: RGB sums, sums of squared luminance, the first sample's signature,
#: the objects met, the shallowest depth each material was met; and the call's kernel counters.
PixelSums = namedtuple("PixelSums", ("sum", "sumsq", "sig", "mask", "depth", "counters"))
#: Where a sample's tree stops (:mod:`.integrator`): boundaries deep, branch weight, the Russian
#: roulette weight (0: none), boundaries per sample.
Cutoffs = namedtuple("Cutoffs", ("max_depth", "min_weight", "rr_weight", "max_nodes"))
#: A ray's crossing: the point, the oriented normal, the direction, the object, part, material
#: and the media either side; ``sidx`` the sample's index among its pixel's anti-aliasing
#: samples (-1: none, a centre or a probe) and ``pseed`` the node's place in the tree (a seed
#: of the pixel and the path of children to it, the same in every sample): where a surface
#: samples a lobe, it draws from a net over the pixel's samples there
#: (:func:`~.sampling.padded_sobol2`).
Interaction = namedtuple("Interaction", ("px", "py", "pz", "nx", "ny", "nz", "dx", "dy", "dz",
                                         "obj", "part", "mat", "inc", "trn", "sidx", "pseed"))
#: ``nk`` children written into the work's ``kids``; ``e*`` radiance sent back at once and ``a*``
#: a label sheet's share of it (summed apart for relabels), both per unit branch weight;
#: ``bits`` the labels consulted (object-mask bits); ``label_bits`` nonzero when a label answered
#: (the dominant path's signature takes them).
Scattered = namedtuple("Scattered", ("nk", "er", "eg", "eb", "ar", "ag", "ab", "bits", "label_bits"))
#: Decal rows and nodes, label rows, texels and their index, region codes and their index,
#: finish-region rows, label sizes (mm), the irradiance table, lights, place rows, the mask of
#: the objects labels lie on; then the record buffers of a relabel (hits, their count,
#: the current sample's rest, per sample its rest and hit range), zero rows when not recording.
LabelTables = namedtuple("LabelTables", ("rows", "nodes", "f", "texels", "tex_i", "codes", "region_i",
                                         "finish", "size", "irr", "lights", "place", "objects",
                                         "hit_f", "hit_i", "hit_n", "rest", "smp_f", "smp_i"))
#: Each object's first relief row and count, kinds, parameter rows, the relief atlas, the
#: closure's irradiance table and lights, the GGX albedo tables (glass, mirror, mirror mean), the
#: ground's caustic grids (irradiance over pi per light, ``(n, rows, cols, 3)``) and their rows,
#: the ground's sky grid (irradiance over pi per cell, ``(cells, 3)``) and its row
#: (:mod:`engine.tracer.tables.sky`), and the backdrop sweep's grid and its row
#: (:mod:`engine.tracer.tables.sweep`).
FinishTables = namedtuple("FinishTables", ("obj_rows", "kinds", "params", "atlas", "irradiance", "lights",
                                           "glass_albedo", "mirror_albedo", "mirror_avg", "caustics",
                                           "caustic_grid", "sky", "sky_grid", "sweep", "sweep_grid"))

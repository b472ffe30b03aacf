"""The records the kernels hand each other: named tuples instead of long positional signatures.

Design rule: numba passes a named tuple as the plain tuple it is (the same machine code), so a
kernel takes a record where it needs a group of values and reads fields by name. Records of
arrays are built once per render on the Python side (:mod:`engine.tracer.context`); records of
scalars are made per hit inside the kernels. Units mm; directions are unit vectors.

=================  ============================================================================
``Geometry``       the render objects' tables (:mod:`engine.tracer.tables.render_objects`): what the
                   exact intersectors search, with the bottle's plan outline (:mod:`.plans`)
``Scene``          a geometry with its media (``(ior, sigma_r, sigma_g, sigma_b)``, 1/mm) and
                   materials (``mat_i`` kinds, ``mat_f`` parameters, :mod:`.materials`)
``Tables``         what a tree reads, in one order everywhere: the scene, the labels, the
                   finishes, the environment's parameters and texels
``Ray``            a ray's origin (mm) and unit direction
``Recorder``       what a tree writes besides its radiance: the shallowest depth per material,
                   the counters, a copy of its intersection queries (benchmarks)
``Wall``           a swept wall in one slab, as the certified bands search it
``Scratch``        a worker's solver space: roots (16,), critical points (5,), band stack (64, 2)
``Work``           a worker's whole scratch: the tree's stack, the children of a hit, ``Scratch``
``Cutoffs``        where a sample's tree stops
``Pixels``         the samples a tile call traces, and ``PixelSums`` what it writes per pixel
``Hit``            the nearest true crossing of a ray: distance, object, part (segment or slab
                   row), the object's oriented unit normal there (object ``-1``: a miss)
``Interaction``    a branch at a surface: the point, the oriented geometric normal, the incoming
                   direction, the object, its part and material, the media on the ray's
                   (``inc``) and the far (``trn``) side, the shading normal and roughness
``Scattered``      what a surface did to a branch (:func:`.surface.scatter`)
``LabelTables``    the labels of a render (:mod:`engine.tracer.tables.labels`) and the record
                   buffers of a relabel
``FinishTables``   reliefs, frosting, the closure's light and the ground's caustics
                   (:mod:`engine.tracer.tables.finishes`, :mod:`engine.tracer.tables.caustics`)
=================  ============================================================================
"""
from __future__ import annotations

from collections import namedtuple

Geometry = namedtuple("Geometry", ("seg", "tab", "slab_f", "slab_i", "obj_i", "obj_f", "plan"))
Scene = namedtuple("Scene", ("geom", "media", "mat_i", "mat_f"))
#: What the tree of a sample reads (all built once per render, :mod:`engine.tracer.context`): the
#: :class:`Scene`, the :class:`LabelTables`, the :class:`FinishTables`, the environment's row
#: ``(scale, rotation rad, factor, ...)`` (:func:`engine.tracer.tables.stage.environment_params`)
#: and its texels ``(H, W, 3)`` (half-float bit patterns or float32).
Tables = namedtuple("Tables", ("scene", "labels", "finishes", "env", "texels"))
#: A ray: origin (mm) and unit direction.
Ray = namedtuple("Ray", ("ox", "oy", "oz", "dx", "dy", "dz"))
#: What a tree writes besides its radiance: ``depth`` (int64 per material, the shallowest depth
#: it met each is min-ed in), the kernel ``counters`` (:mod:`.integrator`'s ``C_*``), and a copy
#: of its intersection queries, ``rays`` float32 ``(N, 6 or 9)`` filled up to ``n_rays[0]``
#: (zero rows: none kept).
Recorder = namedtuple("Recorder", ("depth", "counters", "rays", "n_rays"))
#: One piece of an offset arc's table (:mod:`.revolved`): the segment table and its offset
#: tables, the table row ``k`` (rows ``k, k + 1`` bound the piece), the segment row ``i``, the
#: key coordinate ``axis`` (1: z, a wall; 0: r, a base) and the piece's parameter range
#: ``x0 <= x1`` (fractions of the arc's sweep).
OffsetPiece = namedtuple("OffsetPiece", ("seg", "tab", "k", "i", "axis", "x0", "x1"))
#: A non-round wall in one slab (:mod:`.bands`, :mod:`.swept`): the segment table and its
#: offset tables, the segment rows ``r0, r1, r2`` of its ``nsec`` sections, the cross-section
#: ``kind`` (:mod:`.outlines`), ``(c, s)``, the cosine and sine of the bottle's rotation, and
#: the table of a free plan outline's pieces (:mod:`.plans`; read only by ``OUTLINE`` walls).
Wall = namedtuple("Wall", ("seg", "tab", "r0", "r1", "r2", "nsec", "kind", "c", "s", "plan"))
Scratch = namedtuple("Scratch", ("roots", "crit", "ivals"))
Work = namedtuple("Work", ("stk_f", "stk_i", "stk_u", "kids", "order", "scratch"))
Hit = namedtuple("Hit", ("t", "obj", "part", "nx", "ny", "nz"))
#: The samples a tile call traces: pixel columns and rows, first sample and count of each.
Pixels = namedtuple("Pixels", ("cols", "rows", "first", "count"))
#: Per pixel of a tile call: RGB sums, sums of squared luminance, the first sample's signature,
#: the objects met, the shallowest depth each material was met; and the call's kernel counters;
#: then the sums of the denoiser's guides over the samples, ``(P, 6)``: albedo RGB and normal
#: (:func:`~.integrator.trace_sample`'s guide rule).
PixelSums = namedtuple("PixelSums", ("sum", "sumsq", "sig", "mask", "depth", "counters", "guide"))
#: Where a sample's tree stops (:mod:`.integrator`): boundaries deep, branch weight, the Russian
#: roulette weight (0: none), boundaries per sample.
Cutoffs = namedtuple("Cutoffs", ("max_depth", "min_weight", "rr_weight", "max_nodes"))
#: A ray's crossing: the point, the oriented normal, the direction, the object, part, material
#: and the media either side; ``sidx`` the sample's index among its pixel's anti-aliasing
#: samples (-1: none, a centre or a probe) and ``pseed`` the node's place in the tree (a seed
#: of the pixel and the path of children to it, the same in every sample): where a surface
#: samples a lobe, it draws from a net over the pixel's samples there
#: (:func:`~.sampling.padded_sobol2`). ``s`` is the shading normal, set once where the
#: interaction is made (pbrt's ``SetShadingGeometry``): the relief-bent normal, oriented as ``n``
#: (``s = n`` on a smooth surface), and ``rough`` the frosted roughness there (0: smooth)
#: (:func:`engine.tracer.kernels.surface.interaction`).
Interaction = namedtuple("Interaction", ("px", "py", "pz", "nx", "ny", "nz", "dx", "dy", "dz",
                                         "obj", "part", "mat", "inc", "trn", "sidx", "pseed",
                                         "sx", "sy", "sz", "rough"))
#: ``nk`` children written into the work's ``kids``; ``e*`` radiance sent back at once and ``a*``
#: a label sheet's share of it (summed apart for relabels), both per unit branch weight;
#: ``bits`` the labels consulted (object-mask bits); ``label_bits`` nonzero when a label answered
#: (the dominant path's signature takes them); ``g*`` the albedo a label's texel shows the
#: denoiser's guide (its colour times its cover, the uncovered rest white), -1 where no label
#: answered (:mod:`.integrator`'s guide rule reads the material instead).
Scattered = namedtuple("Scattered", ("nk", "er", "eg", "eb", "ar", "ag", "ab", "bits", "label_bits",
                                     "gr", "gg", "gb"))
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

"""The label tables of one render: compiled labels, the environment's irradiance, the lights.

Design rule: :func:`label_arrays` is the one place a design's labels become the tuple the
kernels take (layout ``LB_*`` of :mod:`engine.tracer.kernels.labels`): the flat arrays of
:func:`engine.appearance.compiled.compile_labels`, each label's size in mm (for emboss slopes),
the environment's diffuse irradiance table (:func:`engine.tracer.lighting.irradiance_table`,
computed once per environment and cached), the directional lights, each label's place row
(the surface and render object it lies on, :func:`engine.appearance.cap_surfaces.place_rows`)
and the bit mask of the objects labels lie on. A design without labels gets
:func:`empty_label_arrays`: zero-row tables of the same types, so the kernels compile once and
pay one length test per hit. Only the objects' numbering comes from the compiled scene, so a
label edit rebuilds only this tuple.
"""
from __future__ import annotations


import numpy as np

from ..appearance.cap_surfaces import P_COLS, place_rows
from ..appearance.compiled import F_COLS, L_COLS, compile_labels
from ..appearance.decal import D_COLS
from .kernels.labels import H_COLS
from .lighting import irradiance_table, light_table

def _tuple(cl, size, irr, lights, place, objects):
    return (cl.decal_rows, cl.decal_nodes, cl.label_f, cl.texels, cl.tex_i, cl.codes, cl.region_i,
            cl.finishes, size, irr, lights, place, np.array([objects], np.int64))


class _Empty:
    decal_rows = np.zeros((0, D_COLS))
    decal_nodes = np.zeros((0, 2), np.float32)
    label_f = np.zeros((0, L_COLS))
    texels = np.zeros((0, 4), np.float32)
    tex_i = np.zeros((0, 3), np.int64)
    codes = np.zeros(0, np.uint8)
    region_i = np.zeros((0, 3), np.int64)
    finishes = np.zeros((0, F_COLS))


def empty_label_arrays() -> tuple:
    """The tables of a design without labels (same types, read-only flags included, as
    :func:`label_arrays`, so the kernels are compiled once for both)."""
    irr = np.zeros((2, 2, 3), np.float32)
    for a in (irr,) + tuple(v for k, v in vars(_Empty).items() if isinstance(v, np.ndarray)):
        a.setflags(write=False)
    place = np.zeros((0, P_COLS))
    place.setflags(write=False)  # as place_rows gives it (numba types read-only arrays apart)
    return _tuple(_Empty, np.zeros((0, 2)), irr, np.zeros((0, 6)), place, 0)


def label_arrays(design, assets, env_texels, first_cap_object: int = 0) -> tuple:
    """The kernels' label tuple of ``design`` (module rule); ``env_texels`` the environment's
    unscaled texels, ``first_cap_object`` the render object of the closure's first part (the
    bottle's object count; prints on the closure lie on those objects). Raises
    :class:`engine.appearance.images.ArtworkError` for a bad image."""
    if not design.labels:
        return empty_label_arrays()
    cl = compile_labels(design, assets or {})
    size = np.array([[lab.width_mm, lab.height_mm] for lab in design.labels], float)
    place, objects = place_rows(design, first_cap_object)
    return _tuple(cl, size, irradiance_table(env_texels), light_table(design.lights), place, objects)


#: The record buffers of a call that does not record (never written: the kernels test the
#: hit table's length first), shared by every call.
_NO_RECORD = (np.zeros((0, H_COLS)), np.zeros((0, 2), np.int64), np.zeros(2, np.int64), np.zeros(3),
              np.zeros((0, 3)), np.zeros((0, 2), np.int64))
#: Hits a recording call makes room for per sample at first (it retries with more on overflow).
HITS_PER_SAMPLE = 2


def with_buffers(labels: tuple, samples: int = 0, hits: int | None = None) -> tuple:
    """``labels`` with the record buffers the kernels append hits to (layout ``LB_HIT_F ..
    LB_SMP_I`` of :mod:`engine.tracer.kernels.labels`): for ``samples`` samples and ``hits``
    hits (default :data:`HITS_PER_SAMPLE` a sample), or none (``samples = 0``: not recording)."""
    if samples <= 0:
        return labels + _NO_RECORD
    cap = HITS_PER_SAMPLE * samples + 64 if hits is None else int(hits)
    return labels + (np.zeros((cap, H_COLS)), np.zeros((cap, 2), np.int64), np.zeros(2, np.int64), np.zeros(3),
                     np.zeros((samples, 3)), np.zeros((samples, 2), np.int64))

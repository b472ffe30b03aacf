"""Relief under a label: a knurl band beneath the paper bends the label's shading normal (its
coat reflection and its lit diffuse term) where the band is and nowhere else, and the geometric
normal still decides media (a white furnace stays 1, no leaks, no mismatches)."""
from __future__ import annotations

import dataclasses

import numpy as np

from engine.appearance.sample import png_bytes
from engine.model.design import BumpTile, Label, LabelSide, Light, RenderSettings
from engine.tracer.context import RenderContext, TraceStats, trace_pixels, trace_rays
from engine.tracer.kernels.integrator import C_LEAKS, C_MISMATCH
from engine.tracer.kernels.labels import LABEL_BIT0
from tests.label_helpers import cylinder_shape, design_with
from tests.test_tracer import WHITE

R = 40.0
#: The knurl band (mm above the standing plane) crosses the label (80 .. 120 mm).
BAND = (95.0, 105.0)


def labelled(bumps=(), **label):
    kw = dict(z_mm=100.0, angle_deg=-90.0, height_mm=40.0, width_mm=60.0, diffuse=0.7, specular=0.3,
              transmission=0.1, front=LabelSide(color=(0.8, 0.3, 0.1)))
    kw.update(label)
    d = design_with(cylinder_shape(R), Label(**kw))
    return dataclasses.replace(d, bumps=tuple(bumps), lights=(Light((-0.3, -1.0, 0.4)),))


KNURL = BumpTile("knurl", "knurl", *BAND, repeat=90, depth=0.4, sharpness=0.8)


def _front(zs):
    """Rays from far on -y onto the label at heights ``zs`` and a spread of x, and their count."""
    xs = np.linspace(-12.0, 12.0, 25)
    o = np.array([[x, -300.0, z] for z in zs for x in xs])
    return o, np.tile([0.0, 1.0, 0.0], (len(o), 1))


def _radiance(design, rays, env=None):
    ctx = RenderContext.from_design(design, None, 8, 8, environment=env)
    out, counters = trace_rays(ctx, *rays)
    assert counters[C_LEAKS] == 0 and counters[C_MISMATCH] == 0
    return out


def test_a_knurl_band_bends_the_label_where_the_band_is_and_nowhere_else():
    plain, knurled = labelled(), labelled((KNURL,))
    inside = _front(np.linspace(BAND[0] + 1.0, BAND[1] - 1.0, 5))
    outside = _front([84.0, 88.0, 112.0, 116.0])
    a, b = _radiance(plain, inside), _radiance(knurled, inside)
    changed = np.abs(a - b).sum(-1) > 1e-4
    assert changed.mean() > 0.8  # the coat and the lit paper follow the ridges
    np.testing.assert_array_equal(_radiance(plain, outside), _radiance(knurled, outside))


def test_the_band_shades_the_sheet_not_its_colour():
    """Bent normals change how the paper is lit, not what it is: with a uniform environment and
    no lights nor coat the paper sends back its albedo K x colour, ridges or not."""
    kw = dict(specular=0.0, transmission=0.0)
    inside = _front([98.0, 100.0, 102.0])
    flat = dataclasses.replace(labelled(**kw), lights=())
    out = _radiance(dataclasses.replace(flat, bumps=(KNURL,)), inside, WHITE)
    np.testing.assert_allclose(out, np.tile(0.7 * np.array([0.8, 0.3, 0.1]), (len(out), 1)), atol=1e-12)


def test_white_furnace_with_a_label_over_relief_stays_one_without_leaks():
    """A white sheet that gives back all it receives (K + T = 1) over a knurl band, in a
    uniform white environment: every pixel exactly 1, no leaks, no mismatches. The artwork is
    half transparent, so the glass beneath takes the band's bent normal too, each branch kept
    on its side of the geometric surface."""
    half = np.full((16, 16, 4), 255, np.uint8)
    half[..., 3] = 128
    d = labelled((KNURL, BumpTile("diamond", "diamond", 60.0, 140.0, repeat=40, depth=0.3)),
                 diffuse=0.6, transmission=0.4, specular=0.2, front=LabelSide("half.png"),
                 back=LabelSide(color=(1.0, 1.0, 1.0)))
    d = dataclasses.replace(d, lights=(), render=RenderSettings(width=20, height=28))
    ctx = RenderContext.from_design(d, {"half.png": png_bytes(half)}, 20, 28, environment=WHITE)
    rows, cols = np.mgrid[0:28, 0:20]
    res = trace_pixels(ctx, cols.ravel(), rows.ravel(), 1, 2)
    img = res.sums / 2
    st = TraceStats()
    st.add_counters(res.counters)
    assert st.boundaries > 500 and np.count_nonzero(res.objects >> LABEL_BIT0) > 20  # the label was met
    assert st.escaped_inside == 0 and st.mismatches == 0
    assert np.all(np.abs(img - 1.0) < 1e-9)

"""Labels drawn by the tracer: furnace, orientation of both faces, finishes, hiding the glass,
relabel equal to a full re-render bit for bit, and designs without labels unchanged."""
from __future__ import annotations

import dataclasses
import os

import numpy as np
import pytest

from engine.tracer.tables import labels as C
from engine.color import srgb_to_linear
from engine.appearance.presets import FOIL_OPTICS
from engine.appearance.sample import png_bytes
from engine.model.design import FinishRegion, Label, LabelSide
from engine.tracer.context import RenderContext, trace_rays
from engine.tracer.tables.environment import EnvironmentMap
from engine.tracer.job import RenderJob
from engine.tracer.job_options import Replaces
from engine.tracer.sampling import Sampling
from engine.tracer.kernels import labels as KL
from engine.tracer.kernels.materials import fresnel_conductor

from tests.label_helpers import BORDEAUX, cylinder_shape, design_with

R = 40.0  # the cylinder's outer radius (mm)
WHITE = EnvironmentMap(np.ones((8, 16, 3), np.float32))


def quadrants(tl, tr, bl, br, n=64) -> bytes:
    """An artwork of four sRGB (0..255) quadrants, as PNG bytes."""
    px = np.empty((n, n, 3), np.uint8)
    h = n // 2
    px[:h, :h], px[:h, h:], px[h:, :h], px[h:, h:] = tl, tr, bl, br
    return png_bytes(px)


def lin(c):
    return srgb_to_linear(np.asarray(c, float) / 255.0).astype(float)


def flat_label(**kw) -> Label:
    """A label facing -y (the camera side of these tests), 40 mm tall, 60 mm around, at z 100."""
    base = dict(z_mm=100.0, angle_deg=-90.0, height_mm=40.0, width_mm=60.0, diffuse=0.7, specular=0.0,
                transmission=0.0)
    base.update(kw)
    return Label(**base)


def design(*labels, lights=()):
    return dataclasses.replace(design_with(cylinder_shape(R), *labels), lights=lights)


def radiance(d, assets, origins, directions, env=WHITE):
    ctx = RenderContext.from_design(d, assets, 8, 8, environment=env)
    out, counters = trace_rays(ctx, np.asarray(origins, float), np.asarray(directions, float))
    return out, counters


def towards(points, origin):
    p = np.asarray(points, float) - np.asarray(origin, float)
    return p / np.linalg.norm(p, axis=-1, keepdims=True)


def front_rays(xz):
    """Rays from far on -y to the wall points at ``(x, z)`` seen straight on (+y)."""
    o = np.array([[x, -500.0, z] for x, z in xz])
    return o, np.tile([0.0, 1.0, 0.0], (len(xz), 1))


def test_every_finish_kind_has_a_kernel_code_and_the_rows_carry_it():
    from engine.model.design import FINISH_KINDS
    assert set(KL.FINISH_CODES) == set(FINISH_KINDS)
    assert len(set(KL.FINISH_CODES.values())) == len(FINISH_KINDS) and 0 not in KL.FINISH_CODES.values()
    row = C._finish_row(FinishRegion(finish="silver_foil"))
    assert row[KL.LF_KIND] == KL.SILVER_FOIL and tuple(row[KL.LF_N:KL.LF_N + 3]) == FOIL_OPTICS["silver_foil"][0]


def test_furnace_paper_sends_back_its_albedo():
    """White uniform environment, no lights, paper with diffuse K, no coat, no transmission:
    the radiance of the sheet is K x colour (the irradiance table is exact in a furnace)."""
    colour = (0.6, 0.3, 0.2)
    d = design(flat_label(front=LabelSide(None, colour)))
    o, dirs = front_rays([(0.0, 100.0), (-15.0, 110.0)])
    out, counters = radiance(d, {}, o, dirs)
    np.testing.assert_allclose(out, np.tile(0.7 * np.array(colour), (2, 1)), rtol=1e-5)
    # an artwork: its decoded linear colour times K
    art = quadrants((200, 120, 40), (200, 120, 40), (200, 120, 40), (200, 120, 40))
    d = design(flat_label(front=LabelSide("a.png")))
    out, _ = radiance(d, {"a.png": art}, o, dirs)
    np.testing.assert_allclose(out, np.tile(0.7 * lin((200, 120, 40)), (2, 1)), rtol=1e-4)
    assert counters[1] == 0 and counters[2] == 0  # no leaks, no medium mismatches


def test_label_hides_the_glass_beneath():
    d0 = design()
    d1 = design(flat_label(front=LabelSide(None, (0.0, 0.0, 0.0))))
    o, dirs = front_rays([(0.0, 100.0), (0.0, 150.0)])
    bare, _ = radiance(d0, {}, o, dirs)
    covered, _ = radiance(d1, {}, o, dirs)
    assert bare[0].sum() > 0.5  # the glass sends light back and through
    np.testing.assert_array_equal(covered[0], 0.0)  # a black sheet without coat: nothing
    np.testing.assert_array_equal(covered[1], bare[1])  # above the label: the glass as before


def test_front_reads_left_to_right_with_azimuth_and_top_up():
    """Seen from outside (camera on -y, +x to its right): top left red, top right blue."""
    art = quadrants((255, 0, 0), (0, 0, 255), (0, 255, 0), (0, 0, 0))
    d = design(flat_label(front=LabelSide("q.png")))
    o, dirs = front_rays([(-10.0, 110.0), (10.0, 110.0), (-10.0, 90.0), (10.0, 90.0)])
    out, _ = radiance(d, {"q.png": art}, o, dirs)
    assert np.argmax(out[0]) == 0 and np.argmax(out[1]) == 2 and np.argmax(out[2]) == 1
    assert out[3].max() < 1e-6


def test_back_is_seen_from_inside_the_right_way_round():
    """From the bottle's axis looking at the label's back (towards -y, so -x is to the
    viewer's right), the back artwork's left half is on the viewer's left."""
    back = quadrants((0, 255, 0), (255, 255, 0), (0, 255, 0), (255, 255, 0))  # left green, right yellow
    d = design(flat_label(back=LabelSide("b.png"), front=LabelSide(None, (1.0, 1.0, 1.0))))
    eye = np.array([0.0, 0.0, 100.0])
    pts = np.array([[-12.0, -np.sqrt(R * R - 144.0), 100.0], [12.0, -np.sqrt(R * R - 144.0), 100.0]])
    out, counters = radiance(d, {"b.png": back}, np.tile(eye, (2, 1)), towards(pts, eye))
    right, left = out  # -x is the viewer's right
    assert right[0] > 3.0 * left[0]  # yellow has red, green has none
    assert counters[1] == 0 and counters[2] == 0


def test_gold_foil_is_a_conductor_reflection():
    key = ((1.0, 1.0, 1.0),)
    gold = FinishRegion("gold", "gold_foil", "chroma", key, 0.1, gloss=1.0)
    d = design(flat_label(front=LabelSide("w.png"), regions=(gold,)))
    white = quadrants(*[(255, 255, 255)] * 4)
    o, dirs = front_rays([(0.0, 100.0)])
    out, _ = radiance(d, {"w.png": white}, o, dirs)
    n, k = FOIL_OPTICS["gold_foil"]
    expect = [fresnel_conductor(1.0, n[c], k[c]) for c in range(3)]
    np.testing.assert_allclose(out[0], expect, rtol=1e-9)
    assert out[0][0] > out[0][1] > out[0][2]  # gold: red over green over blue


def test_clear_vinyl_shows_the_glass_exactly():
    key = ((1.0, 1.0, 1.0),)
    clear = FinishRegion("clear", "clear_vinyl", "chroma", key, 0.1)
    white = quadrants((255, 255, 255), (255, 255, 255), (10, 10, 10), (10, 10, 10))  # top half clear
    d0 = design()
    d1 = design(flat_label(front=LabelSide("w.png"), regions=(clear,)))
    o, dirs = front_rays([(0.0, 110.0), (0.0, 90.0)])
    bare, _ = radiance(d0, {}, o, dirs, env=graded_env())
    clear_out, _ = radiance(d1, {"w.png": white}, o, dirs, env=graded_env())
    np.testing.assert_array_equal(clear_out[0], bare[0])
    assert not np.array_equal(clear_out[1], bare[1])


def graded_env():
    """A non-uniform environment: brighter above than below (finishes then differ)."""
    v = np.linspace(1.0, 0.1, 16, dtype=np.float32)[:, None, None]
    return EnvironmentMap(np.ascontiguousarray(np.broadcast_to(v, (16, 32, 3))).astype(np.float32))


def test_each_finish_looks_different():
    key = ((1.0, 1.0, 1.0),)
    art = {"w.png": quadrants(*[(255, 255, 255)] * 4),
           "s.png": png_bytes(np.where(np.arange(64)[:, None, None] < 32, 255, 128).astype(np.uint8)
                              * np.ones((64, 64, 3), np.uint8))}
    finishes = {
        "paper": (),
        "gold": (FinishRegion("g", "gold_foil", "chroma", key, 0.1, gloss=0.9),),
        "silver": (FinishRegion("s", "silver_foil", "chroma", key, 0.1, gloss=0.9),),
        "clear": (FinishRegion("c", "clear_vinyl", "chroma", key, 0.1),),
        "clear_white": (FinishRegion("cw", "clear_vinyl_white", "chroma", key, 0.1),),
        "varnish": (FinishRegion("v", "varnish", "chroma", key, 0.1, gloss=0.95),),
    }
    o, dirs = front_rays([(0.0, 100.0), (8.0, 104.0)])
    seen = {}
    for name, regions in finishes.items():
        d = design(flat_label(front=LabelSide("w.png"), regions=regions, specular=0.05))
        seen[name] = radiance(d, art, o, dirs, env=graded_env())[0]
    names = list(seen)
    for i in range(len(names)):
        for j in range(i + 1, len(names)):
            assert not np.allclose(seen[names[i]], seen[names[j]], rtol=1e-3), (names[i], names[j])
    # emboss: near the edge of the top half (t = 0.5, z = 100 on the wall) bends the normal up or
    # down (the environment changes with height), the middle of the top half not
    emb = (FinishRegion("e", "emboss", "chroma", key, 0.1, depth_mm=0.5),)
    d_paper = design(flat_label(front=LabelSide("s.png")))
    d_emb = design(flat_label(front=LabelSide("s.png"), regions=emb))
    o, dirs = front_rays([(0.0, 100.4), (0.0, 110.0)])  # t = 0.49: just inside the region
    p, e = radiance(d_paper, art, o, dirs, env=graded_env())[0], radiance(d_emb, art, o, dirs, env=graded_env())[0]
    assert not np.allclose(p[0], e[0], rtol=1e-3)
    np.testing.assert_allclose(p[1], e[1], rtol=1e-12)


def test_lights_light_the_paper_and_labels_cast_shadows():
    """A light straight in front adds K c E cos / pi; a second label in its way blocks it."""
    from engine.model.design import Light
    colour = (0.5, 0.5, 0.5)
    light = Light(direction=(0.0, -1.0, 0.0), color=(1.0, 1.0, 1.0), intensity=2.0)
    o, dirs = front_rays([(0.0, 100.0)])
    dark = EnvironmentMap(np.zeros((8, 16, 3), np.float32))
    lit, _ = radiance(design(flat_label(front=LabelSide(None, colour)), lights=(light,)), {}, o, dirs, env=dark)
    np.testing.assert_allclose(lit[0], 0.7 * 0.5 * 2.0 / np.pi, rtol=1e-9)
    # from behind (+y): the light crosses the glass twice and meets the label's back face
    behind = Light(direction=(0.0, 1.0, 0.0), intensity=2.0)
    d = design(flat_label(front=LabelSide(None, colour), transmission=0.2, diffuse=0.7), lights=(behind,))
    through, _ = radiance(d, {}, o, dirs, env=dark)
    assert 0.0 < through[0][0] < 0.2 * 0.5 * 2.0 / np.pi
    blocker = flat_label(angle_deg=90.0, front=LabelSide(None, colour))
    blocked, _ = radiance(dataclasses.replace(d, labels=d.labels + (blocker,)), {}, o, dirs, env=dark)
    np.testing.assert_array_equal(blocked[0], 0.0)


# ---------------------------------------------------------------------------------- relabel
KW = dict(width=40, height=56, spp=4, threads=1)


def _job(d, assets, **kw):
    job = RenderJob(d, assets, **KW, **kw).start()
    job.wait()
    assert job.error is None
    return job


@pytest.fixture(scope="module")
def relabel_case():
    from engine.model.design import Light
    art_a = quadrants((200, 30, 30), (30, 30, 200), (240, 240, 240), (20, 20, 20))
    art_b = quadrants((30, 160, 30), (200, 200, 30), (240, 240, 240), (20, 20, 20))
    from engine.model.design import Camera
    d = dataclasses.replace(design(flat_label(front=LabelSide("a.png"), specular=0.05, transmission=0.1),
                                   lights=(Light(),)),
                            camera=Camera(eye=(0.0, -400.0, 110.0), target=(0.0, 0.0, 100.0), fov_y_deg=20.0))
    assets = {"a.png": art_a, "b.png": art_b}
    first = _job(d, assets)
    return d, assets, first


def _relabel_equals_full(prev, d2, assets, changed):
    rel = _job(d2, assets, replaces=Replaces(prev, changed))
    full = _job(d2, assets)
    assert rel.context.geometry is prev.context.geometry  # the scene was not rebuilt
    np.testing.assert_array_equal(rel.image(), full.image())
    np.testing.assert_array_equal(rel.film.objects, full.film.objects)
    return rel, full


def test_relabel_artwork_swap_recomputes_only_label_terms(relabel_case):
    d, assets, first = relabel_case
    lab = d.labels[0]
    d2 = dataclasses.replace(d, labels=(dataclasses.replace(lab, front=LabelSide("b.png")),))
    rel, full = _relabel_equals_full(first, d2, assets, {"labels"})
    assert rel.relabelled_pixels == 0 and rel.recoloured_pixels > 0
    assert rel.stats.rays_cast < full.stats.rays_cast / 20
    assert not np.array_equal(rel.image(), first.image())  # the new artwork shows
    # and again from the relabelled job (its records are complete)
    d3 = dataclasses.replace(d, labels=(dataclasses.replace(lab, front=LabelSide("a.png")),))
    rel3, _ = _relabel_equals_full(rel, d3, assets, {"labels"})
    np.testing.assert_array_equal(rel3.image(), first.image())


def test_a_window_relabel_equals_a_full_window_render(relabel_case):
    """The window's tolerance is chosen from the whole image's estimate (adaptive.split_tolerance):
    a relabel replays the waves and so chooses it as the full render does, bit for bit."""
    from engine.tracer.adaptive import DISPLAY_NOISE, SPLIT_LADDER
    d, assets, _ = relabel_case
    win = dict(sampling=Sampling(noise_space="display", noise_target=DISPLAY_NOISE))
    first = _job(d, assets, **win)
    assert first.tolerance / DISPLAY_NOISE in SPLIT_LADDER
    lab = d.labels[0]
    for d2 in (dataclasses.replace(d, labels=(dataclasses.replace(lab, front=LabelSide("b.png")),)),
               dataclasses.replace(d, labels=(dataclasses.replace(lab, diffuse=0.4),))):
        rel, full = _job(d2, assets, replaces=Replaces(first, {"labels"}), **win), _job(d2, assets, **win)
        assert rel.context.geometry is first.context.geometry  # a relabel, not a new scene
        np.testing.assert_array_equal(rel.image(), full.image())
        np.testing.assert_array_equal(rel.sample_counts(), full.sample_counts())
        assert rel.tolerance == full.tolerance


def test_relabel_coefficients_and_moves_trace_what_they_touch(relabel_case):
    d, assets, first = relabel_case
    lab = d.labels[0]
    d2 = dataclasses.replace(d, labels=(dataclasses.replace(lab, diffuse=0.4),))
    rel, full = _relabel_equals_full(first, d2, assets, {"labels"})
    assert 0 < rel.relabelled_pixels < KW["width"] * KW["height"]
    d3 = dataclasses.replace(d, labels=(dataclasses.replace(lab, z_mm=108.0),))
    rel, full = _relabel_equals_full(first, d3, assets, {"labels"})
    assert rel.relabelled_pixels > 0
    from engine.model.design import Light
    d4 = dataclasses.replace(d, lights=(Light(direction=(1.0, -1.0, 0.5)),))
    _relabel_equals_full(first, d4, assets, {"lights"})


def test_labelled_render_has_no_leaks_or_mismatches(relabel_case):
    first = relabel_case[2]
    assert first.stats.escaped_inside == 0 and first.stats.mismatches == 0
    assert first.film.objects.max() >= (1 << KL.LABEL_BIT0)  # some pixel met the label


def test_design_without_labels_renders_as_before():
    """Bordeaux at 48 x 64, 4 spp, rendered before labels existed (tests/data; commit 50cb5c9^,
    re-rendered there with today's ``kernels/sampling.py``, ``adaptive.py`` and ``display.py``
    when sample positions became Sobol and the centre joined the adaptive scatter, with the
    roulette rule of 05be126, and with the studio's texels rounded to half floats and back when
    the kernels began to read half floats: that commit's float32 lookups then add the same
    numbers; when final renders' adaptive rounds became a Neyman allocation with the default
    tolerance 0.005, again when their neighbour share became 0.3 and the tolerance 0.002,
    re-rendered from the tree just before, which matched the old reference bit for bit, with
    only the adaptive rule changed): bit for bit."""
    from engine.files.project import load_project
    ref = np.load(os.path.join(os.path.dirname(__file__), "data", "bordeaux_nolabel_48x64_spp4.npy"))
    d, a = load_project(BORDEAUX)
    job = RenderJob(d, a, width=48, height=64, spp=4, threads=1).start()
    job.wait()
    assert job.error is None and job.records is None  # nothing recorded without labels
    np.testing.assert_array_equal(job.image(), ref)


def test_labelled_sample_renders_from_the_command_line(tmp_path):
    from engine.cli import main
    sample = os.path.join(os.path.dirname(BORDEAUX), "labelled.glassbench")
    out = tmp_path / "out.png"
    assert main(["render", sample, "-o", str(out), "--width", "30", "--height", "40", "--spp", "1"]) == 0
    assert out.stat().st_size > 0


def test_label_record_overflow_traces_again_with_room(monkeypatch, relabel_case):
    """A recording call with too little room for hits traces again with more: same results,
    every hit kept (the record's ranges cover all of them)."""
    import engine.tracer.tables.labels as TL
    from engine.tracer.context import trace_pixels
    d, assets, _ = relabel_case
    ctx = RenderContext.from_design(d, assets, KW["width"], KW["height"])
    cols, rows = np.meshgrid(np.arange(KW["width"]), np.arange(KW["height"]))
    cols, rows = cols.ravel(), rows.ravel()
    plain = trace_pixels(ctx, cols, rows, 0, 2)
    monkeypatch.setattr(TL, "HITS_PER_SAMPLE", 0)  # room for 64 hits only
    rec = trace_pixels(ctx, cols, rows, 0, 2, record_labels=True)
    np.testing.assert_array_equal(rec.sums, plain.sums)
    smp_f, smp_i, hit_f, hit_i = rec.label_record
    assert len(hit_f) > 64 and smp_i[-1, 1] == len(hit_f) and len(smp_f) == 2 * len(cols)

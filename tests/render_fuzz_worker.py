"""Renders random valid designs under a memory limit; run by tests/test_tracer_properties.py.

Not a test module itself (pytest does not collect it): the address-space limit must not touch
the test process. Usage: ``python -m tests.render_fuzz_worker LIMIT_BYTES EXAMPLES``. Prints one
line per design and ``OK peak_rss_mb=... growth_mb=...`` at the end; exits 1 on a failure.
"""
from __future__ import annotations

import math
import resource
import sys

import numpy as np
from hypothesis import HealthCheck, given, settings, strategies as st

from engine.errors import GlassbenchError
from engine.geometry.section import Section
from engine.geometry.segments import Arc, Line
from engine.geometry.shape import BottleShape
from engine.model.design import Camera, Design, Glass, Liquid, RenderSettings
from engine.tracer.job import RenderJob
from engine.tracer.job_options import Workers


def rss_mb() -> float:
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def stepped(r_body, h_body, r_neck, h_shoulder, h_top):
    return Section((Line((0, 0), (r_body, 0)), Line((r_body, 0), (r_body, h_body)),
                    Line((r_body, h_body), (r_neck, h_shoulder)), Line((r_neck, h_shoulder), (r_neck, h_top))),
                   (False, False, False))


def smooth(rb, rh, zb, rs, th, ln, rc, hn):
    """A G1 round section: base, heel arc, body, convex shoulder arc, line, concave neck arc, finish."""
    R = rb + rh
    segs = [Line((0, 0), (rb, 0)), Arc((rb, rh), rh, (rb, 0), (R, rh), "ccw"), Line((R, rh), (R, zb))]
    c = (R - rs, zb)
    p = (c[0] + rs * math.cos(th), c[1] + rs * math.sin(th))
    segs.append(Arc(c, rs, (R, zb), p, "ccw"))
    t = (-math.sin(th), math.cos(th))
    q = (p[0] + t[0] * ln, p[1] + t[1] * ln)
    cc = (q[0] + rc * t[1], q[1] - rc * t[0])
    neck = (cc[0] - rc, cc[1])
    segs += [Line(p, q), Arc(cc, rc, q, neck, "cw"), Line(neck, (neck[0], neck[1] + hn))]
    return Section(tuple(segs), (False,) + (True,) * (len(segs) - 2))


@st.composite
def designs(draw):
    kind = draw(st.sampled_from(["round", "round_smooth", "rounded_square", "rounded_rect", "oval"]))
    wall = draw(st.floats(0.5, 3.0))
    base = wall + draw(st.floats(0.0, 5.0))
    R = draw(st.floats(15.0, 45.0))
    rn = draw(st.floats(wall + 4.0, min(R - 2.0, 16.0)))
    hb, hs = draw(st.floats(40.0, 120.0)), draw(st.floats(10.0, 50.0))
    ht = hb + hs + draw(st.floats(10.0, 40.0))
    if kind == "round":
        secs = {"profile": stepped(R, hb, rn, hb + hs, ht)}
    elif kind == "round_smooth":
        rb = draw(st.floats(8.0, 30.0))
        secs = {"profile": smooth(rb, draw(st.floats(wall + 1.0, 10.0)), hb, draw(st.floats(wall + 2.0, 20.0)),
                                  draw(st.floats(0.3, 1.3)), draw(st.floats(2.0, 20.0)), draw(st.floats(2.0, 12.0)),
                                  draw(st.floats(5.0, 30.0)))}
    elif kind == "rounded_square":
        k = draw(st.floats(1.0, 1.35))
        secs = {"u": stepped(R, hb, rn, hb + hs, ht), "v": stepped(k * R, hb, rn, hb + hs, ht)}
    elif kind == "rounded_rect":
        a, b = R, R * draw(st.floats(0.6, 1.0))
        c = draw(st.floats(wall + 1.0, b))
        secs = {"half_width": stepped(a, hb, rn, hb + hs, ht), "half_depth": stepped(b, hb, rn, hb + hs, ht),
                "corner": stepped(c, hb, rn, hb + hs, ht)}
    else:
        secs = {"half_width": stepped(R, hb, rn, hb + hs, ht),
                "half_depth": stepped(R * draw(st.floats(0.6, 1.0)), hb, rn, hb + hs, ht)}
    cs = "round" if kind.startswith("round") and kind not in ("rounded_square", "rounded_rect") else kind
    shape = BottleShape(cs, secs, wall, base, rotation_deg=draw(st.floats(0.0, 90.0)) if cs != "round" else 0.0)
    fill = draw(st.one_of(st.none(), st.floats(0.0, 1.0)))
    top = shape.z_top
    liquid = None if fill is None else Liquid(ior=1.33, absorption=(0.01, 0.02, 0.0),
                                              fill_value=base + 0.02 + fill * (top - base - 0.03))
    az = draw(st.floats(0.0, 2 * math.pi))
    dist = draw(st.floats(2.5, 8.0)) * top
    eye = (dist * math.cos(az), dist * math.sin(az), draw(st.floats(-0.5, 1.5)) * top)
    return Design(shape=shape, glass=Glass(ior=draw(st.floats(1.3, 1.9)), absorption=(0.005, 0.0, 0.01)),
                  liquid=liquid, camera=Camera(eye=eye, target=(0.0, 0.0, 0.5 * top), fov_y_deg=25.0),
                  render=RenderSettings(width=16, height=16, spp=2, max_depth=draw(st.sampled_from([16, 64, 256])),
                                        min_weight=draw(st.sampled_from([1e-5, 1e-3, 1e-2]))))


STATE = {"n": 0, "rss": []}


@settings(max_examples=int(sys.argv[2]) if len(sys.argv) > 2 else 20, deadline=None, derandomize=True,
          suppress_health_check=list(HealthCheck))
@given(designs())
def check(design):
    try:
        job = RenderJob(design, threads=2, workers=Workers(tile=8)).start()
    except GlassbenchError:
        return
    job.wait()
    if isinstance(job.error, GlassbenchError):  # an invalid shape: refused, fine
        return
    assert job.error is None, repr(job.error)
    img = job.image()
    assert np.all(np.isfinite(img)) and img.min() >= 0.0
    assert job.stats.escaped_inside == 0, f"light leaked out of a medium: {design}"
    assert job.stats.mismatches == 0, f"a hit from the wrong side: {design}"
    STATE["n"] += 1
    STATE["rss"].append(rss_mb())
    print(f"{design.shape.cross_section:15s} fill {design.liquid is not None!s:5} segments "
          f"{job.stats.rays_cast:7d} rss {STATE['rss'][-1]:.0f} MB", flush=True)


def main() -> int:
    limit = int(sys.argv[1])
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    from engine.tracer.warmup import warm_up

    warm_up()
    base = rss_mb()
    check()
    rss = STATE["rss"]
    growth = max(rss[len(rss) // 2:]) - max(rss[: max(1, len(rss) // 2)]) if len(rss) >= 4 else 0.0
    print(f"OK rendered={STATE['n']} peak_rss_mb={max(rss + [base]):.0f} growth_mb={growth:.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

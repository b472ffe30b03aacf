"""Tessellation (engine.geometry.tessellate): closed, outward, within tolerance, converging volumes."""
import math
import subprocess
import sys
from datetime import timedelta
from pathlib import Path

import numpy as np
import pytest
from hypothesis import assume, example, given, settings, strategies as st
from scipy.spatial import cKDTree

from engine.geometry import capacity as cap
from engine.geometry.body import BottleBody
from engine.errors import SectionError, WallError
from engine.geometry.validate import body_profile
from engine.geometry.shape import BottleShape
from engine.geometry.tessellate import (BODY_PARTS, MAX_WALL_TRIANGLES, refine_heights, tessellate_body,
                                       tessellate_liquid, wall_heights)
from engine.limits import MIN_TOL_MM
from tests.tessellate_worker import SHARP_INNER_CORNERS, huge_torus_bottle, stepped_bottle
from tests.test_offset import (cornered_punt_section, heel_through_ring_section, punt_section, spec_shape,
                               stepped_section)


def oval_shape():
    return BottleShape("oval", {"half_width": stepped_section(30.0, 100.0, 12.0, 130.0, 160.0),
                                "half_depth": stepped_section(20.0, 100.0, 12.0, 130.0, 160.0)}, 2.0, 5.0,
                       rotation_deg=30.0)


def punt_shape():
    return BottleShape("round", {"profile": punt_section()}, 3.0, 4.0)


SHAPES = {"round": lambda: spec_shape(1), "square": lambda: spec_shape(3), "ellipse": lambda: spec_shape(4),
          "oval": oval_shape, "punt": punt_shape,
          "cornered punt": lambda: BottleShape("round", {"profile": cornered_punt_section()}, 2.5, 4.0),
          "heel punt": lambda: BottleShape("round", {"profile": heel_through_ring_section()}, 2.5, 3.0)}


@pytest.mark.parametrize("name", SHAPES)
def test_body_mesh_is_closed_outward_with_unit_normals(name):
    mesh = tessellate_body(SHAPES[name](), 0.1)
    assert mesh.is_watertight()
    assert mesh.signed_volume() > 0
    np.testing.assert_allclose(np.linalg.norm(mesh.normals, axis=1), 1.0, atol=1e-12)
    v, f = mesh.vertices, mesh.faces
    g = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    g /= np.linalg.norm(g, axis=1, keepdims=True)
    agree = np.einsum("ij,ij->i", g, mesh.normals[f].mean(axis=1))
    assert np.all(agree > 0.5)
    assert set(np.unique(mesh.part)) == set(range(len(BODY_PARTS)))


def _dense_tree(chain):
    pts = np.concatenate([s.point(np.linspace(0, 1, 20001)) for s in chain])
    return cKDTree(pts)


def _samples(mesh, part_id):
    f = mesh.faces[mesh.part == part_id]
    v = mesh.vertices[f]
    # centroids and edge midpoints: where a flat triangle strays furthest from a curved surface
    return np.concatenate([v.mean(axis=1), 0.5 * (v[:, 0] + v[:, 1]), 0.5 * (v[:, 1] + v[:, 2])])


@pytest.mark.parametrize("name", ["round", "ellipse", "punt", "cornered punt", "heel punt"])
def test_round_chordal_deviation_within_tolerance(name):
    tol = 0.1
    shape = SHAPES[name]()
    mesh = tessellate_body(shape, tol)
    sp = body_profile(shape).sections[0]
    chains = {"outer": sp.outer_wall, "inner": sp.inner_wall, "base_outer": sp.outer_base,
              "base_inner": sp.inner_base}
    worst = 0.0
    for k, part in enumerate(BODY_PARTS):
        q = _samples(mesh, k)
        if part == "rim":
            dev = np.abs(q[:, 2] - shape.z_top)
        else:
            dev = _dense_tree(chains[part]).query(np.stack([np.hypot(q[:, 0], q[:, 1]), q[:, 2]], 1))[0]
        worst = max(worst, float(dev.max()))
    assert worst <= tol
    assert worst > 0.3 * tol  # and not needlessly finer than asked


def _non_round_wall_deviation(shape, mesh, part: str) -> float:
    """Largest distance (mm) of the ``outer`` / ``inner`` wall's triangles from the exact wall,
    where the section is steep enough for the first-order distance to be reliable."""
    body = BottleBody(shape)
    rot = math.radians(shape.rotation_deg)
    q = _samples(mesh, BODY_PARTS.index(part))
    x = math.cos(rot) * q[:, 0] + math.sin(rot) * q[:, 1]
    y = -math.sin(rot) * q[:, 0] + math.cos(rot) * q[:, 1]
    states = body.wall_radii(part, q[:, 2])
    radii = [s[0] for s in states]
    sd, gx, gy, d = shape.xs.signed_distance(radii, x, y)
    steep = np.min([s[2] for s in states], axis=0) > 0.2  # first-order distance is reliable
    gz = sum(d[j] * states[j][1] / np.maximum(states[j][2], 1e-9) for j in range(len(states)))
    return float((np.abs(sd) / np.sqrt(gx ** 2 + gy ** 2 + gz ** 2))[steep].max())


@pytest.mark.parametrize("name", ["square", "oval"])
def test_non_round_wall_deviation_within_tolerance(name):
    tol = 0.1
    shape = SHAPES[name]()
    mesh = tessellate_body(shape, tol)
    for part in ("outer", "inner"):
        assert _non_round_wall_deviation(shape, mesh, part) <= tol, part


def test_volume_converges_to_exact_as_tolerance_shrinks():
    for name in ("round", "square"):
        shape = SHAPES[name]()
        exact = cap.glass_volume_cm3(shape) * 1000
        errs = [abs(tessellate_body(shape, tol).signed_volume() - exact) / exact for tol in (0.2, 0.05, 0.0125)]
        assert errs[0] > errs[1] > errs[2]
        assert errs[2] < 5e-4


@pytest.mark.parametrize("name", SHAPES)
def test_liquid_mesh_closed_and_matches_capacity(name):
    shape = SHAPES[name]()
    prof = body_profile(shape)
    for fill in (prof.z_ib + 2.0, 0.5 * (prof.z_ib + prof.z_top)):
        mesh = tessellate_liquid(shape, fill, 0.05)
        assert mesh.is_watertight()
        exact = cap.capacity_ml(shape, fill) * 1000
        v = mesh.vertices[mesh.faces]
        area = 0.5 * np.linalg.norm(np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]), axis=1).sum()
        # flat triangles within 0.05 mm of the surface move the volume by at most ~ tol x area
        assert abs(mesh.signed_volume() - exact) <= 0.05 * area * 0.5
        top = mesh.faces[mesh.part == 2]
        assert np.allclose(mesh.vertices[top][..., 2], fill, atol=1e-9)


def test_bad_tolerance_and_fill_rejected():
    with pytest.raises(ValueError, match="tolerance"):
        tessellate_body(spec_shape(1), 0.0)
    with pytest.raises(ValueError, match="outside the cavity"):
        tessellate_liquid(spec_shape(1), 3.0)


def test_per_segment_wall_step_is_meshed_as_a_ledge():
    shape = BottleShape("round", {"profile": stepped_section(30.0, 100.0, 12.0, 130.0, 170.0)}, 2.0, 6.0,
                        wall_per_segment=(4.0, 2.5, 2.0))
    mesh = tessellate_body(shape, 0.05)
    assert mesh.is_watertight()
    exact = cap.glass_volume_cm3(shape) * 1000
    assert mesh.signed_volume() == pytest.approx(exact, rel=2e-3)
    inner = mesh.vertices[mesh.faces[mesh.part == 1]].reshape(-1, 3)
    at_step = inner[np.abs(inner[:, 2] - 100.0) < 1e-9]
    radii = np.unique(np.round(np.hypot(at_step[:, 0], at_step[:, 1]), 6))
    assert radii.min() == pytest.approx(26.0) and radii.max() > 26.5  # both sides of the ledge


def _assert_closed_and_close_in_volume(shape, mesh, tol):
    """Watertight, and the volume within ``tol`` x half the area of the capacity module's."""
    assert mesh.is_watertight()
    exact = cap.glass_volume_cm3(shape) * 1000
    v = mesh.vertices[mesh.faces]
    area = 0.5 * np.linalg.norm(np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]), axis=1).sum()
    assert abs(mesh.signed_volume() - exact) <= tol * area * 0.5


# Each example takes well under a second; the deadline (generous for a shared machine) turns a
# regression into a failure, and tests/tessellate_worker.py bounds its memory.
@settings(max_examples=12, deadline=timedelta(seconds=10))
@given(u=st.floats(15.0, 40.0), ratio=st.floats(1.0, 1.35), neck=st.floats(6.0, 14.0),
       w=st.floats(1.0, 3.5), kind=st.sampled_from(["rounded_square", "oval", "round"]))
@example(*SHARP_INNER_CORNERS[0], "rounded_square")
@example(*SHARP_INNER_CORNERS[1], "rounded_square")
def test_random_bottles_are_watertight_and_close_in_volume(u, ratio, neck, w, kind):
    shape = stepped_bottle(kind, u, ratio, neck, w)
    try:
        cap.glass_volume_cm3(shape)
    except (SectionError, WallError):
        assume(False)  # e.g. a wall too thick for the neck: not this test's subject
    _assert_closed_and_close_in_volume(shape, tessellate_body(shape, 0.1), 0.1)


@pytest.mark.parametrize("args", SHARP_INNER_CORNERS)
def test_sharp_inner_corner_is_meshed_small_closed_and_within_tolerance(args):
    """A rounded square whose inner corner radius (about 0.3 mm) is a tenth of the outer one:
    the angles must follow the inner wall, and the rings stay few (they once grew 2^16-fold)."""
    shape = stepped_bottle("rounded_square", *args)
    mesh = tessellate_body(shape, 0.1)
    assert len(mesh.faces) < 12_000  # 4,900 to 7,400 now; before, over 30,000 rings and out of memory
    _assert_closed_and_close_in_volume(shape, mesh, 0.1)
    for part in ("outer", "inner"):
        assert _non_round_wall_deviation(shape, mesh, part) <= 0.1, part


def test_corner_turning_round_with_height_stays_within_tolerance():
    """A rounded rectangle whose 1.5 mm inner corner grows and moves round up the shoulder: the
    angles must also fit the heights between those that first decide them."""
    names = ("half_width", "half_depth", "corner")
    shape = BottleShape("rounded_rect", {nm: stepped_section(r, 46.74, 15.28, 82.01, 97.01)
                                         for nm, r in zip(names, (19.14, 11.49, 2.68))}, 1.19, 1.62)
    mesh = tessellate_body(shape, 0.02)
    assert mesh.is_watertight()
    for part in ("outer", "inner"):
        assert _non_round_wall_deviation(shape, mesh, part) <= 0.02, part


def test_ring_refinement_ends_even_where_the_angles_are_too_coarse():
    """Halving bands cannot cure a ring's own chord sag: 32 angles round a 0.28 mm inner corner
    sag far more than 0.1 mm, and the refinement must still end with few rings."""
    body = BottleBody(stepped_bottle("rounded_square", *SHARP_INNER_CORNERS[0]))
    theta = np.linspace(0.0, 2 * math.pi, 32, endpoint=False)
    chains = [sp.inner_wall for sp in body.profile.sections]
    z0 = wall_heights(chains, 0.1, body.profile.z_ib, body.profile.z_top)
    z = refine_heights(body, "inner", z0, theta, 0.1)
    assert len(z) < 200  # 8 rings to start: 91 now, 51,371 before


def test_nasty_bottles_tessellate_under_a_memory_limit():
    """The sharp-corner bottles mesh, and a 2 m bottle at the finest tolerance is refused, in a
    process limited to 1 GiB of address space: a regression fails instead of eating the machine."""
    limit = 1024 ** 3
    out = subprocess.run([sys.executable, "-m", "tests.tessellate_worker", str(limit)],
                         cwd=Path(__file__).resolve().parents[1], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stdout[-2000:] + out.stderr[-4000:]
    last = out.stdout.strip().splitlines()[-1]
    assert last.startswith("OK"), last
    assert float(last.split("=")[1]) < 1024


def test_a_wall_past_the_triangle_budget_is_refused_naming_a_coarser_tolerance():
    with pytest.raises(ValueError, match="coarser tolerance") as err:
        tessellate_body(huge_torus_bottle(), MIN_TOL_MM)
    message = str(err.value)
    assert f"{MAX_WALL_TRIANGLES:,}" in message
    least = float(message.rsplit("at least ", 1)[1].split(" mm")[0])
    assert least > MIN_TOL_MM


def test_corner_rings_carry_each_sides_exact_normal():
    shape = BottleShape("round", {"profile": stepped_section(30.0, 100.0, 12.0, 130.0, 170.0)}, 2.0, 6.0)
    mesh = tessellate_body(shape, 0.1)
    assert mesh.is_watertight()
    outer = mesh.faces[mesh.part == 0]
    z_mid = mesh.vertices[outer][..., 2].mean(axis=1)
    body_faces = outer[z_mid < 100.0]  # the vertical body: every vertex normal exactly radial
    assert np.abs(mesh.normals[body_faces][..., 2]).max() < 1e-12
    shoulder = outer[(z_mid > 100.0) & (z_mid < 130.0)]
    n = mesh.normals[shoulder]
    expect_nz = 18.0 / math.hypot(18.0, 30.0)  # outward normal of the shoulder line, z part
    np.testing.assert_allclose(n[..., 2], expect_nz, atol=1e-12)
    # the same on a non-round bottle whose sections turn at the same heights
    oval = tessellate_body(oval_shape(), 0.1)
    assert oval.is_watertight()
    outer = oval.faces[oval.part == 0]
    z_mid = oval.vertices[outer][..., 2].mean(axis=1)
    assert np.abs(oval.normals[outer[z_mid < 100.0]][..., 2]).max() < 1e-9
    # shoulders 30 -> 12 and 20 -> 12 mm over 30 mm: n_z between 8/hypot(8, 30) and 18/hypot(18, 30)
    assert oval.normals[outer[(z_mid > 100.0) & (z_mid < 130.0)]][..., 2].min() > 0.25


@pytest.mark.parametrize("name", ["public_1", "public_2", "public_3", "public_4"])
def test_interface_meshes_close_the_glass_and_the_liquid(name):
    """glass|air + glass|liquid is the glass solid; glass|liquid turned + liquid|air the liquid."""
    from benchmarks.oracle_spec import spec_to_design
    from benchmarks.paths import ORACLE_SPECS
    from engine.geometry.tessellate import Mesh, tessellate_interfaces, tessellate_liquid
    from engine.model.fill import fill_height_of

    design, _ = spec_to_design(str(ORACLE_SPECS / f"{name}.json"))
    h = fill_height_of(design)
    parts = tessellate_interfaces(design.shape, h, 0.05)

    def join(meshes, flips):
        v, f, off = [], [], 0
        for m, flip in zip(meshes, flips):
            v.append(m.vertices)
            f.append((m.faces[:, ::-1] if flip else m.faces) + off)
            off += len(m.vertices)
        v, f = np.concatenate(v), np.concatenate(f)
        return Mesh(v, f, np.zeros_like(v), np.zeros(len(f), np.int64), ("x",))

    glass = join([parts["glass_air"]] + ([parts["glass_liquid"]] if h is not None else []), [False, False])
    body = tessellate_body(design.shape, 0.05)
    assert glass.is_watertight()
    # the fill line adds rings, so the chords differ a little from the body's own mesh
    assert abs(glass.signed_volume() - body.signed_volume()) < 1e-4 * body.signed_volume()
    if h is None:
        assert set(parts) == {"glass_air"}
        return
    liquid = join([parts["glass_liquid"], parts["liquid_air"]], [True, False])
    assert liquid.is_watertight()
    ref = tessellate_liquid(design.shape, h, 0.05)
    assert abs(liquid.signed_volume() - ref.signed_volume()) < 1e-4 * ref.signed_volume()

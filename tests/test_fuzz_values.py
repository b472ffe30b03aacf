"""Values out of their physics (issue 11, classes 1 and 3): every value a user can pass is checked
against its bound before work starts, at load, in the command line and in the engine's checks,
with the field named; accepted values keep the ray tree finite and radiance inside float32."""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from engine import cli, limits
from engine.errors import DesignError, MAX_MESSAGE_CHARS, ProjectError
from engine.files.project import save_project
from engine.operations.check import check_design
from engine.geometry import capacity
from engine.model import fill
from engine.model.check import check_values
from engine.model.design import Camera, Environment, Glass, Liquid, RenderSettings
from engine.tracer.tables.environment import EnvironmentMap, clean_texels, environment_from_design
from tests.test_fuzz_files import cylinder_design

FUZZ = settings(max_examples=120, deadline=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
anything = st.one_of(st.floats(allow_nan=True, allow_infinity=True),
                     st.sampled_from([0.0, -0.0, -1.0, 1e-300, 1e300, 180.0, 360.0, 1e-6]))


def refusal(design):
    """The ``DesignError`` message for ``design``, or ``None`` when it is accepted."""
    try:
        check_design(design, {})
    except DesignError as exc:
        assert len(str(exc)) <= MAX_MESSAGE_CHARS
        return str(exc)
    return None


# ------------------------------------------------------------------------- render settings
@FUZZ
@given(w=st.integers(-10, 1 << 20), h=st.integers(-10, 1 << 20), spp=st.integers(-10, 1 << 33),
       depth=st.integers(-10, 1 << 20), weight=anything)
def test_accepted_render_settings_keep_the_work_bounded(w, h, spp, depth, weight):
    message = refusal(cylinder_design(render=RenderSettings(w, h, spp, depth, weight)))
    if message is None:
        assert w * h <= limits.MAX_PIXELS and spp <= limits.SPP_RANGE[1]
        # rays per camera sample <= max_depth / min_weight: finite, and bounded
        assert depth / weight <= limits.MAX_DEPTH_RANGE[1] / limits.MIN_WEIGHT_RANGE[0]
    else:
        assert message.startswith("design.render.")


@pytest.mark.parametrize("weight", [0.0, -1e-3, 1e-300, 1e-6])
def test_min_weight_that_would_never_stop_is_refused(weight):
    with pytest.raises(DesignError, match="design.render.min_weight"):
        check_values(cylinder_design(render=RenderSettings(8, 8, 1, 64, weight)))


@FUZZ
@given(flag=st.sampled_from(["--width", "--height", "--spp"]),
       value=st.one_of(st.integers(-(2 ** 40), 2 ** 40), st.sampled_from([2 ** 31, 100_000, 0, -1])))
def test_cli_sizes_are_checked_before_the_project_is_even_read(flag, value, capsys):
    # The project does not exist: a size out of range must be named first, nothing rendered.
    status = cli.main(["render", "/nonexistent/p.glassbench", "-o", "/nonexistent/out.png", flag, str(value)])
    err = capsys.readouterr().err
    lo, hi = {"--width": limits.WIDTH_RANGE, "--height": limits.HEIGHT_RANGE, "--spp": limits.SPP_RANGE}[flag]
    assert status == 2 and err.count("\n") == 1
    assert (flag in err) == (not lo <= value <= hi)


def test_cli_size_combined_with_the_project_is_checked_too(tmp_path, capsys):
    path = tmp_path / "p.glassbench"
    save_project(path, cylinder_design(render=RenderSettings(16384, 1024, 1)))
    assert cli.main(["render", str(path), "-o", str(tmp_path / "o.png"), "--height", "2048"]) == 2
    assert "more than 16777216 pixels" in capsys.readouterr().err
    assert not (tmp_path / "o.png").exists()


# --------------------------------------------------------------------------------- physics
@FUZZ
@given(mode=st.sampled_from(["height", "volume"]), value=st.one_of(anything, st.floats(-10, 400)))
def test_fill_level_is_inside_the_cavity_or_refused(mode, value):
    design = cylinder_design(liquid=Liquid(fill_mode=mode, fill_value=value))
    message = refusal(design)
    shape = design.shape
    if message is not None:
        assert message.startswith("design.liquid.fill_value")
        return
    h = fill.fill_height_mm(shape, design.liquid)
    assert shape.base_thickness + fill.MIN_DEPTH_MM <= h <= shape.z_top
    assert 0.0 < fill.fill_volume_ml(shape, design.liquid) <= capacity.brimful_ml(shape) * (1 + 1e-12)


@FUZZ
@given(density=anything)
def test_glass_mass_is_positive_for_every_accepted_density(density):
    design = cylinder_design(glass=Glass(density_g_cm3=density))
    if refusal(design) is None:
        assert capacity.glass_mass_g(design.shape, density) > 0.0
    else:
        assert not limits.DENSITY_RANGE[0] <= density <= limits.DENSITY_RANGE[1] or math.isnan(density)


@FUZZ
@given(eye=st.tuples(anything, anything, anything), target=st.sampled_from([(0.0, 0.0, 50.0), None]),
       up=st.sampled_from([(0.0, 0.0, 1.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0)]), fov=anything)
def test_accepted_cameras_give_a_proper_view(eye, target, up, fov):
    from engine.tracer.camera import PinholeCamera
    cam = Camera(eye, eye if target is None else target, up, fov)
    message = refusal(cylinder_design(camera=cam))
    if message is not None:
        assert message.startswith("design.camera.")
        return
    rays = PinholeCamera.from_design(cam, 4, 4).rays(np.array([0.0, 4.0]), np.array([0.0, 4.0]))[1]
    assert np.all(np.isfinite(rays)) and 0.0 < fov < 180.0


def test_camera_refusals_name_the_problem():
    same = Camera((1.0, 2.0, 3.0), (1.0, 2.0, 3.0), (0.0, 0.0, 1.0), 30.0)
    with pytest.raises(DesignError, match="looks nowhere"):
        check_values(cylinder_design(camera=same))
    along = Camera((0.0, 0.0, 300.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), 30.0)
    with pytest.raises(DesignError, match="design.camera.up is parallel"):
        check_values(cylinder_design(camera=along))
    for fov in (0.0, 180.0, 360.0, -30.0):
        with pytest.raises(DesignError, match="design.camera.fov_y_deg"):
            check_values(cylinder_design(camera=Camera(fov_y_deg=fov)))


# ---------------------------------------------------------------------------- environment
texel_values = st.one_of(st.floats(width=32, allow_nan=True, allow_infinity=True),
                         st.sampled_from([-1.0, -np.inf, np.inf, np.nan, 3e38, limits.MAX_TEXEL * 10]))


@FUZZ
@given(values=st.lists(texel_values, min_size=12, max_size=12), scale=anything)
def test_radiance_of_an_accepted_environment_is_finite_and_non_negative_in_float32(values, scale):
    env = Environment("file", "e.exr", scale, 0.0)
    try:
        check_values(cylinder_design(environment=env))
    except DesignError as exc:
        assert str(exc).startswith("design.environment.scale")
        with pytest.raises(ValueError):
            environment_from_design(env, {"e.exr": np.zeros((2, 2, 3), np.float32)})
        return
    texels = np.array(values, dtype=np.float32).reshape(2, 2, 3)
    emap = environment_from_design(env, {"e.exr": texels})
    assert np.all((emap.texels >= 0) & (emap.texels <= limits.MAX_TEXEL))
    d = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])
    # Every sample of the largest image at the largest scale, summed, still fits in float32.
    worst = emap.lookup(d).astype(np.float64) * limits.MAX_PIXELS * limits.SPP_RANGE[1]
    assert np.all(np.isfinite(worst.astype(np.float32))) and np.all(worst >= 0)


def test_cleaning_rule_is_exact():
    tex = np.array([np.nan, -np.inf, -2.0, 0.5, np.inf, 1e30], dtype=np.float32)
    out = clean_texels(tex.copy())
    np.testing.assert_array_equal(out, np.array([0, 0, 0, 0.5, limits.MAX_TEXEL, limits.MAX_TEXEL], np.float32))


def test_environment_map_keeps_its_public_fields():
    emap = environment_from_design(Environment(scale=2.0, rotation_deg=15.0))
    assert isinstance(emap, EnvironmentMap) and emap.texels.dtype == np.float32
    assert emap.texels.ndim == 3 and emap.texels.shape[2] == 3
    assert (emap.scale, emap.rotation_deg) == (2.0, 15.0)


def test_every_range_is_checked_in_project_terms():
    cases = {"design.glass.ior": dataclasses.replace(cylinder_design().glass, ior=0.5),
             "design.glass.absorption[1]": Glass(absorption=(0.0, -1.0, 0.0))}
    for field, glass in cases.items():
        with pytest.raises(ProjectError, match=field.replace("[", r"\[").replace("]", r"\]")):
            check_design(cylinder_design(glass=glass), {})


@FUZZ
@given(mode=st.sampled_from(["height", "volume"]), value=anything, top=st.floats(20.0, 150.0))
def test_a_fitted_liquid_always_fits_and_a_fitting_one_is_kept(mode, value, top):
    from engine.geometry.section import Section
    from engine.geometry.segments import Line
    from engine.geometry.shape import BottleShape
    sec = Section((Line((0, 0), (30, 0)), Line((30, 0), (30, top))))
    shape = BottleShape("round", (("profile", sec),), 3.0, 6.0)
    liquid = Liquid(fill_mode=mode, fill_value=value)
    fitted = fill.fitted_liquid(shape, liquid)
    fill.check_fill(shape, fitted)
    try:
        fill.check_fill(shape, liquid)
    except DesignError:
        assert fitted != liquid
    else:
        assert fitted is liquid


@FUZZ
@given(argv=st.lists(st.sampled_from(["info", "render", "new", "export-mesh", "x", "y.png", "z.glassbench",
                                      "-o", "--width", "--spp", "abc", "-3", "2147483648", "--from-dxf",
                                      "--bogus", "--json", "--tol", "1e-9", "--wall", "nan"]), max_size=7))
def test_every_failing_command_line_is_one_line_with_status_2(argv, capsys):
    import app.main as app_main
    for entry in (cli.main, app_main.main):
        if entry is app_main.main and (not argv or argv[0] not in cli.SUBCOMMANDS):
            argv = ["--bogus"] + argv  # the window's own parser, made to fail before any window
        try:
            status = entry(argv)
        except SystemExit as exc:
            status = exc.code
        out = capsys.readouterr()
        assert status == 2, (argv, out)
        assert out.err.count("\n") == 1 and len(out.err) <= MAX_MESSAGE_CHARS + 120, out.err

"""Warnings for designs that are valid geometry but cannot be made or filled (engine, no Qt)."""
from __future__ import annotations

import dataclasses
import os

import pytest

from engine.files.project import load_project
from engine.geometry.editing import delete_segment, place_joint
from engine.model import advice, fill, tint

RESOURCES = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "resources")


def _sample(name):
    return load_project(os.path.join(RESOURCES, f"{name}.glassbench"))[0]


@pytest.mark.parametrize("name", ["bordeaux", "square", "jar"])
def test_the_samples_have_nothing_to_warn_about(name):
    assert advice.design_warnings(_sample(name)) == []


def test_a_neck_bore_too_narrow_to_fill_is_named_with_its_numbers():
    d = _sample("bordeaux")
    shape = d.shape.with_section("profile", place_joint(d.shape.primary, 5, r=3.44))
    (warning,) = advice.design_warnings(dataclasses.replace(d, shape=shape, liquid=None))
    assert "0.88 mm across" in warning and "3.44 mm mouth radius" in warning and "3 mm wall" in warning


def test_a_liquid_left_at_the_brim_after_deleting_segments_is_named():
    jar = _sample("jar")
    shape = jar.shape.with_section("profile", delete_segment(jar.shape.primary, 2))
    liquid = fill.fitted_liquid(shape, jar.liquid)
    (warning,) = advice.design_warnings(dataclasses.replace(jar, shape=shape, liquid=liquid))
    assert "at the brim" in warning and "headspace" in warning
    above = advice.design_warnings(dataclasses.replace(jar, shape=shape), fill_height_mm=44.0)
    assert "14.0 mm above the brim" in above[0]


def test_thin_glass_is_named():
    d = _sample("jar")
    thin = dataclasses.replace(d.shape, wall_thickness=0.5)
    assert any("0.5 mm wall" in w for w in advice.design_warnings(dataclasses.replace(d, shape=thin)))


def test_tint_by_thickness_round_trips_and_a_thinner_reference_is_stronger():
    amber = (0x7A / 255, 0x4F / 255, 0x10 / 255)
    a10 = tint.absorption_from_transmittance(amber, 10.0)
    assert tint.transmittance(a10, 10.0) == pytest.approx(amber)
    a5 = tint.absorption_from_transmittance(amber, 5.0)
    assert a5 == pytest.approx(tuple(2 * x for x in a10))
    assert tint.transmittance(a10, 6.0)[2] < 0.25, "two 3 mm walls of this amber are clearly amber"
    with pytest.raises(ValueError):
        tint.absorption_from_transmittance(amber, 0.0)


@pytest.mark.parametrize("name, ml, new", [("Bordeaux 750 ml", 500, "Bordeaux 500 ml"),
                                           ("Bordeaux 750 ml", 750.2, None),
                                           ("Spirits 70cl", 500, "Spirits 50cl"),
                                           ("Jar 0,5 l", 330, "Jar 0,33 l"),
                                           ("Untitled", 300, None)])
def test_a_name_that_quotes_a_volume_follows_the_fill(name, ml, new):
    assert advice.updated_name(name, ml) == new

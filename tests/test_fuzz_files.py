"""Hostile project files (issue 11, classes 1, 2, 5 and 6): the loader never hangs, nothing is
saved that cannot be opened again, every error is one bounded line, and small archives cannot
claim large amounts of memory."""
from __future__ import annotations

import dataclasses
import json

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from engine import limits
from engine.errors import MAX_MESSAGE_CHARS, ProjectError
from engine.files.jsontext import nesting_depth
from engine.files.project import Limits, load_project, load_project_bytes, save_project
from engine.files.serialize import design_to_dict, document_from_design
from engine.model.design import Camera, Design, Environment, Light, Liquid, RenderSettings
from engine.geometry.section import Section
from engine.geometry.segments import Line
from engine.geometry.shape import BottleShape
from tests.test_project_fuzz import zip_bytes

FUZZ = settings(max_examples=60, deadline=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])


def cylinder_design(**parts) -> Design:
    sec = Section((Line((0, 0), (30, 0)), Line((30, 0), (30, 100))))
    base = Design(BottleShape("round", (("profile", sec),), 3.0, 6.0),
                  liquid=Liquid(fill_mode="height", fill_value=50.0),
                  render=RenderSettings(8, 8, 1), name="Cylinder")
    return dataclasses.replace(base, **parts)


# ------------------------------------------------------------------ class 1: linear JSON scan
def reference_depth(text: bytes) -> int:
    """Bracket depth outside strings, one character at a time (the obvious linear scan)."""
    depth = best = 0
    in_string = escaped = False
    for c in text.decode("utf-8", "replace"):
        if in_string:
            if escaped:
                escaped = False
            elif c == "\\":
                escaped = True
            elif c == '"':
                in_string = False
        elif c == '"':
            in_string = True
        elif c in "[{":
            depth += 1
            best = max(best, depth)
        elif c in "]}":
            depth -= 1
    return best


json_noise = st.text(alphabet='[]{}"\\ab:,é', max_size=200)
json_values = st.recursive(st.one_of(st.none(), st.integers(), st.text(alphabet='[]{}"\\x\n', max_size=8)),
                           lambda inner: st.one_of(st.lists(inner, max_size=4),
                                                   st.dictionaries(st.text(alphabet='[]"\\k', max_size=4),
                                                                   inner, max_size=3)),
                           max_leaves=20)


@FUZZ
@given(text=st.one_of(json_noise, json_values.map(json.dumps)))
def test_depth_scan_agrees_with_a_character_scan(text):
    # On text that is not JSON the figure may differ (the parser then refuses the text anyway).
    raw = text.encode("utf-8")
    assert nesting_depth(raw) == reference_depth(raw) or not _valid_json(raw)


def _valid_json(raw: bytes) -> bool:
    try:
        json.loads(raw)
    except ValueError:
        return False
    return True


@FUZZ
@given(value=json_values)
def test_depth_of_valid_json_is_exact(value):
    raw = json.dumps(value).encode("utf-8")
    assert nesting_depth(raw) == reference_depth(raw)


def test_unterminated_string_of_escaped_quotes_is_refused():
    # The 258-byte file that hung the loader, scaled up: one string of 60,000 escaped quotes.
    text = '{"format_version": 1, "design": "' + '\\"' * 60_000
    with pytest.raises(ProjectError, match="not valid JSON"):
        load_project_bytes(zip_bytes([("project.json", text)]))


def test_deep_nesting_is_refused_before_parsing():
    with pytest.raises(ProjectError, match="nested deeper than 64"):
        load_project_bytes(zip_bytes([("project.json", "[" * 100_000 + "]" * 100_000)]))


# --------------------------------------------------------- class 2: never write what cannot be read
texts = st.one_of(st.text(max_size=30), st.sampled_from(["\ud800", "a\udfffb", "x" * (limits.MAX_TEXT_CHARS + 1),
                                                          "y" * limits.MAX_TEXT_CHARS]))
numbers = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.sampled_from([0.0, -1.0, 1e-300, 1e300]))


@st.composite
def hostile_designs(draw):
    parts = {}
    if draw(st.booleans()):
        parts["name"] = draw(texts)
    if draw(st.booleans()):
        parts["notes"] = draw(texts)
    if draw(st.booleans()):
        parts["lights"] = (Light(),) * draw(st.sampled_from([0, 1, limits.MAX_LIST_ITEMS, limits.MAX_LIST_ITEMS + 1]))
    if draw(st.booleans()):
        parts["render"] = RenderSettings(draw(st.integers(-5, 1 << 20)), draw(st.integers(-5, 1 << 20)),
                                         draw(st.integers(-5, 1 << 40)), draw(st.integers(-5, 1 << 20)),
                                         draw(numbers))
    if draw(st.booleans()):
        parts["camera"] = Camera((0.0, -300.0, 50.0), (0.0, draw(numbers), 50.0), (0.0, 0.0, 1.0), draw(numbers))
    if draw(st.booleans()):
        parts["environment"] = Environment(scale=draw(numbers), rotation_deg=draw(numbers))
    if draw(st.booleans()):
        parts["liquid"] = Liquid(fill_mode=draw(st.sampled_from(["height", "volume", "weight"])),
                                 fill_value=draw(numbers))
    return cylinder_design(**parts)


@FUZZ
@given(design=hostile_designs())
def test_a_saved_project_always_opens_again(tmp_path_factory, design):
    path = tmp_path_factory.mktemp("save") / "p.glassbench"
    try:
        save_project(path, design, {})
    except ProjectError as exc:
        assert not path.exists(), "a refused save wrote a file"
        assert len(str(exc)) <= MAX_MESSAGE_CHARS
        return
    loaded, assets = load_project(path)
    assert design_to_dict(loaded) == design_to_dict(design) and assets == {}


def test_names_notes_and_lists_at_the_limit_round_trip_and_past_it_are_refused(tmp_path):
    at_limit = cylinder_design(name="n" * limits.MAX_TEXT_CHARS, lights=(Light(),) * limits.MAX_LIST_ITEMS)
    save_project(tmp_path / "ok.glassbench", at_limit)
    assert load_project(tmp_path / "ok.glassbench")[0] == at_limit
    for past in (dict(notes="n" * (limits.MAX_TEXT_CHARS + 1)), dict(lights=(Light(),) * (limits.MAX_LIST_ITEMS + 1)),
                 dict(name="lone \ud800")):
        with pytest.raises(ProjectError, match=f"design.{next(iter(past))}"):
            save_project(tmp_path / "no.glassbench", cylinder_design(**past))
    assert not (tmp_path / "no.glassbench").exists()


def test_a_lone_surrogate_is_refused_on_load_too():
    # JSON can spell one ("\ud800"); the loader refuses what the writer refuses.
    doc = document_from_design(cylinder_design())
    text = json.dumps(doc).replace('"Cylinder"', '"bad \\ud800"')
    with pytest.raises(ProjectError, match="design.name holds a character that cannot be stored"):
        load_project_bytes(zip_bytes([("project.json", text)]))


# ------------------------------------------------------------- class 5: bounded one-line messages
@FUZZ
@given(path=st.sampled_from(["name", "notes", "render", "camera", "liquid", "shape"]),
       value=st.one_of(st.tuples(st.text(max_size=4), st.integers(100_001, 200_000)).map(lambda t: (t[0] or "\n") * t[1]),
                       st.integers(min_value=10 ** 40, max_value=10 ** 41),
                       st.integers(4097, 6000).map(lambda n: ["x"] * n)))
def test_every_load_error_is_one_bounded_line(path, value):
    doc = document_from_design(cylinder_design())
    doc["design"][path] = value
    try:
        load_project_bytes(zip_bytes([("project.json", json.dumps(doc))]))
    except ProjectError as exc:
        message = str(exc)
        assert len(message) <= MAX_MESSAGE_CHARS and "\n" not in message
    else:
        pytest.fail("a hostile value was accepted")


def test_an_unknown_field_inside_a_segment_is_refused():
    doc = document_from_design(cylinder_design())
    doc["design"]["shape"]["sections"]["profile"]["segments"][1]["bulge"] = 0.5
    with pytest.raises(ProjectError, match="line segment has unknown field.*'bulge'"):
        load_project_bytes(zip_bytes([("project.json", json.dumps(doc))]))


# ------------------------------------------------------------ class 6: small files, bounded memory
def test_a_small_archive_cannot_declare_large_assets():
    doc = json.dumps(document_from_design(cylinder_design()))
    blob = zip_bytes([("project.json", doc)] + [(f"assets/a{i}.exr", b"\0" * (8 << 20)) for i in range(4)])
    assert len(blob) < 200_000  # 32 MiB of zeros compress a thousandfold
    with pytest.raises(ProjectError, match="declares more than"):
        load_project_bytes(blob)
    small = Limits(json_bytes=1 << 20, unpack_ratio=10_000)  # the ratio, not the bytes, decides
    design, assets = load_project_bytes(blob, small)
    assert sorted(assets) == [f"a{i}.exr" for i in range(4)]


@FUZZ
@given(ratio=st.integers(1, 400), size=st.integers(0, 1 << 16))
def test_unpacked_bytes_never_exceed_the_budget(ratio, size):
    doc = json.dumps(document_from_design(cylinder_design()))
    blob = zip_bytes([("project.json", doc), ("assets/a.bin", b"\0" * size)])
    lim = Limits(json_bytes=1 << 14, unpack_ratio=ratio)
    budget = min(lim.total_bytes, lim.json_bytes + ratio * len(blob))
    try:
        _, assets = load_project_bytes(blob, lim)
    except ProjectError as exc:
        assert "declares more than" in str(exc)
        assert len(doc.encode()) + size > budget
    else:
        assert len(doc.encode()) + len(assets["a.bin"]) <= budget

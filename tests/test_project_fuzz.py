"""Fuzzing the project loader: whatever the bytes, it returns a Design or raises ProjectError."""
from __future__ import annotations

import io
import json
import zipfile

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from engine.model.design import Design
from engine.errors import ProjectError
from engine.files.project import Limits, load_project_bytes, save_project
from tests.test_project import ASSETS, make_design

FUZZ = settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
SMALL = Limits(members=16, json_bytes=1 << 18, asset_bytes=1 << 16, total_bytes=1 << 18)

json_leaf = st.one_of(st.none(), st.booleans(), st.integers(-2 ** 70, 2 ** 70),
                      st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=20))
json_value = st.recursive(json_leaf, lambda inner: st.one_of(
    st.lists(inner, max_size=4), st.dictionaries(st.text(max_size=8), inner, max_size=4)),
    max_leaves=12)


def good_doc() -> dict:
    from engine.files.serialize import document_from_design
    return document_from_design(make_design(), "fuzz")


def zip_bytes(members) -> bytes:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", compression=zipfile.ZIP_DEFLATED) as zf:
        for name, data in members:
            zf.writestr(name, data)
    return buf.getvalue()


def doc_archive(doc) -> bytes:
    return zip_bytes([("project.json", json.dumps(doc))] +
                     [("assets/" + k, v) for k, v in ASSETS.items()])


def paths(node, prefix=()):
    """Every (container path, key) in a JSON tree."""
    out = []
    items = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else ()
    for k, v in items:
        out.append(prefix + (k,))
        out.extend(paths(v, prefix + (k,)))
    return out


def load_or_project_error(blob: bytes, limits=SMALL):
    try:
        design, assets = load_project_bytes(blob, limits)
    except ProjectError as exc:
        assert str(exc)  # the error names a problem
        return None
    assert isinstance(design, Design) and isinstance(assets, dict)
    return design


def format0_doc() -> dict:
    d = make_design()
    return {"format_version": 0, "name": "proto",
            "shape": {"cross_section": "round", "sections": {"profile": d.shape.primary.to_dicts()},
                      "wall": 2.5, "base": 5.0, "rotation_deg": 0.0},
            "glass": {"ior": 1.5, "absorption": [0, 0, 0.01]},
            "liquid": {"ior": 1.33, "absorption": [0.1, 0.1, 0.1], "fill_height": 80.0},
            "camera": {"eye": [0, -400, 100], "target": [0, 0, 60], "up": [0, 0, 1], "fov_y_deg": 30},
            "render": {"width": 200, "height": 300, "spp": 4}}


def mutate(data, doc) -> dict:
    """Replace, delete or add one to three values anywhere in the JSON tree."""
    all_paths = paths(doc)
    for _ in range(data.draw(st.integers(1, 3))):
        path = data.draw(st.sampled_from(all_paths))
        parent = doc
        try:
            for k in path[:-1]:
                parent = parent[k]
            op = data.draw(st.sampled_from(["replace", "delete", "add"]))
            if op == "replace":
                parent[path[-1]] = data.draw(json_value)
            elif op == "delete":
                del parent[path[-1]]
            elif isinstance(parent, dict):
                parent[data.draw(st.text(max_size=8))] = data.draw(json_value)
            elif isinstance(parent, list):
                parent.append(data.draw(json_value))
        except (KeyError, IndexError, TypeError):
            continue  # an earlier mutation removed or replaced this path
    return doc


@FUZZ
@given(data=st.data())
def test_mutated_documents(data):
    load_or_project_error(doc_archive(mutate(data, good_doc())))


@FUZZ
@given(data=st.data())
def test_mutated_format_0_documents(data):
    # Migration code reads untrusted input too.
    load_or_project_error(doc_archive(mutate(data, format0_doc())))


@FUZZ
@given(text=st.one_of(st.text(max_size=200), json_value.map(json.dumps)))
def test_garbage_json_text(text):
    assert load_or_project_error(zip_bytes([("project.json", text)])) is None


@FUZZ
@given(data=st.data())
def test_mutated_archive_bytes(data):
    blob = bytearray(doc_archive(good_doc()))
    for _ in range(data.draw(st.integers(1, 6))):
        op = data.draw(st.sampled_from(["flip", "truncate", "insert", "delete"]))
        pos = data.draw(st.integers(0, len(blob) - 1))
        if op == "flip":
            blob[pos] ^= data.draw(st.integers(1, 255))
        elif op == "truncate":
            del blob[pos:]
        elif op == "insert":
            blob[pos:pos] = data.draw(st.binary(min_size=1, max_size=8))
        else:
            del blob[pos:pos + data.draw(st.integers(1, 16))]
        if not blob:
            blob = bytearray(b"\0")
    load_or_project_error(bytes(blob))


def test_unmutated_archive_loads(tmp_path):
    # The fuzzers' starting point is a valid project (else they would prove nothing).
    design = load_or_project_error(doc_archive(good_doc()))
    assert design == make_design()
    assert load_or_project_error(doc_archive(format0_doc())).name == "proto"
    save_project(tmp_path / "x.glassbench", make_design(), ASSETS)
    assert load_or_project_error((tmp_path / "x.glassbench").read_bytes()) == make_design()


"""Reading a CAD file back with OpenCascade and checking each solid in it.

Design rule: a CAD export is only as good as what a CAD system reads from it, so the check
reads the written file with OpenCascade's own reader (STEP and IGES through the XDE document,
which keeps the bodies' names; BREP as one compound in the bodies' order), never the shapes
still in memory, and asks of every solid: is it valid (``BRepCheck_Analyzer``), is it closed
(every shell closed, no free edge), and is its volume the one the trade numbers give, to
:data:`VOLUME_RTOL` relative. The report is plain numbers, so the command
line prints it and tests assert on it. Units mm and mm^3.
"""
from __future__ import annotations

from pathlib import Path

from OCP.BRep import BRep_Builder, BRep_Tool
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepGProp import BRepGProp
from OCP.BRepTools import BRepTools
from OCP.GProp import GProp_GProps
from OCP.IGESCAFControl import IGESCAFControl_Reader
from OCP.ShapeAnalysis import ShapeAnalysis_FreeBounds
from OCP.STEPCAFControl import STEPCAFControl_Reader
from OCP.TCollection import TCollection_ExtendedString
from OCP.TDataStd import TDataStd_Name
from OCP.OCP.collections import Sequence_TDF_Label as TDF_LabelSequence
from OCP.TDocStd import TDocStd_Document
from OCP.TopAbs import TopAbs_ShapeEnum
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS, TopoDS_Shape
from OCP.XCAFDoc import XCAFDoc_DocumentTool

from .occ_profile import CadError

#: Largest relative difference between a solid's volume and the trade numbers' figure.
VOLUME_RTOL = 1e-5
#: Relative accuracy asked of OpenCascade's volume integration.
VOLUME_EPS = 1e-9


def _solids(shape) -> list:
    out, it = [], TopExp_Explorer(shape, TopAbs_ShapeEnum.TopAbs_SOLID)
    while it.More():
        out.append(TopoDS.Solid(it.Current()))
        it.Next()
    return out


def _read_xde(path: str, reader) -> list[tuple[str, object]]:
    doc = TDocStd_Document(TCollection_ExtendedString("XmlXCAF"))
    reader.SetNameMode(True)
    if not reader.Perform(path, doc):
        raise CadError(f"OpenCascade cannot read {path} back")
    tool = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
    labels = TDF_LabelSequence()
    tool.GetFreeShapes(labels)
    out = []
    for i in range(1, labels.Length() + 1):
        label = labels.Value(i)
        name = TDataStd_Name()
        has = label.FindAttribute(TDataStd_Name.GetID_s(), name)
        title = name.Get().ToExtString() if has else ""
        out.extend((title, solid) for solid in _solids(tool.GetShape_s(label)))
    return out


def read_solids(path) -> list[tuple[str, object]]:
    """``[(name, solid), ...]`` read from a STEP, IGES or BREP file (BREP: names empty)."""
    path = str(path)
    suffix = Path(path).suffix.lower()
    if suffix in (".step", ".stp"):
        return _read_xde(path, STEPCAFControl_Reader())
    if suffix in (".iges", ".igs"):
        return _read_xde(path, IGESCAFControl_Reader())
    shape = TopoDS_Shape()
    if not BRepTools.Read_s(shape, path, BRep_Builder()):
        raise CadError(f"OpenCascade cannot read {path} back")
    return [("", s) for s in _solids(shape)]


def volume_mm3(solid) -> float:
    """The solid's volume (mm^3) by OpenCascade's integration to :data:`VOLUME_EPS`."""
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(solid, props, VOLUME_EPS, False)
    return float(props.Mass())


def is_closed(solid) -> bool:
    """Whether every shell of ``solid`` is closed and no edge bounds a single face."""
    it = TopExp_Explorer(solid, TopAbs_ShapeEnum.TopAbs_SHELL)
    shells = 0
    while it.More():
        shells += 1
        if not BRep_Tool.IsClosed_s(it.Current()):
            return False
        it.Next()
    free = ShapeAnalysis_FreeBounds(solid)
    open_wires = TopExp_Explorer(free.GetOpenWires(), TopAbs_ShapeEnum.TopAbs_EDGE).More()
    closed_wires = TopExp_Explorer(free.GetClosedWires(), TopAbs_ShapeEnum.TopAbs_EDGE).More()
    return shells > 0 and not open_wires and not closed_wires


def check_cad_file(path, bodies) -> dict:
    """Read ``path`` back and check it against the written ``bodies`` (see the module rule).

    Returns ``{"bodies": [{"name", "valid", "closed", "volume_mm3", "expected_mm3",
    "relative_error", "deviation_mm"}, ...]}``; raises ``CadError`` naming the first body that
    is missing, invalid, open, or whose volume is off by more than the tolerance.
    """
    solids = read_solids(path)
    if len(solids) != len(bodies):
        raise CadError(f"the file holds {len(solids)} solids, {len(bodies)} were written")
    report = []
    for body, (name, solid) in zip(bodies, solids):
        if name and name != body.name:
            raise CadError(f"the file's solids are out of order: {name!r} where {body.name!r} was written")
        entry = {"name": body.name, "valid": bool(BRepCheck_Analyzer(solid).IsValid()),
                 "closed": is_closed(solid), "volume_mm3": volume_mm3(solid),
                 "expected_mm3": body.expected_mm3, "relative_error": None,
                 "deviation_mm": body.deviation_mm}
        if body.expected_mm3:
            entry["relative_error"] = abs(entry["volume_mm3"] - body.expected_mm3) / body.expected_mm3
        report.append(entry)
        if not entry["valid"]:
            raise CadError(f"the {body.name} read back is not a valid solid")
        if not entry["closed"]:
            raise CadError(f"the {body.name} read back is not closed")
        if entry["relative_error"] is not None and entry["relative_error"] > VOLUME_RTOL:
            raise CadError(f"the {body.name}'s volume read back, {entry['volume_mm3']:.6f} mm3, is "
                           f"off the trade figure {body.expected_mm3:.6f} mm3 by "
                           f"{entry['relative_error']:.2e} (more than {VOLUME_RTOL:g})")
    return {"bodies": report}

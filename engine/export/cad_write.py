"""Writing named solids as STEP (AP214, through the XDE document so names survive), IGES or BREP.

Design rule: OpenCascade's own writers do the format; this module only puts each
:class:`~engine.export.cad.CadBody` into an XDE document as one top-level shape named after it
(the mould shop's CAD shows ``glass``, ``liquid``, ``closure cap``), sets millimetres as the
file's unit and reports a writer that fails as a ``CadError``. IGES is written in
its BRep mode (solids as MSBO entities, not loose trimmed surfaces); OpenCascade's writers read
such parameters when they are constructed, so they are set first. BREP has no names: its solids
are written as one compound in the bodies' order, which :mod:`engine.export.cad_check` reads
back in the same order. Units mm.
"""
from __future__ import annotations

from OCP.BRep import BRep_Builder
from OCP.BRepTools import BRepTools
from OCP.IFSelect import IFSelect_ReturnStatus
from OCP.IGESCAFControl import IGESCAFControl_Writer
from OCP.IGESControl import IGESControl_Controller
from OCP.Interface import Interface_Static
from OCP.Quantity import Quantity_Color, Quantity_TypeOfColor
from OCP.STEPCAFControl import STEPCAFControl_Writer
from OCP.STEPControl import STEPControl_Controller, STEPControl_StepModelType
from OCP.TCollection import TCollection_ExtendedString
from OCP.TDataStd import TDataStd_Name
from OCP.TDocStd import TDocStd_Document
from OCP.TopoDS import TopoDS_Compound
from OCP.XCAFDoc import XCAFDoc_ColorType, XCAFDoc_DocumentTool

from .occ_profile import CadError

#: Display colours (linear RGB) per body kind in the XDE document: glass pale, liquid amber.
KIND_COLOURS = {"glass": (0.80, 0.90, 0.92), "liquid": (0.75, 0.45, 0.10), "closure": (0.5, 0.5, 0.5)}


def xde_document(bodies, title: str = ""):
    """An XDE document holding each body as a named, coloured top-level shape (mm)."""
    doc = TDocStd_Document(TCollection_ExtendedString("XmlXCAF"))
    shapes = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
    colours = XCAFDoc_DocumentTool.ColorTool_s(doc.Main())
    for body in bodies:
        label = shapes.AddShape(body.solid, False)
        TDataStd_Name.Set_s(label, TCollection_ExtendedString(body.name))
        r, g, b = KIND_COLOURS.get(body.kind, (0.5, 0.5, 0.5))
        colours.SetColor(label, Quantity_Color(r, g, b, Quantity_TypeOfColor.Quantity_TOC_RGB),
                         XCAFDoc_ColorType.XCAFDoc_ColorSurf)
    return doc


def _write_step(bodies, path: str, title: str) -> None:
    STEPControl_Controller.Init_s()  # declares the parameters; the writer reads them when made
    Interface_Static.SetCVal_s("write.step.unit", "MM")
    Interface_Static.SetCVal_s("write.step.schema", "AP214IS")
    writer = STEPCAFControl_Writer()
    writer.SetNameMode(True)
    writer.SetColorMode(True)
    if not writer.Transfer(xde_document(bodies, title), STEPControl_StepModelType.STEPControl_AsIs):
        raise CadError("the STEP writer refuses the solids")
    if writer.Write(path) != IFSelect_ReturnStatus.IFSelect_RetDone:
        raise CadError(f"the STEP writer could not write {path}")


def _write_iges(bodies, path: str, title: str) -> None:
    IGESControl_Controller.Init_s()  # declares the parameters; the writer reads them when made
    Interface_Static.SetCVal_s("write.iges.unit", "MM")
    Interface_Static.SetIVal_s("write.iges.brep.mode", 1)  # solids (MSBO), not trimmed surfaces
    writer = IGESCAFControl_Writer()
    writer.SetNameMode(True)
    writer.SetColorMode(True)
    if not writer.Transfer(xde_document(bodies, title)):
        raise CadError("the IGES writer refuses the solids")
    if not writer.Write(path):
        raise CadError(f"the IGES writer could not write {path}")


def _write_brep(bodies, path: str, title: str) -> None:
    compound, builder = TopoDS_Compound(), BRep_Builder()
    builder.MakeCompound(compound)
    for body in bodies:
        builder.Add(compound, body.solid)
    if not BRepTools.Write_s(compound, path):
        raise CadError(f"the BREP writer could not write {path}")


_WRITERS = {".step": _write_step, ".stp": _write_step, ".iges": _write_iges,
            ".igs": _write_iges, ".brep": _write_brep}


def write_bodies(bodies, path: str, suffix: str, title: str = "") -> None:
    """Write ``bodies`` to ``path`` in the format of ``suffix`` (``.step``/``.stp``,
    ``.iges``/``.igs``, ``.brep``); ``CadError`` if OpenCascade's writer fails."""
    _WRITERS[suffix.lower()](bodies, str(path), title)

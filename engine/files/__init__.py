"""Files in and out: the versioned ``.glassbench`` project archive and its JSON serializer,
DXF section import, and mesh export. Everything read here is untrusted and checked against the
bounds of :mod:`engine.limits` before it is used, and everything written goes through
:mod:`engine.io.atomic`, so a file appears whole or not at all; a project is written only
after the check that runs on load has passed for it.
"""

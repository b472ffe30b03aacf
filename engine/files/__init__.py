"""Files in and out: the versioned ``.glassbench`` project archive and its JSON serializer,
DXF section import, and mesh export. Everything read here is untrusted and checked against
bounds before it is used.
"""

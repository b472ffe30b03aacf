"""glassbench engine: bottle geometry, trade numbers, design projects and the glass tracer.

A plain Python library: it never imports Qt, so it runs headless and from the command line.
All lengths are millimetres and geometry is float64 unless a name says otherwise. Every bound on
what a user can pass lives in :mod:`engine.limits`; every error is an
:class:`engine.errors.GlassbenchError` of one bounded line.
"""
__version__ = "0.1.0"

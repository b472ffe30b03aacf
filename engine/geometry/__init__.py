"""Bottle geometry: segments, sections and shapes (the designer's values), their validation,
the derived inner walls and body surfaces, tessellation, and the trade numbers (capacities,
glass volume and mass). Pure functions and frozen values in millimetres; no rendering, no files.
"""

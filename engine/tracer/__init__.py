"""The progressive glass tracer: render geometry, the whole reflection/refraction tree of each
camera sample (Whitted-style: every Fresnel branch followed, depth first with a bounded stack),
tiled jobs.

Public entry points: :class:`engine.tracer.job.RenderJob` with its options
:class:`engine.tracer.sampling.Sampling` and the records of :mod:`engine.tracer.job_options`,
:func:`engine.tracer.job.render_image`,
:func:`engine.tracer.job.tonemap_srgb8` and :func:`engine.cli.render.render_command`.
Import them from their modules; this package file stays light so importing ``engine`` is cheap.
"""

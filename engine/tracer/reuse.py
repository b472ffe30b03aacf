"""What a new render may take over from the render it replaces, decided once from the change.

Design rule: a job is handed the job it replaces and the :class:`~engine.model.changes.Change`
the scene announced since (unioned over the edits in between); :func:`reuse_of` reads it once
and returns the strategy, a small object whose ``run(job, previous)`` does it: :data:`KEEP_FILM`
(nothing the image shows changed: a name, the notes), a :class:`Relabel` (:mod:`engine.tracer.relabel`:
only labels, lights or their images), a :class:`Retint` (:mod:`engine.tracer.retint`: only the
glass's or the liquid's absorption; a full render with a preview from the old film), or
:data:`FULL_RENDER`. Each needs the previous job finished, without error, at the same size
and sampling (two jobs with equal :meth:`~engine.tracer.job.RenderJob.sampling_key` of the same
design trace the same samples), except that a retint still running hands its basis on to the
next colour edit.
"""
from __future__ import annotations

from ..model.changes import Change, changed_assets
from .retint import RetintBasis, retint_basis
from .relabel import RelabelPlan, plan_relabel

#: Design fields the image depends on (an edit of any other field keeps the film).
VISUAL_FIELDS = frozenset({"shape", "glass", "liquid", "camera", "environment", "render", "assets",
                           "labels", "lights", "bumps", "cap", "stage"})


class FullRender:
    """Render everything (the job's own waves)."""

    def run(self, job, previous) -> None:
        job._render()

    def __repr__(self) -> str:
        return "FULL_RENDER"


class KeepFilm:
    """The previous job's film is this job's: its scene, records and figures describe it."""

    def run(self, job, previous) -> None:
        job.adopt(previous)

    def __repr__(self) -> str:
        return "KEEP_FILM"


class Relabel:
    """Trace again only the pixels a label's change reaches (``plan``: a
    :class:`~engine.tracer.relabel.RelabelPlan`), the rest replayed from the previous film."""

    def __init__(self, plan: RelabelPlan):
        self.plan = plan

    def run(self, job, previous) -> None:
        job.relabel(self.plan)


class Retint:
    """Render everything, and meanwhile show the previous converged film retinted by the new
    centres' ratios (``basis``: a :class:`~engine.tracer.retint.RetintBasis`)."""

    def __init__(self, basis: RetintBasis):
        self.basis = basis

    def run(self, job, previous) -> None:
        job.retint = self.basis
        job._render()


#: The strategies without state.
FULL_RENDER, KEEP_FILM = FullRender(), KeepFilm()


def lights_shade(design) -> bool:
    """Whether ``design``'s lights light anything: its labels, its closure's diffuse
    (plastic, cork) parts, or a diffuse ground."""
    return bool(design.labels) or design.cap is not None or lit_ground(design)


def lit_ground(design) -> bool:
    """Whether ``design`` stands on a diffuse ground that its lights light: their light through
    the bottle (the caustic grids, :mod:`engine.tracer.tables.caustics`) depends on the labels
    and the lights, and no relabel record holds it."""
    return bool(design.lights) and diffuse_ground(design)


def diffuse_ground(design) -> bool:
    """Whether ``design`` stands on a diffuse ground: the sky's light on it through the bottle
    (the sky grid, :mod:`engine.tracer.tables.sky`) depends on the labels, and no relabel
    record holds it."""
    return design.stage.is_diffuse_ground


def _keeps_film(previous, design, change: Change) -> bool:
    visual = set(change) & VISUAL_FIELDS
    if not design.labels and not previous.design.labels:
        visual.discard("labels")
    if not lights_shade(design) and not lights_shade(previous.design):
        visual.discard("lights")
    return not visual


def reuse_of(previous, design, assets, sampling_key, changed):
    """The strategy (:data:`KEEP_FILM`, a :class:`Relabel`, a :class:`Retint` or :data:`FULL_RENDER`) of a job
    rendering ``design`` with ``assets`` at ``sampling_key`` (its ``sampling_key()``) after job
    ``previous``, ``changed`` the fields (a :class:`Change`, or names) changed since."""
    if previous is None or changed is None or previous.sampling_key() != sampling_key:
        return FULL_RENDER
    finished = previous.done and previous.error is None and not previous.cancelled
    change = Change.of(changed)
    if finished and _keeps_film(previous, design, change):
        return KEEP_FILM
    basis = retint_basis(previous, design, change)
    if basis is not None:
        return Retint(basis)
    if not finished:
        return FULL_RENDER
    if diffuse_ground(design) or diffuse_ground(previous.design):
        return FULL_RENDER  # labels or lights changed the light on the ground (its grids)
    if change.assets is None:  # the caller named fields only: which assets changed is read here, once
        change = Change(change, changed_assets(previous.assets, assets))
    plan = plan_relabel(previous, design, assets, change)
    return FULL_RENDER if plan is None else Relabel(plan)

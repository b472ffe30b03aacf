"""A render's sampling options as one record: what a caller chooses about where samples go.

Design rule: the options that decide a render's adaptive rounds, besides its size and ``spp``,
travel as one immutable :class:`Sampling`, checked once when it is made and stating every
default once, here; :class:`engine.tracer.job.RenderJob` takes it whole (``sampling=``), and
each front end names its own as a constant (the window: :data:`app.engine_bridge.WINDOW_NOISE`;
final renders, the command line and batches: :data:`FINAL_SAMPLING`). The module imports no
kernels, so command lines and benchmarks can state their settings at import time.
"""
from __future__ import annotations

from dataclasses import dataclass

from .adaptive import NOISE_SPACES, NOISE_TARGET, POLICIES


@dataclass(frozen=True)
class Sampling:
    """Where a job's adaptive rounds stop: the options of a render's sampling besides its size
    and ``spp`` (both the design's unless a :class:`~engine.tracer.job.RenderJob` overrides
    them). Immutable; checked when made (``ValueError`` names the bad field); the defaults are a
    final render's. Two jobs of one design at one size and ``spp`` with equal ``Sampling`` trace
    the same samples.

    Attributes
    ----------
    adaptive : bool
        Add the adaptive rounds after the uniform anti-aliasing rounds.
    noise_target : float
        The adaptive rounds' tolerance, > 0: a fraction of the design's reference level (the
        environment's mean radiance) in linear space, where a pixel gets one sample per
        tolerance of its one-sample scatter (Neyman allocation); with ``noise_space="display"``
        each pixel's standard error below this many display units once tone-mapped.
    noise_space : str
        "linear" (references, final renders) or "display" (the window:
        :data:`~engine.tracer.adaptive.DISPLAY_NOISE`): see
        :func:`~engine.tracer.adaptive.noise_targets`.
    policy : str
        "split" or "classic": in display space, "split" is the window's
        :class:`~engine.tracer.adaptive.SplitPolicy` (one tolerance for the whole image, samples
        up to ``SPLIT_FACTOR x spp``); "classic", and either in linear space, is
        :class:`~engine.tracer.adaptive.ScatterPolicy`
        (:func:`~engine.tracer.adaptive.sampling_policy`).
    cap_factor : int or None
        The classic policy's sample cap, ``cap_factor x spp``, >= 1 (``None``: the noise space's
        default, :data:`~engine.tracer.adaptive.LINEAR_FACTOR` or ``ADAPTIVE_FACTOR``). At a
        tight ``noise_target`` the pixels of thick bases ask for more than the default cap
        (references: ``benchmarks.oracle_render``); the window's split policy ignores it.
    sketch : bool
        Before the centres, trace the display-only sketch (:mod:`engine.tracer.sketch`) where
        a watched render's trees are heavy: the window's first full frame for its denoiser. It
        never enters the film, so it changes no pixel of the image.
    """

    adaptive: bool = True
    noise_target: float = NOISE_TARGET
    noise_space: str = "linear"
    policy: str = "split"
    cap_factor: int | None = None
    sketch: bool = False

    def __post_init__(self):
        if self.noise_space not in NOISE_SPACES:
            raise ValueError(f"noise_space must be 'linear' or 'display', not {self.noise_space!r}")
        if self.policy not in POLICIES:
            raise ValueError(f"policy must be 'split' or 'classic', not {self.policy!r}")
        if not float(self.noise_target) > 0.0:  # (also refuses NaN)
            raise ValueError(f"noise_target must be a number above 0, not {self.noise_target!r}")
        if self.cap_factor is not None and not int(self.cap_factor) >= 1:
            raise ValueError(f"cap_factor must be None or an integer of at least 1, not {self.cap_factor!r}")
        # one type per field, so that equal options compare equal (``RenderJob.sampling_key``)
        object.__setattr__(self, "adaptive", bool(self.adaptive))
        object.__setattr__(self, "sketch", bool(self.sketch))
        object.__setattr__(self, "noise_target", float(self.noise_target))
        if self.cap_factor is not None:
            object.__setattr__(self, "cap_factor", int(self.cap_factor))


#: A final render's sampling (every default).
FINAL_SAMPLING = Sampling()

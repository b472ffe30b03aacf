"""Where samples go: the progressive plan and the anti-aliasing policy of a render.

Design rule: smooth glass traced Whitted-style has no noise; a pixel's only error is its
footprint, which matters where the image has edges. So every pixel gets its centre sample, and
only pixels that differ from a neighbour (another dominant path, or a radiance step above the
contrast threshold) get stratified anti-aliasing samples, then more where their own samples
still scatter. Every decision here is a pure function of the film after a wave, so a pixel's
samples do not depend on thread count or tile order, and a relabel that replays the waves
equals a full render. Every threshold is local to a pixel or fixed per design (the
environment's mean radiance, never the image's), with one exception: the window's adaptive
rounds choose their per-pixel tolerance from a short ladder by the whole image's estimated
error (:func:`split_tolerance`), so an edit elsewhere can move a pixel's samples by a step.
A render asks these through its :class:`SamplingPolicy` (:func:`sampling_policy`): the final
renders' :class:`ScatterPolicy` or the window's :class:`SplitPolicy`.
"""
from __future__ import annotations

import numpy as np

from ..color import display_slope

#: First anti-aliasing round: samples every edge pixel gets.
FIRST_AA = 4
#: Relative radiance step between neighbouring centres that marks an edge.
CONTRAST = 0.04
#: Adaptive rounds in display space (the honesty check's reference) raise a pixel to at most
#: this many times ``spp`` samples.
ADAPTIVE_FACTOR = 16
#: Adaptive rounds in linear space (final renders) raise a pixel to at most this many times
#: ``spp`` samples: their Neyman allocation (:func:`noise_targets`) gives the few pixels that
#: scatter most the samples they need, and 16 x spp held them back (public_1-4, 4 samples on
#: edges, against 16 x: the same error in 0.6-0.8 x the time below 1.2 % rel RMSE).
LINEAR_FACTOR = 64
#: Final renders' default tolerance, a fraction of the design's reference level: a pixel gets
#: one sample per tolerance of its one-sample scatter (Neyman allocation, :func:`noise_targets`).
#: Chosen on the bundled samples' final renders (180 x 240, 16 spp, against a render with 64 spp
#: at 0.001 on other samples): against the same standard error for every pixel (below 0.01)
#: the same or a smaller error in about the same time: jar 1.03 % rel RMSE in 7.2 s
#: (1.25 % in 6.3 s), cut decanter 1.40 % in 15.3 s (1.60 % in 13.7 s), knurled jar 1.92 % in
#: 18.9 s (2.71 % in 20.7 s), frosted logo 1.20 % in 2.4 s (1.04 % in 4.2 s; 0.99 % in 4.4 s at
#: 0.001). 0.005 would take half the time but lose on the frosted logo (1.62 %).
NOISE_TARGET = 0.002
#: The window's target: per-pixel standard error below this many display units (sRGB, 0..1)
#: once tone-mapped (:func:`engine.color.tonemap_srgb8`). Measured on the bundled sample
#: at the window's 715x954 against a render with 256 samples per edge pixel: 0.22 display levels
#: (of 255) RMS in 3.8 s, where ``NOISE_TARGET`` in linear radiance gives 0.14 levels in 5.4 s
#: (it also spends samples on highlights the display clips): both far below a visible step.
DISPLAY_NOISE = 2.0 / 255.0
#: A pixel's adaptive rounds ask at least this share of the samples its neediest neighbour
#: asks (:func:`noise_targets`, linear space): a scatter estimated from a handful of samples
#: misses rare bright paths, and the neighbours' estimate is a second opinion. Measured with
#: 4 anti-aliasing samples, Neyman allocation and tolerances 0.02-0.005 (draft cuts) on
#: public_1, 3, 4: 0.3 gives 0.5-0.8 x the error of 0.1 for 1.0-1.15 x the time (public_3 at
#: 0.01: 1.09 % in 1.17 s against 1.24 % in 0.99 s; 0.987 %, Mitsuba's 1024-spp error, in about
#: 1.5 s against 1.65 s); 0.5 and 1.0 spend more than they gain, 0 loses 10-15 % in error.
NEIGHBOUR_SHARE = 0.3
#: Where :func:`noise_targets` may judge a pixel's scatter.
NOISE_SPACES = ("linear", "display")
#: The adaptive rounds' policies (:func:`sampling_policy`).
POLICIES = ("split", "classic")
#: The adaptive rounds' samples play Russian roulette on branches into glass or liquid lighter
#: than this: those pixels are noisy anyway (light trapped in thick glass), and a sample then
#: costs about a path instead of a tree (``python -m benchmarks.tracer``: error against time).
ROULETTE = 0.05
#: Final renders with adaptive rounds measure every pixel whose centre met the bottle and that
#: no edge marked with this many anti-aliasing samples (:func:`measure_mask`, :func:`inner_steps`).
MEASURE_AA = 4


def preview_block(width: int, height: int) -> int:
    """Edge (px) of the preview wave's blocks: about 48 blocks across the longer side."""
    return max(2, 2 ** int(np.log2(max(2, max(width, height) // 48))))


def _neighbours(a, mode):
    """The 8 neighbour views of the ``(H, W)`` array ``a``, beyond its border padded by
    ``np.pad``'s ``mode``."""
    p = np.pad(a, 1, mode=mode)
    h, w = a.shape
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            if dy or dx:
                yield p[1 + dy:1 + dy + h, 1 + dx:1 + dx + w]


def _neighbour_max(a, op):
    """Per pixel, ``op`` of ``a`` with each of its 8 neighbours (edges replicate)."""
    out = np.zeros(a.shape, bool)
    for b in _neighbours(a, "edge"):
        out |= op(a, b)
    return out


def _neighbour_max_value(a):
    """Per pixel, the largest of its 8 neighbours' values of ``a`` (0 outside the image)."""
    out = np.zeros(a.shape)
    for b in _neighbours(a, "constant"):
        np.maximum(out, b, out=out)
    return out


def _steps(a, b, level: float) -> np.ndarray:
    """Where luminances ``a`` and ``b`` differ by more than ``CONTRAST`` of the larger plus a
    floor of 1 % of ``level``."""
    return np.abs(a - b) > CONTRAST * np.maximum(a, b) + 0.01 * level


def edge_mask(centre_lum, signature, level: float) -> np.ndarray:
    """Pixels whose centre differs from a neighbour's: another dominant path, or a luminance
    step above ``CONTRAST`` of the larger (plus a floor of 1 % of ``level``)."""
    step = _neighbour_max(centre_lum, lambda a, b: _steps(a, b, level))
    path = _neighbour_max(signature, lambda a, b: a != b)
    return step | path


def measure_mask(objects, edges, adaptive: bool, space: str) -> np.ndarray:
    """Pixels without an edge that final renders measure with :data:`MEASURE_AA` samples: with
    adaptive rounds in linear space, those whose centre's tree met an object (``objects``: the
    film's bit mask per pixel); none otherwise (the window's display-space rounds, whose
    honesty reference is display-space too, and renders without adaptive rounds).

    Why: a centre sample stands for its pixel only where the image is smooth across it, and the
    edge test sees steps between neighbouring centres, not detail inside a pixel. Through glass
    the environment is magnified, folded and cut by caustics: on public_3 (a rounded-square flask
    with liquid) 333 pixels whose centre alone stood for them (of 54,000) held 0.48 % of its
    0.71 % rel RMSE (16 samples, tolerance 0.002), the mean of their samples 3-10 % from their
    centre; anti-aliased, 0.04 %. The measurement stays only where it shows such detail
    (:func:`inner_steps`); elsewhere the pixel keeps its centre, which traced the whole tree
    (adaptive samples play roulette: kept everywhere, the measurement made public_1's thick
    base noisier, 0.74 -> 0.80 %)."""
    if not adaptive or space != "linear" or MEASURE_AA <= 0:
        return np.zeros(edges.shape, bool)
    return (objects != 0) & ~edges


def inner_steps(film, measured, level: float) -> np.ndarray:
    """Pixels of ``measured`` whose anti-aliasing samples' mean differs from their centre by the
    edge test's step (:func:`edge_mask`): detail inside the pixel, which makes it an edge."""
    with film.lock:
        centre = film.centre.mean(axis=2)
        mean = film.aa_sum.mean(axis=2) / np.maximum(film.aa_count, 1)
    return measured & (film.aa_count > 0) & _steps(mean, centre, level)


def _scatter(film):
    """``(at, have, mean, var)`` of the anti-aliased pixels: their indices, AA sample counts,
    AA mean luminance, and the sample variance of their luminance, the centre sample counted
    in (a fixed point, so never in the pixel's mean, but one more probe where a few stratified
    samples may all have missed a thin bright feature: measured on public_3 at 4 samples and
    a 0.05 target, 1.66 % against 1.76 % rel RMSE in the same time)."""
    with film.lock:
        at = np.nonzero(film.aa_count)  # only anti-aliased pixels: a few per cent of the image
        have = film.aa_count[at]
        centre = film.centre[at].mean(axis=1)
        aa_lum = film.aa_sum[at].mean(axis=1)
        sumsq = film.aa_sumsq[at]
    n = have.astype(float)
    m1 = (aa_lum + centre) / (n + 1.0)
    var = np.maximum((sumsq + centre ** 2) / (n + 1.0) - m1 ** 2, 0.0) * (n + 1.0) / n
    return at, have, aa_lum / n, var


def noise_targets(film, cap: int, noise_target: float, level: float, space: str = "linear") -> np.ndarray:
    """Samples each anti-aliased pixel should reach: at least what it has, at most ``cap``; 0 for
    pixels without anti-aliasing samples. ``var`` is :func:`_scatter`'s (one sample's variance).

    ``space`` "linear" (final renders; what rel RMSE against a reference measures): Neyman
    allocation, ``n = sqrt(var) / tolerance`` with the tolerance ``noise_target x level``
    (radiance). Samples in proportion to a pixel's scatter minimise the image's summed squared
    error for the samples spent (``sum var_i / n_i`` under ``sum n_i`` fixed); a pixel's
    standard error is then ``sqrt(scatter x tolerance)``: the tolerance where one sample
    scatters by it, more where a pixel is hard. Asking every pixel for the same standard
    error (``n = var / tolerance^2``) pours samples into the few pixels that scatter most (light
    trapped in a thick base: 30 pixels held half of public_1's error) up to the cap, and too
    many into the moderate ones. Measured on public_1-4 (4 samples on edges;
    ``benchmarks/RESULTS.md``): 0.98 % rel RMSE in 0.76 s on public_1 where the same standard
    error everywhere gave 1.07 % in 1.16 s. A pixel asks at least ``NEIGHBOUR_SHARE`` of what its neediest
    neighbour asks: a thin feature that a neighbour's samples caught crosses into this pixel
    too, where four stratified samples may all have missed it.

    "display" (the window's classic policy and the honesty check's reference): every pixel's
    standard error below ``noise_target`` display units, ``n = var slope^2 / noise_target^2``
    through the tone map's slope at the pixel's mean (:func:`display_slope`), so a pixel surely
    above white (its mean two standard errors above 1) needs nothing more and dark glass needs
    more. (No neighbour share there: on the window's sample, whose edges have had sixteen
    samples by then, it cost 15 % more time and its display error rose from 0.20 to 0.22
    levels.)
    """
    at, have, mean, var = _scatter(film)
    if space == "linear":
        need = np.sqrt(var) / (noise_target * level)
        full = np.zeros(film.aa_count.shape)
        full[at] = need
        need = np.maximum(need, NEIGHBOUR_SHARE * _neighbour_max_value(full)[at])
    elif space == "display":
        clipped = mean - 2.0 * np.sqrt(var / have) > 1.0
        slope = display_slope(np.minimum(mean, 1.0 - 1e-9))  # a mean near white may still fall
        need = np.where(clipped, 0.0, var * slope ** 2 / noise_target ** 2)
    else:
        raise ValueError(f"noise space must be 'linear' or 'display', not {space!r}")
    out = np.zeros(film.aa_count.shape, np.int64)
    out[at] = np.clip(np.ceil(need), have, cap).astype(np.int64)
    return out


def plan(spp: int, adaptive: bool, factor: int = ADAPTIVE_FACTOR):
    """The anti-aliasing rounds: ``[(samples, varied)]``.

    Every edge pixel is raised to 4, then doubling, up to ``spp`` samples (``varied`` False:
    the same count for all: a heavy-tailed pixel shows its scatter only after a dozen samples).
    With adaptivity, rounds then raise each anti-aliased pixel to what its own scatter asks
    (``varied`` True: :func:`noise_targets`), with a cap that quadruples each round up to
    ``ADAPTIVE_FACTOR x spp``: light trapped in thick glass gets hundreds of samples. Measured
    on public_1 against raising edges to 4 and deciding from there: 0.71 % against 0.93 % rel
    RMSE in the same time.
    """
    rounds, have = [], 0
    nxt = min(FIRST_AA, spp)
    while have < spp:
        rounds.append((nxt, False))
        have = nxt
        nxt = min(spp, 2 * have)
    if adaptive:
        cap, top = have, max(1, spp) * factor
        while cap < top:
            cap = min(top, 4 * cap)
            rounds.append((cap, True))
    return rounds


# ---------------------------------------------------------------- the window's policy: split halves
#: The window's anti-aliasing starts with this many samples per edge pixel, then doubles: each
#: doubling compares the mean of the samples before it with the mean of those it added.
SPLIT_FIRST = 8
#: A pixel's own split estimate is one degree of freedom; it takes at least this share of the
#: mean estimate of the anti-aliased pixels around it (3 x 3), so one lucky agreement of its two
#: halves does not stop it while its neighbours still scatter.
SPLIT_POOL = 0.5
#: The window's adaptive rounds raise a pixel to at most this many times ``spp`` samples, and
#: play Russian roulette below :data:`SPLIT_ROULETTE` (final renders: :data:`ADAPTIVE_FACTOR`,
#: :data:`ROULETTE`). The pixels that reach the cap are relief and thick glass seen through
#: relief, whose scatter comes from where a sample lands (facet edges, a softbox through a
#: chain of total internal reflections), not from the tree: a cheaper sample that follows fewer
#: faint branches costs them little accuracy, and the samples it saves buy a higher cap.
#: Measured with ``python -m benchmarks.window_levers`` (119 x 159, levels RMS against an
#: independent reference, rays), against (16, 0.05): knurled jar 2.26 -> 2.14 levels with 0.88 x
#: the rays, cut decanter 1.71 -> 1.67 with 0.87 x, frosted logo 1.84 -> 1.75 with 1.08 x, jar
#: 1.25 -> 1.36 with 1.04 x (thick glass without relief: its scatter is the tree's, which the
#: roulette adds to). (32, 0.2) was more honest on relief at 1.1-1.4 x the rays of (16, 0.05).
SPLIT_FACTOR = 24
SPLIT_ROULETTE = 0.2
#: The window's image-level target, a share of its per-pixel tolerance: a pixel's tolerance is
#: loosened to the widest step of ``SPLIT_LADDER`` (multiples of it) at which the image's
#: estimated RMS error stays below this share of it (:func:`split_tolerance`; with the window's
#: 2 levels, 1 level RMS, two thirds of the honesty check's bound of 1.5 levels RMS,
#: ``benchmarks.window_converge``). Measured at 715 x 953
#: (2 threads; each render's error from a second one on other samples, levels RMS): jar 38.7 s
#: 0.78 -> 32.5 s 0.90 (3 levels chosen), threaded bottle 19.6 s 0.42 -> 8.9 s 0.68 (8), Bordeaux
#: 3.2 s 0.23 -> 2.4 s 0.30 (8); samples whose error at 2 levels is already near the bound
#: (relief) keep 2. Without the cap's floor in the estimate the jar chose 4 levels and measured
#: 1.02 (26.2 s): its capped pixels stay above the step. The ladder stops at 4 x (8 levels):
#: with 1 level RMS over the image few pixels can sit there, so the 99th percentile stays far
#: below the honesty check's 10 levels.
SPLIT_IMAGE_SHARE = 0.5
SPLIT_LADDER = (1.0, 1.5, 2.0, 3.0, 4.0)


def split_plan(spp: int, adaptive: bool):
    """The window's anti-aliasing rounds ``[(samples, varied)]``: edge pixels to 4, then to
    :data:`SPLIT_FIRST` (the first split of a pixel's samples into two equal nets), then (with
    ``adaptive``) doubling rounds (the last one to the cap) for the pixels whose split
    estimate (:func:`split_targets`) is still above their tolerance, up to ``SPLIT_FACTOR x spp``."""
    first = min(FIRST_AA, spp)
    rounds = [(first, False)]
    if not adaptive:
        have = first
        while have < spp:
            have = min(spp, 2 * have)
            rounds.append((have, False))
        return rounds
    have = first
    top = max(1, spp) * SPLIT_FACTOR
    if SPLIT_FIRST > have:
        have = min(SPLIT_FIRST, top)
        rounds.append((have, False))
    while have < top:
        have = min(top, 2 * have)
        rounds.append((have, True))
    return rounds


class SamplingPolicy:
    """How a render's anti-aliasing rounds choose each pixel's samples: the rounds
    ``[(samples, varied)]`` (:meth:`rounds`), each round's per-pixel targets (:meth:`targets`;
    a uniform round gives the edge pixels ``samples``), the Russian roulette weight its varied
    rounds play (``roulette``), and after the last round how many pixels stopped at the cap with
    their error still above the tolerance (:meth:`capped`). A policy holds the state of one
    render (its tolerance): make one per render (:func:`sampling_policy`)."""

    roulette = ROULETTE
    #: the per-pixel tolerance (display units) the rounds settled at; ``None`` if not tracked
    tolerance = None

    def rounds(self, spp: int, adaptive: bool) -> list:
        raise NotImplementedError

    def mark(self, film):
        """What to remember of ``film`` before a round (the split policy: its sums)."""
        return None

    def targets(self, film, samples: int, varied: bool, edges, mark, level: float) -> np.ndarray:
        """Samples each pixel should reach after a round of ``samples`` (``varied``: adaptive)."""
        return np.where(edges, samples, 0)

    def capped(self, film, mark) -> int:
        return 0


class ScatterPolicy(SamplingPolicy):
    """Final renders and references (``"classic"``): uniform rounds, then adaptive ones giving
    each pixel samples in proportion to its one-sample scatter (:func:`noise_targets`), up to
    :data:`LINEAR_FACTOR` x spp in linear space or :data:`ADAPTIVE_FACTOR` x spp in display space
    (or ``factor`` x spp where given)."""

    def __init__(self, noise_target: float, space: str, factor: int | None = None):
        self.noise_target, self.space = noise_target, space
        self.factor = factor if factor is not None else LINEAR_FACTOR if space == "linear" else ADAPTIVE_FACTOR

    def rounds(self, spp: int, adaptive: bool) -> list:
        return plan(spp, adaptive, self.factor)

    def targets(self, film, samples, varied, edges, mark, level):
        if not varied:
            return super().targets(film, samples, varied, edges, mark, level)
        return noise_targets(film, samples, self.noise_target, level, self.space)


class SplitPolicy(SamplingPolicy):
    """The window's (display space, ``"split"``): :func:`split_plan`'s rounds; a varied round
    doubles the pixels whose split estimate (:func:`split_targets`) is above the tolerance
    :func:`split_tolerance` chose, which only tightens from round to round."""

    roulette = SPLIT_ROULETTE

    def __init__(self, noise_target: float):
        self.noise_target = noise_target
        self._tol = np.inf
        self._cap = 1

    def rounds(self, spp: int, adaptive: bool) -> list:
        out = split_plan(spp, adaptive)
        self._cap = out[-1][0]
        return out

    def mark(self, film):
        return film.mark()

    def targets(self, film, samples, varied, edges, mark, level):
        if not varied:
            return super().targets(film, samples, varied, edges, mark, level)
        errors = split_errors(film, mark)
        self._tol = self.tolerance = split_tolerance(film, mark, self.noise_target, self._tol, self._cap, errors)
        return split_targets(film, mark, samples, self._tol, errors)

    def capped(self, film, mark) -> int:
        return int(np.count_nonzero(split_unconverged(film, mark, self._tol)))


def sampling_policy(space: str, policy: str, noise_target: float, cap_factor: int | None = None) -> SamplingPolicy:
    """The :class:`SamplingPolicy` of a render in noise ``space`` (``"linear"``/``"display"``)
    with ``policy`` (``"split"``: the window's, in display space; ``"classic"``). ``cap_factor``
    sets the classic policy's cap (``cap_factor x spp`` samples; ``None``: the space's default);
    the window's split policy keeps :data:`SPLIT_FACTOR`."""
    if space == "display" and policy == "split":
        return SplitPolicy(noise_target)
    return ScatterPolicy(noise_target, space, cap_factor)


def split_targets(film, mark, cap: int, noise_target: float, errors=None) -> np.ndarray:
    """Samples each anti-aliased pixel should reach (0 for the others): twice what it has, up
    to ``cap``, while its remaining error in display units is above ``noise_target``.

    The error of a pixel whose last round doubled its samples is estimated from the two halves
    of them (``mark``: the film's ``(luminance sums, counts)`` before that round,
    :meth:`~engine.tracer.film.Film.mark`): with Owen-scrambled Sobol points each half is itself
    a scrambled net, so ``|display(mean of the first half) - display(mean of the second half)| /
    2`` bounds the standard error of the whole mean from above (the halves of a net are
    negatively correlated) and, unlike the scatter of single samples, it sees how much faster
    than ``1 / sqrt(n)`` stratified samples converge at an edge. Tone-mapping each half
    (:func:`engine.color.srgb_encode`) makes a highlight above white need nothing and dark glass
    need more. One pixel's estimate is a single degree of freedom: it takes at least
    :data:`SPLIT_POOL` of the mean estimate over the anti-aliased pixels of its 3 x 3 block."""
    n, more = _split_verdict(film, mark, noise_target, errors)
    return np.where(more, np.minimum(2 * n, cap), np.where(n > 0, n, 0)).astype(np.int64)


def split_unconverged(film, mark, noise_target: float) -> np.ndarray:
    """Pixels whose last doubling round (``mark`` taken before it) left their split estimate
    (:func:`split_targets`) above ``noise_target``: after the plan's last round, those that
    stopped at the sample cap rather than at their tolerance (bool ``(H, W)``)."""
    return _split_verdict(film, mark, noise_target)[1]


def _split_verdict(film, mark, noise_target: float, errors=None):
    """``(n, more)``: the anti-aliasing sample counts and the pixels whose pooled split estimate
    (:func:`split_targets`) is above ``noise_target``."""
    n, err2, halves = split_errors(film, mark) if errors is None else errors
    return n, halves & (err2 > noise_target * noise_target)


def split_tolerance(film, mark, noise_target: float, previous: float, cap: int, errors=None) -> float:
    """The window's per-pixel tolerance for its next adaptive round (display units): the widest
    step ``k x noise_target`` of :data:`SPLIT_LADDER`, no wider than ``previous`` (the tolerance
    of the round before, so rounds only tighten), at which the image would be done: its RMS
    error over all pixels at most ``SPLIT_IMAGE_SHARE x noise_target``, each anti-aliased
    pixel's split estimate (:func:`split_targets`) clipped to the step (a pixel above it is
    refined until below) but not below what it keeps at the sample ``cap`` (its estimate scaled
    as ``1 / sqrt(samples)``), the others counted as 0. ``noise_target`` when no step is: where
    the pixels the cap will stop hold the image above the bound, the window spends as a
    per-pixel tolerance would. The first adaptive round decides: there every anti-aliased pixel
    has an estimate (the uniform round before it split all of them); later rounds see only the
    pixels the last one refined, whose estimates can still tighten the step.

    This makes the window's "converged" a statement about the image, which is what its honesty
    is judged by, instead of a per-pixel bound that most pixels beat by far. The choice is a
    pure function of the film after a wave, so a relabel (which replays the waves) still equals
    a full render bit for bit; a label edit that moves the image across a step traces more of
    its clean pixels again."""
    n, err2, _ = split_errors(film, mark) if errors is None else errors
    floor = err2 * n / max(cap, 1)  # (n <= cap)
    bound = (SPLIT_IMAGE_SHARE * noise_target) ** 2
    for k in sorted(SPLIT_LADDER, reverse=True):
        tau = k * noise_target
        if tau <= previous and float(np.mean(np.maximum(np.minimum(err2, tau * tau), floor))) <= bound:
            return tau
    return noise_target


def split_errors(film, mark):
    """``(n, err2, halves)``: the anti-aliasing sample counts, each pixel's pooled squared split
    estimate in display units (0 where it has none) and the pixels that have one. A round's
    decisions (:func:`split_tolerance`, :func:`split_targets`) may share one: ``errors=``
    (some 0.1 s at the window's size)."""
    from ..color import srgb_encode

    prev_sum, prev_n = mark
    with film.lock:
        n = film.aa_count.copy()
        lum = film.aa_sum.mean(axis=2)
    new_n = n - prev_n
    halves = (prev_n > 0) & (new_n > 0)
    first = prev_sum[halves] / prev_n[halves]
    last = (lum[halves] - prev_sum[halves]) / new_n[halves]
    d = np.abs(srgb_encode(first) - srgb_encode(last))  # (the tone map on those pixels alone)
    err2 = np.zeros(n.shape)
    err2[halves] = 0.25 * d * d
    # the mean over the 3 x 3 block's pixels that have an estimate
    have = halves.astype(float)
    total, count = np.zeros(err2.shape), np.zeros(err2.shape)
    for e, c in zip(_neighbours(err2, "constant"), _neighbours(have, "constant")):
        total += e
        count += c
    pooled = (total + err2) / np.maximum(count + have, 1.0)
    err2 = np.where(halves, np.maximum(err2, SPLIT_POOL * pooled), 0.0)
    return n, err2, halves

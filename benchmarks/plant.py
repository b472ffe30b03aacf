"""The glass plant's sheet (issue 43): figures per sample, closed-form checks, and a mesh peer.

Usage::

    python -m benchmarks.plant [--quick] [--repeat N]

Three measurements, units mm, g, MPa, deg, seconds:

* **Samples.** For every bundled sample (``resources/*.glassbench``), the figures of
  :func:`engine.plant.sheet.plant_numbers`: the least tip angle and its plan direction, the tip
  angle of each state (empty, filled, brimful) with the liquid moving (its surface level) and
  frozen, the largest membrane stress; and the seconds one evaluation takes **cold**. The
  engine's caches are keyed on the shape (a frozen, hashable value), so each repetition changes
  the wall by ``1e-9 k`` mm (``dataclasses.replace``): no cache can answer, and the profile's
  validation, offsetting and every integral are paid, as on a designer's edit. The median of
  ``--repeat`` such runs is quoted; a warm call (same design again) is shown beside as proof
  that the cold runs really miss the caches.
* **Closed forms.** Every case of :func:`benchmarks.plant_cases.closed_form_cases`: the
  engine's value, the exact one, the relative error.
* **Peer.** The mass properties (volume, height of the centre of mass) of the glass and of the
  upright liquid, as a mesh tool gets them: :func:`engine.geometry.tessellate.tessellate_body`
  and :func:`~engine.geometry.tessellate.tessellate_liquid` at a chordal tolerance, then
  ``trimesh``'s mass properties (divergence theorem over the triangles). Timed cold like the
  engine (a fresh shape each run, tessellation and ``trimesh`` both counted) at several
  tolerances, and compared with the engine's exact figures
  (:func:`engine.plant.mass.glass_part` and :func:`~engine.plant.mass.liquid_part`, also timed
  cold): against the closed forms of a plain cylinder (both methods), and against the engine's
  own figures on every distinct sample shape. The error of one evaluation is the worst relative
  error of its four figures. The peer's convergence (error falling with the tolerance, and its
  order) is checked before any time ratio is quoted; a second peer point extrapolates its two
  finest tolerances (Richardson, order 1), the best a mesh tool could do with the same meshes,
  and checks the engine's sample figures independently to about 1e-6. Even that stays far
  above the engine's error, so the quoted time ratio (peer's best point / engine) is a lower
  bound on the ratio at equal error.

Writes ``benchmarks/out/plant_samples.csv``, ``plant_closed_forms.csv``, ``plant_peer.csv`` and
``plant.png`` (left: time vs relative error, log-log; right: cold seconds per sample). Prints
last ``plant_seconds_per_evaluation_max=X`` (the slowest sample's cold median) and
``plant_worst_closed_form_error=X`` (the worst relative error over the closed-form cases).
"""
from __future__ import annotations

import argparse
import csv
import dataclasses
import glob
import os
import statistics
import time

import numpy as np

from benchmarks.plant_cases import GLASS_G_MM3, closed_form_cases, cylinder, cylinder_glass, frustum_moments
from engine.files.project import load_project
from engine.geometry.tessellate import tessellate_body, tessellate_liquid
from engine.model import fill
from engine.model.design import Liquid
from engine.plant import mass
from engine.plant.sheet import plant_numbers

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "out")
#: The bundled samples (``resources/NAME.glassbench``), sorted by name.
SAMPLES = sorted(glob.glob(os.path.join(ROOT, "resources", "*.glassbench")))
#: Chordal tolerances (mm) of the peer, coarse to fine.
TOLERANCES = (0.5, 0.2, 0.1, 0.05, 0.02, 0.01, 0.005)
QUICK_TOLERANCES = (0.5, 0.1, 0.02, 0.01)
#: The plain cylinder of the peer's closed form: radius, height, wall, base, liquid depth (mm).
CYL_R, CYL_H, CYL_W, CYL_B, CYL_DEPTH = 30.0, 150.0, 3.0, 6.0, 100.0
#: The glass density (g/cm^3) of :data:`benchmarks.plant_cases.GLASS_G_MM3`.
GLASS_G_CM3 = GLASS_G_MM3 * 1e3

_FRESH = [0]


# ------------------------------------------------------------------------------ timing
def fresh_shape(shape):
    """``shape`` with its wall thicker by ``1e-9 k`` mm (k counts up): a value no cache has seen."""
    _FRESH[0] += 1
    return dataclasses.replace(shape, wall_thickness=shape.wall_thickness + 1e-9 * _FRESH[0])


def fresh_design(design):
    """``design`` with a :func:`fresh_shape`: every cache of the engine (keyed on the shape) misses."""
    return dataclasses.replace(design, shape=fresh_shape(design.shape))


def median_seconds(fn, make_input, repeat: int) -> float:
    """Median wall time (s) of ``fn(make_input())`` over ``repeat`` runs (the input made untimed)."""
    times = []
    for _ in range(repeat):
        x = make_input()
        t0 = time.perf_counter()
        fn(x)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def rel(value: float, exact: float) -> float:
    """Relative error of ``value`` against ``exact`` (absolute when ``exact`` is 0)."""
    return abs(value - exact) / (abs(exact) if exact else 1.0)


# ------------------------------------------------------------------------------ samples
def sample_row(path: str, repeat: int) -> dict:
    """The plant's figures of one sample (deg, MPa) and its cold and warm seconds per
    :func:`plant_numbers` evaluation (median of ``repeat`` cold runs, best of 3 warm ones)."""
    design, _ = load_project(path)
    numbers = plant_numbers(design)
    states = {s["state"]: s for s in numbers["states"]}
    for s in numbers["states"]:
        if s["state"] != "filled":  # fixed masses: the moving and the frozen figure are one
            assert s["tip_deg"] == s["tip_frozen_deg"], (path, s)
    row = {"sample": os.path.basename(path)[:-len(".glassbench")],
           "kind": design.shape.cross_section,
           "least_tip_deg": numbers["least_tip"]["deg"], "least_tip_state": numbers["least_tip"]["state"],
           "least_tip_direction_deg": numbers["least_tip"]["direction_deg"]}
    for state in ("empty", "filled", "brimful"):
        s = states.get(state, {})
        row[f"tip_{state}_deg"] = s.get("tip_deg")
        row[f"tip_{state}_frozen_deg"] = s.get("tip_frozen_deg")
    row["max_stress_mpa"] = (numbers["stress"] or {}).get("max_mpa")
    row["cold_s"] = median_seconds(plant_numbers, lambda: fresh_design(design), repeat)
    row["warm_s"] = median_seconds(plant_numbers, lambda: design, 3)
    return row


def _f(x, spec: str) -> str:
    """``x`` formatted, or ``-`` for a figure that is not given."""
    return "-" if x is None else format(x, spec)


def print_samples(rows: list[dict]) -> None:
    """The per-sample table: tip angles moving/frozen (deg), stress (MPa), ms per evaluation."""
    print("Samples: plant_numbers, tip angles moving/frozen (deg), cold = median over fresh shapes")
    print(f"{'sample':16s} {'least':>6s} {'state':>8s} {'dir':>5s} {'empty':>13s} {'filled':>13s} "
          f"{'brimful':>13s} {'stress MPa':>10s} {'cold ms':>8s} {'warm ms':>8s}")
    for r in rows:
        tips = [f"{_f(r[f'tip_{s}_deg'], '.2f')}/{_f(r[f'tip_{s}_frozen_deg'], '.2f')}"
                for s in ("empty", "filled", "brimful")]
        print(f"{r['sample']:16s} {r['least_tip_deg']:6.2f} {r['least_tip_state']:>8s} "
              f"{r['least_tip_direction_deg']:5.1f} {tips[0]:>13s} {tips[1]:>13s} {tips[2]:>13s} "
              f"{_f(r['max_stress_mpa'], '10.2f'):>10s} {r['cold_s'] * 1e3:8.1f} {r['warm_s'] * 1e3:8.2f}")


# ------------------------------------------------------------------------------ closed forms
def closed_form_rows() -> list[dict]:
    """Each closed-form case: the engine's value, the exact one, their relative error."""
    rows = []
    for case in closed_form_cases():
        value = case.value()
        rows.append({"case": case.name, "value": value, "exact": case.exact, "rel_error": rel(value, case.exact)})
    return rows


def print_closed_forms(rows: list[dict]) -> None:
    """The closed-form table."""
    print("Closed forms (mm, g, MPa, deg)")
    print(f"{'case':48s} {'value':>20s} {'exact':>20s} {'rel error':>10s}")
    for r in rows:
        print(f"{r['case']:48s} {r['value']:20.12f} {r['exact']:20.12f} {r['rel_error']:10.2e}")


# ------------------------------------------------------------------------------ the peer
def exact_properties(shape, fill_mm: float) -> tuple[float, float, float, float]:
    """The engine's exact ``(glass mm^3, glass centre z mm, liquid mm^3, liquid centre z mm)``
    of ``shape`` with upright liquid up to ``fill_mm`` (:mod:`engine.plant.mass`)."""
    glass = mass.glass_part(shape, GLASS_G_CM3)
    liquid = mass.liquid_part(shape, fill_mm, 1.0)
    return (glass.mass_g / (GLASS_G_CM3 * mass.G_PER_MM3), glass.cg_z_mm,
            liquid.mass_g / mass.G_PER_MM3, liquid.cg_z_mm)


def mesh_properties(shape, fill_mm: float, tol_mm: float) -> tuple[float, float, float, float]:
    """The same four figures by ``trimesh`` from the engine's meshes at chordal tolerance
    ``tol_mm`` (mm). The meshes are closed and outward (``Mesh.is_watertight``), so the
    divergence theorem over their triangles holds without welding."""
    import trimesh

    out = []
    for mesh in (tessellate_body(shape, tol_mm), tessellate_liquid(shape, fill_mm, tol_mm)):
        props = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False).mass_properties
        out += [float(props["volume"]), float(props["center_mass"][2])]
    return tuple(out)


def cylinder_closed_form() -> tuple[float, float, float, float]:
    """The plain cylinder's four figures in closed form (mm^3, mm): polynomial integrals."""
    mg, zg = cylinder_glass(CYL_R, CYL_H, CYL_W, CYL_B)
    vl, ml = frustum_moments(CYL_R - CYL_W, 0.0, CYL_B, CYL_B + CYL_DEPTH)
    return mg / GLASS_G_MM3, zg, vl, ml / vl


def richardson(coarse, fine, ratio: float) -> tuple:
    """The peer's figures extrapolated to tolerance 0 from two tolerances ``ratio`` apart: the
    error falls as the tolerance (order 1, checked by :func:`convergence`), so
    ``(ratio fine - coarse) / (ratio - 1)`` cancels its leading term."""
    return tuple((ratio * f - c) / (ratio - 1.0) for c, f in zip(coarse, fine))


def peer_cases() -> list[tuple[str, object, float, tuple | None]]:
    """``(name, shape, fill height mm, closed form or None)``: the plain cylinder, then every
    distinct sample shape (samples sharing a shape are measured once) at its own fill."""
    cyl = cylinder(CYL_R, CYL_H, CYL_W, CYL_B, Liquid(fill_mode="height", fill_value=CYL_B + CYL_DEPTH))
    cases = [("cylinder", cyl.shape, CYL_B + CYL_DEPTH, cylinder_closed_form())]
    seen = set()
    for path in SAMPLES:
        design, _ = load_project(path)
        if design.shape in seen or design.liquid is None:
            continue
        seen.add(design.shape)
        name = os.path.basename(path)[:-len(".glassbench")]
        cases.append((name, design.shape, fill.fill_height_mm(design.shape, design.liquid), None))
    return cases


def peer_rows(tols, repeat: int) -> list[dict]:
    """Time (s, cold median) and relative errors of the engine and of the mesh peer per case
    and tolerance. The reference is the closed form where there is one, else the engine."""
    rows = []
    names = ("glass_volume", "glass_cg_z", "liquid_volume", "liquid_cg_z")
    for name, shape, fill_mm, closed in peer_cases():
        ours = exact_properties(shape, fill_mm)
        ref, basis = (closed, "closed form") if closed is not None else (ours, "glassbench")
        secs = median_seconds(lambda s: exact_properties(s, fill_mm), lambda: fresh_shape(shape), repeat)
        methods = [("glassbench", 0.0, ours, secs)]
        for tol in tols:
            got = mesh_properties(shape, fill_mm, tol)
            secs = median_seconds(lambda s: mesh_properties(s, fill_mm, tol), lambda: fresh_shape(shape), repeat)
            methods.append(("trimesh", tol, got, secs))
        (_, t1, a, s1), (_, t2, b, s2) = methods[-2:]
        methods.append(("richardson", t2, richardson(a, b, t1 / t2), s1 + s2))
        for method, tol, got, secs in methods:
            errs = {f"{k}_rel_error": rel(g, r) for k, g, r in zip(names, got, ref)}
            rows.append({"case": name, "reference": basis, "method": method, "tol_mm": tol, "seconds": secs,
                         **{k: g for k, g in zip(names, got)}, **errs, "rel_error": max(errs.values())})
    return rows


def convergence(rows: list[dict]) -> tuple[bool, float]:
    """Whether the peer's error falls at every finer tolerance (within 10 %, or already under
    1e-12), and its order ``p`` (error ~ tol^p, least squares in log-log)."""
    tol = np.array([r["tol_mm"] for r in rows])
    err = np.array([max(r["rel_error"], 1e-300) for r in rows])
    falls = bool(np.all((err[1:] <= 1.1 * err[:-1]) | (err[1:] < 1e-12)))
    order = float(np.polyfit(np.log(tol), np.log(err), 1)[0])
    return falls, order


def print_peer(rows: list[dict]) -> list[str]:
    """The peer's table and, per case, its convergence and the time ratio at comparable error;
    returns the summary lines (printed too)."""
    print("Peer: mass properties of glass and liquid; trimesh on the engine's tessellation vs "
          "glassbench's exact integrals (cold seconds)")
    print(f"{'case':16s} {'reference':>11s} {'method':>10s} {'tol mm':>7s} {'ms':>9s} {'glass V':>9s} "
          f"{'glass z':>9s} {'liquid V':>9s} {'liquid z':>9s} {'worst':>9s}")
    for r in rows:
        print(f"{r['case']:16s} {r['reference']:>11s} {r['method']:>10s} {r['tol_mm']:7.3f} "
              f"{r['seconds'] * 1e3:9.2f} {r['glass_volume_rel_error']:9.1e} {r['glass_cg_z_rel_error']:9.1e} "
              f"{r['liquid_volume_rel_error']:9.1e} {r['liquid_cg_z_rel_error']:9.1e} {r['rel_error']:9.1e}")
    lines, ratios = [], []
    for case in dict.fromkeys(r["case"] for r in rows):
        ours = next(r for r in rows if r["case"] == case and r["method"] == "glassbench")
        plain = sorted((r for r in rows if r["case"] == case and r["method"] == "trimesh"), key=lambda r: -r["tol_mm"])
        falls, order = convergence(plain)
        if not falls:
            errors = ", ".join(f"{r['rel_error']:.1e}" for r in plain)
            lines.append(f"{case}: the peer does not converge (errors {errors}); no ratio quoted")
            continue
        # the peer's best point (extrapolated or not) is still far above the engine's error, so its
        # time there is a lower bound on what it would need to match the engine
        best = min((r for r in rows if r["case"] == case and r["method"] != "glassbench"), key=lambda r: r["rel_error"])
        ratio = best["seconds"] / ours["seconds"]
        ratios.append((ratio, case))
        if ours["reference"] == "closed form":
            engine = f"glassbench {ours['seconds'] * 1e3:.2f} ms at error {ours['rel_error']:.1e}"
            need = plain[-1]["tol_mm"] * (max(ours["rel_error"], 1e-16) / plain[-1]["rel_error"]) ** (1.0 / order)
            engine += f" (the plain peer would need tol ~{need:.0e} mm to match)"
        else:
            engine = f"glassbench {ours['seconds'] * 1e3:.2f} ms (the reference: agrees with the peer to {best['rel_error']:.1e})"
        lines.append(f"{case}: peer converges, error ~ tol^{order:.2f} ({plain[0]['tol_mm']:g} to {plain[-1]['tol_mm']:g} mm); "
                     f"best peer {best['method']} at {best['tol_mm']:g} mm: {best['seconds'] * 1e3:.1f} ms at error "
                     f"{best['rel_error']:.1e}; {engine}; time ratio x{ratio:.0f} (a lower bound at comparable error)")
    if ratios:
        lo, hi = min(ratios), max(ratios)
        lines.append(f"peer / glassbench time at the peer's best error: x{lo[0]:.0f} ({lo[1]}) to x{hi[0]:.0f} ({hi[1]})")
    for line in lines:
        print(line)
    return lines


# ------------------------------------------------------------------------------ output
def write_csv(name: str, rows: list[dict]) -> None:
    """``rows`` (dicts with the same keys) as ``benchmarks/out/NAME``."""
    with open(os.path.join(OUT, name), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


def chart(peer: list[dict], samples: list[dict]) -> None:
    """``plant.png``: time vs relative error per case (log-log, the engine's point and the
    peer's line in one colour), and the cold seconds per sample."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(12, 4.8), gridspec_kw={"width_ratios": [3, 2]})
    for case in dict.fromkeys(r["case"] for r in peer):
        rr = [r for r in peer if r["case"] == case]
        mesh = [r for r in rr if r["method"] == "trimesh"]
        line, = ax.loglog([r["seconds"] for r in mesh], [max(r["rel_error"], 1e-17) for r in mesh], "o--",
                          label=f"{case}: trimesh on tessellation (vs {mesh[0]['reference']})")
        rich = [r for r in rr if r["method"] == "richardson"]
        ax.loglog([r["seconds"] for r in rich], [max(r["rel_error"], 1e-17) for r in rich], "^", ms=8,
                  color=line.get_color(), label=f"{case}: trimesh, Richardson of the two finest")
        ours = next(r for r in rr if r["method"] == "glassbench")
        if ours["reference"] == "closed form":
            ax.loglog([ours["seconds"]], [max(ours["rel_error"], 1e-17)], "s", ms=10, color=line.get_color(),
                      label=f"{case}: glassbench exact (vs closed form)")
        else:
            ax.axvline(ours["seconds"], color=line.get_color(), lw=0.8, ls=":")
    ax.set_xlabel("seconds per evaluation, cold (glass + liquid mass properties)")
    ax.set_ylabel("worst relative error (volume, centre z)")
    ax.set_title("Mass properties: glassbench vs trimesh\n(dotted: glassbench's time on a sample, its own reference)",
                 fontsize=9)
    ax.legend(fontsize=6)
    bx.barh([r["sample"] for r in samples], [r["cold_s"] * 1e3 for r in samples])
    bx.set_xlabel("ms per plant_numbers, cold (median)")
    bx.set_title("The plant's sheet per sample", fontsize=9)
    bx.invert_yaxis()
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "plant.png"), dpi=120)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="3 repetitions, 4 tolerances")
    ap.add_argument("--repeat", type=int, default=None, help="cold repetitions per figure (default 5; quick 3)")
    args = ap.parse_args(argv)
    repeat = args.repeat or (3 if args.quick else 5)
    os.makedirs(OUT, exist_ok=True)
    started = time.perf_counter()

    samples = [sample_row(p, repeat) for p in SAMPLES]
    print_samples(samples)
    print()
    closed = closed_form_rows()
    print_closed_forms(closed)
    print()
    peer = peer_rows(QUICK_TOLERANCES if args.quick else TOLERANCES, repeat)
    print_peer(peer)

    write_csv("plant_samples.csv", samples)
    write_csv("plant_closed_forms.csv", closed)
    write_csv("plant_peer.csv", peer)
    chart(peer, samples)
    print()
    print(f"wrote {os.path.relpath(OUT, ROOT)}/plant_samples.csv, plant_closed_forms.csv, plant_peer.csv, plant.png "
          f"({time.perf_counter() - started:.0f} s)")
    print(f"plant_seconds_per_evaluation_max={max(r['cold_s'] for r in samples):.3g}")
    print(f"plant_worst_closed_form_error={max(r['rel_error'] for r in closed):.3g}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

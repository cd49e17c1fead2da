"""Issue 60's time to equal error: the Cornell box (examples/light/cornell.scn, the same
scene as examples/mitsuba/cornell.xml and examples/cycles/cornell.py) or, with `--scene
gyroid-room`, benches/scenes/gyroid-room.scn (scnc tracing the field; Mitsuba and Cycles
rendering scnc's mesh of it, its meshing counted in their time) rendered by scnc,
Mitsuba 3 and Blender Cycles at a ladder of samples, each image's RMSE against the truth
estimated, and the time each renderer needs to reach a target RMSE.

    python3 benches/light_error.py [--scene cornell] [--res 512] [--ladder 16,64,256,1024] \
        [--cycles-ladder 16,64,256] [--ref-spp 4096] [--sampler multijitter] [--target 0.02] \
        [--noise-ladder 0.1,0.05,0.03] [--noise-cap 4096] [--cycles-noise-ladder 0.02,0.01] \
        [--rows rows.txt] [--skip cycles]

How the error is estimated (all radiance, linear, every pixel and channel):
- The reference is Mitsuba at `--ref-spp` samples; its own noise is known from Mitsuba's
  pairs below (variance × N is constant for an unbiased renderer), and is subtracted from
  every MSE measured against it: MSE(truth) = MSE(reference) − σ²_M / ref_spp.
- Mitsuba and Cycles render every rung twice with different seeds: two independent
  images differ by twice one's variance, so MSE(truth) = MSE(pair) / 2, needing no
  reference (Cycles' scene differs in small ways, mesh spheres and its filter, so it is
  held only to its own truth; its RMSE against the reference is logged beside it). scnc
  has no seed (its sampler is deterministic), so it is held to the reference.
- Each renderer's RMSE is extrapolated as c/√N from its top rung (the slope over the
  ladder is printed), its time fitted as a + b·N (start-up, scene loading, JIT and BVH in a); the time to `--target` is
  a + b·(c / target)².
Wall time of the whole command for scnc, of load + render for Mitsuba, of the render call
for Cycles (each renderer's start-up cost counted once in a), 2 threads each.
scnc also renders with adaptive sampling (`--noise ε --samples cap`, one rung an ε of
`--noise-ladder`), held to the reference as its fixed rungs are; its time to the target
is interpolated between rungs on log RMSE against log time. `--cycles-noise-ladder` does
the same for Cycles' adaptive sampling (`adaptive_threshold`), held to itself by pairs.
`--rows` writes `RENDERER SAMPLES RMSE SECONDS` lines for `cargo run --release --example
light_plot -- out.png < rows.txt`.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
SCENES = {
    "cornell": (os.path.join(ROOT, "examples", "light", "cornell.scn"),
                os.path.join(ROOT, "examples", "mitsuba", "cornell.xml"),
                os.path.join(ROOT, "examples", "cycles", "cornell.py")),
    "gyroid-room": (os.path.join(ROOT, "benches", "scenes", "gyroid-room.scn"),
                    os.path.join(ROOT, "examples", "mitsuba", "gyroid-room.xml"),
                    os.path.join(ROOT, "examples", "cycles", "gyroid-room.py")),
}
SHEET = os.path.join(ROOT, "benches", "scenes", "gyroid-sheet.scn")
SCNC = os.path.join(ROOT, "target", "release", "scnc")


def read_exr(path):
    import mitsuba as mi
    return np.array(mi.Bitmap(path), dtype=np.float64)[:, :, :3]


def scnc(scene, res, spp, tmp, noise=None):
    """One scnc render: `spp` samples a pixel, or with `noise` adaptive sampling up to
    `spp`; the image, the wall time and the mean samples a pixel (from `--stats`)."""
    out = os.path.join(tmp, f"scnc-{spp}-{noise}.exr")
    more = ["--noise", str(noise)] if noise else []
    start = time.time()
    r = subprocess.run([SCNC, "render", scene, "-o", out, "--width", str(res), "--height", str(res),
                        "--samples", str(spp), "--threads", "2", "--stats", *more],
                       check=True, capture_output=True, text=True)
    seconds = time.time() - start
    line = [l for l in r.stderr.splitlines() if "samples per pixel" in l][0]
    taken = float(line.split("(")[1].split()[0])
    return read_exr(out), seconds, taken


MITSUBA_CHILD = r"""
import json, sys, time
import numpy as np
import mitsuba as mi
xml, variant, sampler, res, spp, seed, out, extra = sys.argv[1:9]
mi.set_variant(variant)
mi.set_log_level(mi.LogLevel.Warn)
start = time.time()
scene = mi.load_file(xml, spp=int(spp), res=int(res), sampler=sampler, **json.loads(extra))
# The LLVM variant renders lazily: the image is computed when it is read, so the clock
# stops after writing it.
mi.Bitmap(mi.render(scene, seed=int(seed))).write(out)
print(json.dumps({"seconds": time.time() - start}))
"""


def mitsuba(xml, extra, variant, sampler, res, spp, seed, tmp):
    """One Mitsuba render of `xml` (`extra`: more of its parameters, the gyroid room's
    mesh) in its own process, so that every rung pays the same start-up."""
    out = os.path.join(tmp, f"mitsuba-{spp}-{seed}.exr")
    r = subprocess.run([sys.executable, "-c", MITSUBA_CHILD, xml, variant, sampler, str(res), str(spp), str(seed),
                        out, json.dumps(extra)],
                       check=True, capture_output=True, text=True, env={**os.environ, "DRJIT_NUM_THREADS": "2"})
    # Mitsuba's own log lines (coloured) share standard output: the figure is the last
    # JSON object in it.
    return read_exr(out), json.loads(r.stdout[r.stdout.rindex('{"seconds"'):].splitlines()[0])["seconds"]


def cycles(script, extra, res, spp, seed, tmp):
    """One Cycles render by `script` (`extra`: its further arguments, the gyroid room's
    mesh): the image and the render call's seconds."""
    out = os.path.join(tmp, f"cycles-{spp}-{seed}.exr")
    r = subprocess.run([sys.executable, script, *extra, "--res", str(res), "--spp", str(spp), "--seed", str(seed),
                        "--out", out], check=True, capture_output=True, text=True)
    seconds = float([l for l in r.stderr.splitlines() if l.startswith("cycles:")][-1].split()[1])
    return read_exr(out), seconds


def mse(a, b):
    return float(np.mean((a - b) ** 2))


def pair(render, n):
    """Two renders of `n` samples with seeds 1 and 2: the MSE of one against the truth
    (two independent images differ by twice one's variance), their mean time, the first."""
    x, t1 = render(n, 1)
    y, t2 = render(n, 2)
    return mse(x, y) / 2, (t1 + t2) / 2, x, (t1, t2)


def fit(ladder, rmse, seconds):
    """c and the slope of RMSE against N on log–log, and a, b of time = a + b·N. c is
    RMSE·√N at the top rung: a sampler that converges faster than 1/√N at the low rungs
    (stratified and quasi-random ones do) is not credited with keeping that up."""
    n = np.array(ladder, dtype=np.float64)
    slope, _ = np.polyfit(np.log(n), np.log(rmse), 1)
    c = float(rmse[-1] * np.sqrt(n[-1]))
    b, a = np.polyfit(n, np.array(seconds), 1)
    return c, float(slope), float(max(a, 0.0)), float(b)


def time_to(rungs, target):
    """The time to RMSE `target` of adaptive rungs `(threshold, samples, MSE, seconds)`:
    interpolated on log RMSE against log time between the rungs that bracket it, or
    extrapolated from the two nearest."""
    pts = sorted((np.log(t), 0.5 * np.log(e2)) for _, _, e2, t in rungs)
    goal = np.log(target)
    k = next((i for i in range(len(pts) - 1) if pts[i + 1][1] <= goal <= pts[i][1]),
             0 if goal > pts[0][1] else len(pts) - 2)
    (t0, e0), (t1, e1) = pts[k], pts[k + 1]
    return float(np.exp(t0 + (goal - e0) * (t1 - t0) / (e1 - e0)))


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--res", type=int, default=512)
    p.add_argument("--ladder", default="16,64,256,1024")
    p.add_argument("--cycles-ladder", default="16,64,256")
    p.add_argument("--sampler", default="multijitter", help="Mitsuba's sampler (its best at equal samples here)")
    p.add_argument("--ref-spp", type=int, default=4096)
    p.add_argument("--target", type=float, default=0.02)
    p.add_argument("--variant", default="llvm_ad_rgb")
    p.add_argument("--rows")
    p.add_argument("--skip", default="")
    p.add_argument("--scene", default="cornell", choices=sorted(SCENES))
    p.add_argument("--noise-ladder", default="0.1,0.05,0.03", help="scnc --noise rungs (empty: none)")
    p.add_argument("--noise-cap", type=int, default=4096, help="the most samples with adaptive sampling")
    p.add_argument("--cycles-noise-ladder", default="", help="Cycles adaptive thresholds (empty: none)")
    a = p.parse_args()
    scene, xml, cycles_script = SCENES[a.scene]
    extra, cycles_extra = {}, []
    ladder = [int(x) for x in a.ladder.split(",")]
    skip = set(a.skip.split(",")) - {""}
    results, adaptive, cycles_adaptive = {}, [], []
    with tempfile.TemporaryDirectory() as tmp:
        log = lambda *m: print(*m, file=sys.stderr, flush=True)
        meshing = 0.0
        if a.scene == "gyroid-room":
            # The other renderers get scnc's own mesh of the field; making it is part of
            # their time.
            mesh = os.path.join(tmp, "gyroid.ply")
            start = time.time()
            subprocess.run([SCNC, "export", SHEET, "-o", mesh, "--tolerance", "0.001", "--threads", "2"], check=True,
                           stderr=subprocess.DEVNULL)
            meshing = time.time() - start
            extra["mesh"] = mesh
            cycles_extra = ["--mesh", mesh]
            log(f"meshing the gyroid sheet at --tolerance 0.001: {meshing:.1f} s")
        render_m = lambda spp, seed: mitsuba(xml, extra, a.variant, a.sampler, a.res, spp, seed, tmp)
        log(f"reference: Mitsuba {a.res}² × {a.ref_spp}")
        ref, t_ref = render_m(a.ref_spp, 1000)
        log(f"  {t_ref:.1f} s, mean {ref.mean(axis=(0, 1))}")
        # Mitsuba's pairs give its variance, and so the reference's own noise.
        m_rows, var_m = [], []
        for n in ladder:
            e2, t, x, (t1, t2) = pair(render_m, n)
            var_m.append(e2 * n)
            m_rows.append((n, e2, t + meshing))
            log(f"  mitsuba {n}: {t1:.1f} / {t2:.1f} s, rmse {e2 ** 0.5:.4f}, against ref "
                f"{mse(x, ref) ** 0.5:.4f}")
        ref_noise = float(np.mean(var_m)) / a.ref_spp
        # scnc has no seed: its MSE against the truth is its MSE against the reference
        # less the reference's own noise.
        held = lambda x: max(mse(x, ref) - ref_noise, 1e-12)
        results["Mitsuba 3"] = m_rows
        if "scnc" not in skip:
            rows = []
            for n in ladder:
                x, t, _ = scnc(scene, a.res, n, tmp)
                e2 = held(x)
                rows.append((n, e2, t))
                log(f"  scnc {n}: {t:.1f} s, rmse {e2 ** 0.5:.4f} (against ref {mse(x, ref) ** 0.5:.4f}), "
                    f"mean {x.mean(axis=(0, 1))}")
            results["scnc"] = rows
            # Adaptive sampling: each rung an ε, its samples wherever the noise is. Its
            # time to the target is interpolated on log RMSE against log time between the
            # rungs around it (or extrapolated from the two nearest).
            for eps in [float(x) for x in a.noise_ladder.split(",") if x]:
                x, t, taken = scnc(scene, a.res, a.noise_cap, tmp, eps)
                e2 = held(x)
                adaptive.append((eps, taken, e2, t))
                log(f"  scnc --noise {eps}: {t:.1f} s, {taken:.1f} samples a pixel, rmse {e2 ** 0.5:.4f}, "
                    f"mean {x.mean(axis=(0, 1))}")
        if "cycles" not in skip:
            rows = []
            render_c = lambda spp, seed: cycles(cycles_script, cycles_extra, a.res, spp, seed, tmp)
            for n in [int(x) for x in a.cycles_ladder.split(",")]:
                e2, t, x, (t1, t2) = pair(render_c, n)
                rows.append((n, e2, t + meshing))
                # Against Mitsuba's reference as well: what its own noise does not explain
                # is a difference of the scenes (its filter is not the tent).
                log(f"  cycles {n}: {t1:.1f} / {t2:.1f} s, rmse {e2 ** 0.5:.4f}, against ref "
                    f"{mse(x, ref) ** 0.5:.4f}, mean {x.mean(axis=(0, 1))}")
            results["Cycles"] = rows
            # Cycles' own adaptive sampling, as scnc's: pairs of seeds at each threshold.
            for th in [float(x) for x in a.cycles_noise_ladder.split(",") if x]:
                more = [*cycles_extra, "--adaptive-threshold", str(th)]
                render_a = lambda spp, seed: cycles(cycles_script, more, a.res, spp, seed, tmp)
                e2, t, x, (t1, t2) = pair(render_a, a.noise_cap)
                cycles_adaptive.append((th, float("nan"), e2, t + meshing))
                log(f"  cycles --adaptive-threshold {th}: {t1:.1f} / {t2:.1f} s, rmse {e2 ** 0.5:.4f}")
    if meshing:
        print(f"Mitsuba's and Cycles' times include meshing the field at --tolerance 0.001: {meshing:.1f} s\n")
    print(f"{a.scene} {a.res}², reference Mitsuba ({a.sampler}) × {a.ref_spp} (its noise, RMSE "
          f"{ref_noise ** 0.5:.4f}, subtracted), target RMSE {a.target}, 2 threads each\n")
    print("| renderer | samples | seconds | RMSE |")
    print("|---|---|---|---|")
    summary = {}
    for name, rows in results.items():
        for n, e2, t in rows:
            print(f"| {name} | {n} | {t:.2f} | {e2 ** 0.5:.4f} |")
        c, slope, a0, b = fit([r[0] for r in rows], [r[1] ** 0.5 for r in rows], [r[2] for r in rows])
        need = (c / a.target) ** 2
        summary[name] = (slope, a0, b, need, a0 + b * need)
    print("\n| renderer | RMSE slope | start-up s | s per sample | samples to target | seconds to target |")
    print("|---|---|---|---|---|---|")
    for name, (slope, a0, b, need, t) in summary.items():
        print(f"| {name} | {slope:.3f} | {a0:.2f} | {b:.4f} | {need:.0f} | {t:.1f} |")
    if "scnc" in summary:
        for name in ("Mitsuba 3", "Cycles"):
            if name in summary:
                print(f"\nscnc's time to target against {name}'s: {summary['scnc'][4] / summary[name][4]:.2f}×")
    for name, rungs in (("scnc --noise", adaptive), ("Cycles adaptive", cycles_adaptive)):
        if len(rungs) < 2:
            continue
        print(f"\n| {name} (most samples {a.noise_cap}) | threshold | samples a pixel | seconds | RMSE |")
        print("|---|---|---|---|---|")
        for eps, taken, e2, t in rungs:
            shown = "—" if np.isnan(taken) else f"{taken:.1f}"
            print(f"| | {eps} | {shown} | {t:.2f} | {e2 ** 0.5:.4f} |")
        t_goal = time_to(rungs, a.target)
        print(f"\n{name}: {t_goal:.1f} s to RMSE {a.target}")
        for other in ("Mitsuba 3", "Cycles"):
            if other in summary:
                print(f"{name}'s time to target against {other}'s fixed samples: {t_goal / summary[other][4]:.2f}×")
    if a.rows:
        with open(a.rows, "w") as f:
            for name, rows in results.items():
                for n, e2, t in rows:
                    f.write(f"{name.split()[0]} {n} {e2 ** 0.5:.6g} {t:.4g}\n")
            for _, taken, e2, t in adaptive:
                f.write(f"scnc-noise {taken:.0f} {e2 ** 0.5:.6g} {t:.4g}\n")


if __name__ == "__main__":
    main()

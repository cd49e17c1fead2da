#!/usr/bin/env python3
"""Renders examples/light/cornell.scn with scnc and examples/mitsuba/cornell.xml with
Mitsuba 3, both to linear float, and compares them: the mean of each channel and the
relative RMSE (RMSE over the mean), with each renderer's time and the noise each image
still has (the RMSE between two halves of its samples, scaled to the whole).

    pip install mitsuba                 # and Debian's libllvm19 for the llvm variant
    cargo build --release
    python3 examples/mitsuba/compare.py [--res 128] [--spp 4096] [--variant llvm_ad_rgb]

Both renderers use 2 threads. Prints a Markdown table (docs/light.md quotes it)."""

import argparse
import os
import subprocess
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
SCENE = os.path.join(ROOT, "examples", "light", "cornell.scn")
XML = os.path.join(HERE, "cornell.xml")
SCNC = os.path.join(ROOT, "target", "release", "scnc")


def scnc(res, spp, out):
    """scnc's render at res × res with spp samples, as float radiance, and its time."""
    text = open(SCENE).read().replace("width = 256, height = 256", f"width = {res}, height = {res}")
    scene = os.path.join(os.path.dirname(out), "cornell.scn")
    with open(scene, "w") as f:
        f.write(text)
    start = time.time()
    subprocess.run([SCNC, "render", scene, "-o", out, "--samples", str(spp), "--threads", "2"], check=True,
                   stderr=subprocess.DEVNULL)
    took = time.time() - start
    import mitsuba as mi
    return np.array(mi.Bitmap(out), dtype=np.float64), took


def mitsuba(variant, res, spp, seed=0):
    """Mitsuba's render, and its time (scene loading and JIT compilation included)."""
    import mitsuba as mi
    mi.set_variant(variant)
    mi.set_log_level(mi.LogLevel.Warn)
    start = time.time()
    scene = mi.load_file(XML, spp=spp, res=res)
    img = np.array(mi.render(scene, seed=seed), dtype=np.float64)
    return img, time.time() - start


def rel_rmse(a, b):
    return float(np.sqrt(np.mean((a - b) ** 2)) / np.mean(b))


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--res", type=int, default=128)
    p.add_argument("--spp", type=int, default=4096)
    p.add_argument("--variant", default="llvm_ad_rgb")
    a = p.parse_args()
    os.environ.setdefault("DRJIT_NUM_THREADS", "2")
    import mitsuba as mi
    try:
        mi.set_variant(a.variant)
    except Exception:
        a.variant = "scalar_rgb"
    with tempfile.TemporaryDirectory() as tmp:
        ours, t_ours = scnc(a.res, a.spp, os.path.join(tmp, "scnc.exr"))
        theirs, t_theirs = mitsuba(a.variant, a.res, a.spp)
        # Each renderer's own noise: two independent half-sample renders of Mitsuba.
        half1, _ = mitsuba(a.variant, a.res, a.spp // 2, seed=1)
        half2, _ = mitsuba(a.variant, a.res, a.spp // 2, seed=2)
    m_ours, m_theirs = ours.mean(axis=(0, 1)), theirs.mean(axis=(0, 1))
    print(f"| | scnc | Mitsuba 3 ({a.variant}) |")
    print("|---|---|---|")
    print(f"| time, {a.res}² × {a.spp} spp, 2 threads | {t_ours:.1f} s | {t_theirs:.1f} s |")
    for k, name in enumerate("RGB"):
        print(f"| mean {name} | {m_ours[k]:.5f} | {m_theirs[k]:.5f} ({100 * (m_ours[k] / m_theirs[k] - 1):+.2f} %) |")
    print(f"| relative RMSE, scnc against Mitsuba | {100 * rel_rmse(ours, theirs):.2f} % | |")
    # Two half renders differ by √2 × one half's noise, and a half's noise is √2 × the
    # whole's: their RMSE is 2 × the whole render's noise.
    print(f"| Mitsuba's own noise at {a.spp} spp (halves' RMSE / 2) | | {100 * rel_rmse(half1, half2) / 2:.2f} % |")


if __name__ == "__main__":
    main()

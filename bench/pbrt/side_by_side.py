#!/usr/bin/python3
"""nimbus against pbrt-v4 on the same scenes (issue 13): run by bench/pbrt_side_by_side.sh.

Per scene, every renderer configuration renders SPP samples per pixel on one thread, REPS
times (seeds 1..REPS), configurations interleaved within each repetition so that a slow spell
of the shared machine touches all of them alike. Each configuration's error is its MSE (over
pixels and channels) against that renderer's own converged reference, less the reference's
own expected error, averaged over the repetitions; its time is the process's CPU time
(user + system) at SPP spp less that at 1 spp (the setup: parsing, grid loading, majorant
structures, image writing), medians over the repetitions, scaled by SPP / (SPP - 1).
Efficiency is 1 / (MSE * time), also given relative to pbrt-v4 on the same scene.

References are rendered once (all threads, seeds 977 and 978, REF_SPP/2 spp each; their
average is the reference and a quarter of the two halves' MSE is its expected error) and cached
in OUT/refs, keyed by the scene file's contents, the overrides and REF_SPP: delete that folder
after changing a renderer. Two references of the same scene (nimbus spectral mode and pbrt-v4)
are compared to show that the scenes match: image means, and block means against the
references' own noise.

--manifold-off (off by default) adds, to every scene run, nimbus with manifold next-event
estimation turned off (the render setting integrator.manifold=false, issue 41), spectral MIS in
rgb and in spectral 4 mode, measured against the same reference as manifold sampling on (both
estimate the same image, so a bias between them would only add to its MSE). A nimbus without
that setting rejects the key, and the run stops at its first render.
"""

import argparse
import hashlib
import json
import os
import shutil
import statistics
import subprocess
import sys
import time

import numpy as np

from harness import (LUMINANCE, REPO, RenderFailed, block_sums, log, nimbus_command,
                     pbrt_command, read_exr, run_timed)

HERE = os.path.join(REPO, "bench", "pbrt")

# nimbus settings: (label, overrides)
SPECTRUM = {
    "rgb": ['spectrum.mode="rgb"'],
    "spectral 4": ['spectrum.mode="spectral"', "spectrum.wavelengths=4"],
}
TRACKING = {
    "spectral-mis": ['integrator.tracking="spectral-mis"', 'integrator.absorption="collide"'],
    "spectral-mis, every light per vertex": [
        'integrator.tracking="spectral-mis"', 'integrator.absorption="collide"',
        'integrator.light_sampling="all"'],
    "history + decomposition": [
        'integrator.tracking="spectral-history"', 'integrator.absorption="weight"',
        "integrator.decomposition=true", 'integrator.transmittance="residual-ratio"'],
}
COMMON = ['integrator.sampler="zsobol"']
# nimbus's own default count of wavelengths in spectral mode (pbrt-v4's is fixed at 4 when it is
# compiled), with spectral MIS only. Its expected image is spectral 4's (both estimate the same
# CIE integrals without bias), so it is measured against spectral 4's reference: a bias between
# them would only add to its MSE.
DEFAULT_COUNT = ("spectral 8 (default)", ['spectrum.mode="spectral"', "spectrum.wavelengths=8"])
# --manifold-off: manifold next-event estimation turned off (issue 41; default on).
MANIFOLD_OFF = ("spectral-mis, manifold off", ["integrator.manifold=false"])

# --voxel-size, for the titles.
VOXEL_SIZE = [1 / 64]
# scene key -> (title, nimbus scene, pbrt scene); paths relative to OUT once staged.
SCENES = {
    "cloud": ("chromatic cloud (nimbus: its procedural density; pbrt: the {grid} grid)",
              "chromatic_cloud.json", "chromatic_cloud.pbrt"),
    "cloud-grid": ("chromatic cloud, the same {grid} grid in both",
                   "chromatic_cloud_vdb.json", "chromatic_cloud.pbrt"),
    "marble": ("marble sphere (SSS behind glass, IOR 1.5)", "marble.json", "marble.pbrt"),
    "skin": ("skin ellipsoid (SSS behind glass, IOR 1.3)", "skin.json", "skin.pbrt"),
    "marble-sun": ("marble sphere under a 1° sun (sphere light)", "marble_sun.json",
                   "marble_sun.pbrt"),
    "rough-marble": ("marble sphere behind a rough dielectric (GGX α 0.3, single scattering)",
                     "rough_marble.json", "rough_marble.pbrt"),
    "rough-gold": ("rough gold-like conductor sphere (GGX α 0.2, single scattering)",
                   "rough_gold.json", "rough_gold.pbrt"),
}


class Ctx:
    def __init__(self, a):
        self.a = a
        self.out = os.path.abspath(a.out)
        self.tmp = os.path.join(self.out, "tmp")
        self.refs = os.path.join(self.out, "refs")
        os.makedirs(self.tmp, exist_ok=True)
        os.makedirs(self.refs, exist_ok=True)
        self.exr_to_pfm = a.exr_to_pfm

    # One render; returns (image, cpu seconds, wall seconds, stats or None).
    def render(self, r, spp, seed, threads, tag):
        exr = os.path.join(self.tmp, tag + ".exr")
        if r["renderer"] == "nimbus":
            stats = os.path.join(self.tmp, tag + ".json")
            cmd = nimbus_command(self.a.nimbus, r["scene"], exr, spp, seed, threads, stats,
                                 r["overrides"])
        else:
            stats = None
            cmd = pbrt_command(self.a.pbrt, r["scene"], exr, spp, seed, threads, False)
        try:
            cpu, wall, _ = run_timed(cmd, self.out, os.path.join(self.tmp, tag + ".log"), 2000)
        except RenderFailed as e:
            hint = ""
            if MANIFOLD_OFF[1][0] in r.get("overrides", []):
                hint = ("\n(--manifold-off needs a nimbus that has the render setting "
                        "integrator.manifold, issue 41)")
            sys.exit("command failed (exit %d): %s\n%s%s" % (e.code, " ".join(e.cmd),
                                                             e.log_tail, hint))
        img = read_exr(self.exr_to_pfm, exr)
        st = json.load(open(stats)) if stats else None
        return img, cpu, wall, st

    def reference(self, c):
        r = dict(c, overrides=c["ref_overrides"])
        key = hashlib.sha1(open(os.path.join(self.out, r["scene"]), "rb").read())
        key.update(("|".join(r["overrides"]) + "|%d" % self.a.ref_spp).encode())
        name = "%s-%s-%s" % (r["renderer"], os.path.splitext(r["scene"])[0], key.hexdigest()[:12])
        path = os.path.join(self.refs, name + ".npz")
        if os.path.exists(path):
            z = np.load(path)
            return z["mean"], float(z["noise"]), z["pixel_var"]
        half = max(1, self.a.ref_spp // 2)
        log("reference: %s, %s, 2 x %d spp on %d threads..." % (
            r["label"], r["scene"], half, self.a.ref_threads))
        t0 = time.time()
        h1 = self.render(r, half, 977, self.a.ref_threads, name + "-h1")[0]
        h2 = self.render(r, half, 978, self.a.ref_threads, name + "-h2")[0]
        mean = 0.5 * (h1 + h2)
        pixel_var = 0.25 * (h1 - h2) ** 2  # an unbiased estimate of each pixel's variance
        noise = float(pixel_var.mean())
        np.savez(path, mean=mean, noise=noise, pixel_var=pixel_var)
        log("  %.0f s, noise %.3e" % (time.time() - t0, noise))
        return mean, noise, pixel_var


def stage(ctx):
    """Copies the scenes into OUT and makes the cloud's grid (VDB for nimbus, NanoVDB for pbrt)."""
    out = ctx.out
    for f in ("chromatic_cloud.json", "marble.json", "skin.json", "marble_sun.json"):
        shutil.copyfile(os.path.join(REPO, "scenes", "bench", f), os.path.join(out, f))
    for f in ("chromatic_cloud_vdb.json", "chromatic_cloud.pbrt", "marble.pbrt", "skin.pbrt",
              "marble_sun.pbrt", "rough_marble.json", "rough_marble.pbrt", "rough_gold.json",
              "rough_gold.pbrt"):
        shutil.copyfile(os.path.join(HERE, f), os.path.join(out, f))
    src = os.path.join(out, "chromatic_cloud.json")
    stamp = os.path.join(out, "chromatic_cloud.grid-stamp")
    key = hashlib.sha1(open(src, "rb").read() + str(ctx.a.voxel_size).encode()).hexdigest()
    vdb = os.path.join(out, "chromatic_cloud.vdb")
    nvdb = os.path.join(out, "chromatic_cloud.nvdb")
    if not (os.path.exists(stamp) and open(stamp).read() == key and os.path.exists(vdb)
            and os.path.exists(nvdb)):
        log("exporting the cloud's density (voxel size %g)..." % ctx.a.voxel_size)
        subprocess.run([ctx.a.nimbus, "export-vdb", src, "-o", vdb, "--voxel-size",
                        repr(ctx.a.voxel_size), "--quiet"], check=True)
        subprocess.run([ctx.a.vdb_tool, "-read", vdb, "-write", "codec=none", "bits=32", nvdb],
                       check=True, stdout=subprocess.DEVNULL)
        open(stamp, "w").write(key)


def configs(scene_key, manifold_off=False):
    title, nscene, pscene = SCENES[scene_key]
    # The cloud's grid spans the unit sphere's box [-1, 1]³ with a voxel at each end.
    title = title.format(grid="%d³" % (round(2 / VOXEL_SIZE[0]) + 1))
    cs = [{"renderer": "pbrt", "label": "pbrt-v4", "spectrum": "spectral 4",
           "tracking": "spectral MIS (volpath)", "scene": pscene, "overrides": [],
           "ref_overrides": []}]
    for sp, so in SPECTRUM.items():
        for tr, to in TRACKING.items():
            # One reference per spectrum mode (the expected image does not depend on the
            # tracking estimator): spectral MIS's.
            cs.append({"renderer": "nimbus", "label": "nimbus %s" % sp, "spectrum": sp,
                       "tracking": tr, "scene": nscene, "overrides": COMMON + so + to,
                       "ref_overrides": COMMON + so + TRACKING["spectral-mis"]})
    sp, so = DEFAULT_COUNT
    cs.append({"renderer": "nimbus", "label": "nimbus %s" % sp, "spectrum": sp,
               "tracking": "spectral-mis", "scene": nscene,
               "overrides": COMMON + so + TRACKING["spectral-mis"],
               "ref_overrides": COMMON + SPECTRUM["spectral 4"] + TRACKING["spectral-mis"]})
    if manifold_off:
        for sp, so in SPECTRUM.items():
            ref = COMMON + so + TRACKING["spectral-mis"]
            cs.append({"renderer": "nimbus", "label": "nimbus %s" % sp, "spectrum": sp,
                       "tracking": MANIFOLD_OFF[0], "scene": nscene,
                       "overrides": ref + MANIFOLD_OFF[1], "ref_overrides": ref})
    return title, cs


def block_compare(ref_a, var_a, ref_b, var_b, block):
    """Block means of two references: the relative difference of each block's luminance, and
    the part of it that the references' own noise explains (from their per-pixel variance
    estimates, channels taken as independent). z-scores would mislead: where a pixel sees only
    the sky, its variance is near 0 and the renderers' RGB-to-spectrum round trips (pbrt's
    within about 1e-4) dominate."""
    def blocks(x):
        return block_sums(x, block)
    n = block * block
    wl = LUMINANCE
    la, lb = (blocks(ref_a) / n) @ wl, (blocks(ref_b) / n) @ wl
    noise = np.sqrt((blocks(var_a) / n ** 2 + blocks(var_b) / n ** 2) @ (wl ** 2))
    rel = (lb - la) / np.maximum(la, 1e-6)
    bright = la > 0.1 * la.max()
    return {"blocks": int(la.size), "n_bright": int(bright.sum()),
            "lum_rel_rms": float(np.sqrt((rel[bright] ** 2).mean())),
            "lum_rel_max": float(np.abs(rel[bright]).max()),
            "noise_rel_rms": float(np.sqrt(((noise / np.maximum(la, 1e-6))[bright] ** 2).mean()))}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--pbrt", required=True)
    ap.add_argument("--nimbus", required=True)
    ap.add_argument("--vdb-tool", dest="vdb_tool", default="vdb_tool")
    ap.add_argument("--exr-to-pfm", dest="exr_to_pfm", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--ref-spp", dest="ref_spp", type=int, default=4096)
    ap.add_argument("--ref-threads", dest="ref_threads", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--voxel-size", dest="voxel_size", type=float, default=1 / 64)
    ap.add_argument("--json", default=None, help="also write the raw results here")
    ap.add_argument("--manifold-off", dest="manifold_off", action="store_true",
                    help="also run nimbus with integrator.manifold=false (issue 41; needs a "
                         "nimbus that has that setting)")
    ap.add_argument("scenes", nargs="*", default=list(SCENES))
    a = ap.parse_args()
    for s in a.scenes:
        if s not in SCENES:
            sys.exit("unknown scene %r (known: %s)" % (s, ", ".join(SCENES)))
    VOXEL_SIZE[0] = a.voxel_size
    ctx = Ctx(a)
    stage(ctx)

    results = {}
    for s in a.scenes:
        title, cs = configs(s, a.manifold_off)
        for c in cs:
            c["ref"], c["ref_noise"], c["ref_var"] = ctx.reference(c)
        results[s] = (title, cs)

    # Timed renders: every repetition runs every configuration of every scene, interleaved.
    for rep in range(a.reps):
        log("repetition %d of %d" % (rep + 1, a.reps))
        for s in a.scenes:
            for i, c in enumerate(results[s][1]):
                img, cpu, wall, st = ctx.render(c, a.spp, 1 + rep, 1, "%s-%d" % (s, i))
                _, cpu1, wall1, _ = ctx.render(c, 1, 1 + rep, 1, "%s-%d-setup" % (s, i))
                mse = float(((img - c["ref"]) ** 2).mean()) - c["ref_noise"]
                c.setdefault("mse", []).append(mse)
                c.setdefault("cpu", []).append(cpu)
                c.setdefault("wall", []).append(wall)
                c.setdefault("cpu1", []).append(cpu1)
                c.setdefault("mean", []).append(img.mean(axis=(0, 1)))
                if st:
                    c.setdefault("nimbus_wall", []).append(st["wall_seconds"])

    load = open("/proc/loadavg").read().split()[:3]
    print("\n%d × %d pixels, %d spp, one thread each, %d repetitions (seeds 1–%d); references "
          "%d spp; load average at the end %s.\n" % (
              64, 64, a.spp, a.reps, a.reps, a.ref_spp, " ".join(load)))
    raw = {}
    for s in a.scenes:
        title, cs = results[s]
        print("### %s\n" % title)
        print("| renderer | spectrum | tracking | time (s) | setup (s) | MSE | efficiency "
              "1/(MSE·s) | × pbrt-v4 |")
        print("|---|---|---|---|---|---|---|---|")
        base = None
        for c in cs:
            t64 = statistics.median(c["cpu"])
            t1 = statistics.median(c["cpu1"])
            t = max(t64 - t1, 1e-9) * a.spp / max(a.spp - 1, 1)
            mse = statistics.fmean(c["mse"])
            eff = 1 / (mse * t)
            if base is None:
                base = eff
            c.update(time=t, setup=t1, mse_mean=mse, eff=eff, rel=eff / base)
            print("| %s | %s | %s | %.3f | %.3f | %.3e | %.3g | **%.2f** |" % (
                c["renderer"], c["spectrum"], c["tracking"], t, t1, mse, eff, eff / base))
        # How well the scenes match: the references' means.
        pb = cs[0]
        print("\nReferences (%d spp; noise = the expected MSE of the reference itself):\n" % a.ref_spp)
        print("| reference | image mean (R, G, B) | vs pbrt-v4 (R, G, B) | noise |")
        print("|---|---|---|---|")
        for c in cs:
            if c["renderer"] == "nimbus" and (c["tracking"] != "spectral-mis"
                                              or c["spectrum"] == DEFAULT_COUNT[0]):
                continue  # one reference per nimbus spectrum mode is enough here
            m = c["ref"].mean(axis=(0, 1))
            rel = (m - pb["ref"].mean(axis=(0, 1))) / pb["ref"].mean(axis=(0, 1))
            print("| %s %s | %.4f, %.4f, %.4f | %+.2f %%, %+.2f %%, %+.2f %% | %.1e |" % (
                c["renderer"], c["spectrum"], *m, *(100 * rel), c["ref_noise"]))
        nspec = [c for c in cs if c["renderer"] == "nimbus" and c["spectrum"] == "spectral 4"
                 and c["tracking"] == "spectral-mis"][0]
        nrgb = [c for c in cs if c["renderer"] == "nimbus" and c["spectrum"] == "rgb"
                and c["tracking"] == "spectral-mis"][0]
        cmp = {}
        for label, c in (("nimbus spectral 4", nspec), ("nimbus rgb", nrgb)):
            for b in (16, 8):
                r = block_compare(pb["ref"], pb["ref_var"], c["ref"], c["ref_var"], b)
                cmp["%s/%d" % (label, b)] = r
                print("\n%s against pbrt-v4, %d blocks of %d × %d pixels: block luminance "
                      "differs by %.2f %% rms, at most %.2f %% (the %d blocks brighter than a "
                      "tenth of the brightest); the references' own noise: %.2f %% rms."
                      % (label, r["blocks"], b, b, 100 * r["lum_rel_rms"],
                         100 * r["lum_rel_max"], r["n_bright"], 100 * r["noise_rel_rms"]),
                      end="")
        print("\n")
        raw[s] = {"title": title, "compare": cmp, "configs": [
            {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in c.items()
             if k not in ("ref", "ref_var")} for c in cs]}
    if a.json:
        def conv(o):
            if isinstance(o, np.ndarray):
                return o.tolist()
            if isinstance(o, np.generic):
                return o.item()
            raise TypeError(type(o))
        json.dump(raw, open(a.json, "w"), indent=1, default=conv)


if __name__ == "__main__":
    main()

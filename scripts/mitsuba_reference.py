"""Renders DIR/scene.xml (from `translucent export mitsuba`) with Mitsuba 3; see scripts/reference."""
import argparse
import json
import os
import sys
import time

import numpy as np
import mitsuba as mi


def fail(msg, code=2):
    print(f"error: {msg}", file=sys.stderr)
    sys.exit(code)


def main():
    p = argparse.ArgumentParser(prog="scripts/reference")
    p.add_argument("dir")
    p.add_argument("--spp", type=int, default=1024, help="samples per pixel per seed")
    p.add_argument("--seeds", type=int, default=2, help="independent renders (at least 2)")
    p.add_argument("--first-seed", type=int, default=0, help="the first seed (to add renders to earlier ones)")
    p.add_argument("--variant", default=None)
    p.add_argument("--max-depth", type=int, default=None)
    p.add_argument("--rr-depth", type=int, default=None)
    p.add_argument("--out", default=None)
    p.add_argument("--routes", action="store_true",
                   help="split the subsurface light by route (scripts/mitsuba_routes.py): OUT is all of it, "
                        "OUT-one-exit.exr the route translucent's models draw, OUT.json each route's mean")
    a = p.parse_args()
    scene_path = os.path.join(a.dir, "scene.xml")
    info_path = os.path.join(a.dir, "reference.json")
    if not os.path.isfile(scene_path) or not os.path.isfile(info_path):
        fail(f"{a.dir}: no scene.xml and reference.json (write them with translucent export mitsuba --out {a.dir})")
    if a.spp < 1 or a.seeds < 2:
        fail("--spp must be at least 1 and --seeds at least 2")
    info = json.load(open(info_path))
    variant = a.variant or ("llvm_ad_rgb" if os.environ.get("DRJIT_LIBLLVM_PATH") else "scalar_rgb")
    if a.routes and (a.max_depth is not None or a.rr_depth is not None):
        fail("--routes follows every path to its end: no --max-depth or --rr-depth (its -one-exit-single image is the light scattered once)")
    if a.routes and not variant.startswith("llvm"):
        fail(f"--routes needs an llvm variant (Dr.Jit's vectorised loops), not {variant}: install Debian's libllvm19")
    try:
        mi.set_variant(variant)
    except Exception as e:
        fail(f"--variant {variant}: {e}")
    if a.routes:
        sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
        import mitsuba_routes
    out = a.out or os.path.join(a.dir, "reference.exr")
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    params = {"spp": a.spp}
    if a.max_depth is not None:
        params["max_depth"] = a.max_depth
    if a.rr_depth is not None:
        params["rr_depth"] = a.rr_depth
    subtract = bool(info.get("subsurface_only"))
    if a.routes and not subtract:
        fail(f"{a.dir}: --routes splits the light through the medium, what render --no-specular draws: export with --no-specular")
    start = time.time()
    images = []
    routes = []
    for seed in range(a.first_seed, a.first_seed + a.seeds):
        scene = mi.load_file(scene_path, seed=seed, **params)
        if a.routes:
            problem = mitsuba_routes.check_scene(scene)
            if problem:
                fail(f"{scene_path}: --routes: {problem}")
            split = np.array(
                mi.render(scene, integrator=mi.load_dict({"type": "route_split"}), seed=seed, spp=a.spp), dtype=np.float64
            )
            # RGBA (the one-exit route), then the other routes (RGB each).
            others = len(mitsuba_routes.ROUTES) - 1
            per_route = [split[..., 0:3]] + [split[..., 4 + 3 * k:7 + 3 * k] for k in range(others)]
            routes.append(per_route)
            full = split[..., 0:4].copy()
            full[..., :3] = per_route[0] + per_route[1] + per_route[2]
            images.append(full)
            print(f"seed {seed}: {time.time() - start:.0f} s", file=sys.stderr, flush=True)
            continue
        full = np.array(mi.render(scene), dtype=np.float64)
        if subtract:
            refl = np.array(mi.render(mi.load_file(scene_path, seed=seed, transmittance=0.0, **params)), dtype=np.float64)
            full[..., :3] -= refl[..., :3]
        images.append(full)
        print(f"seed {seed}: {time.time() - start:.0f} s", file=sys.stderr, flush=True)
    seconds = time.time() - start
    stack = np.stack(images)
    mean = stack.mean(axis=0)
    covered = mean[..., 3] >= 0.999
    if not covered.any():
        fail(f"{scene_path}: the object covers no pixel fully", 1)
    per_seed = np.array([[img[..., c][covered].mean() for c in range(3)] for img in images])
    object_mean = per_seed.mean(axis=0)
    # Standard error of the mean of the seeds' object means, relative to it.
    noise = per_seed.std(axis=0, ddof=1) / np.sqrt(a.seeds) / np.where(object_mean != 0, object_mean, np.nan)
    if not np.isfinite(mean).all():
        fail("the render has non-finite pixels", 1)
    mi.Bitmap(mean.astype(np.float32), pixel_format=mi.Bitmap.PixelFormat.RGBA).write(out)
    route_report = None
    if a.routes:
        route_report = {}
        for k, route in enumerate(mitsuba_routes.ROUTES):
            seeds_means = np.array([[r[k][..., c][covered].mean() for c in range(3)] for r in routes])
            route_mean = seeds_means.mean(axis=0)
            with np.errstate(divide="ignore", invalid="ignore"):
                route_noise = seeds_means.std(axis=0, ddof=1) / np.sqrt(a.seeds) / route_mean
            route_report[route] = {
                "object_mean": route_mean.tolist(),
                "share_of_all": (route_mean / object_mean).tolist(),
                # None where the route carries no light (a convex object never re-enters).
                "relative_noise_of_mean": [float(v) if np.isfinite(v) else None for v in route_noise],
            }
            if route.startswith("one_exit"):
                image = mean.copy()
                image[..., :3] = np.mean([r[k] for r in routes], axis=0)
                suffix = route.replace("_", "-")
                mi.Bitmap(image.astype(np.float32), pixel_format=mi.Bitmap.PixelFormat.RGBA).write(
                    os.path.splitext(out)[0] + f"-{suffix}.exr"
                )
    report = {
        "scene": scene_path,
        "variant": variant,
        "spp_per_seed": a.spp,
        "seeds": a.seeds,
        "subtracted_reflection": subtract,
        "seconds": round(seconds, 1),
        "covered_pixels": int(covered.sum()),
        "object_mean": object_mean.tolist(),
        "relative_noise_of_mean": [None if not np.isfinite(v) else float(v) for v in noise],
        "per_seed_means": per_seed.tolist(),
        "export": info.get("command"),
    }
    if route_report:
        report["routes"] = route_report
    json.dump(report, open(os.path.splitext(out)[0] + ".json", "w"), indent=2)
    print(f"wrote {out} ({variant}, {a.seeds} seeds x {a.spp} spp, {seconds:.0f} s)")
    print("object mean R G B: " + " ".join(f"{v:.6g}" for v in object_mean))
    print("noise of the mean (standard error / mean) R G B: " + " ".join(f"{100 * v:.3f}%" for v in noise))
    for route, numbers in (route_report or {}).items():
        print(f"route {route}: mean " + " ".join(f"{v:.6g}" for v in numbers["object_mean"])
              + ", share " + " ".join(f"{v:.4f}" for v in numbers["share_of_all"]))


if __name__ == "__main__":
    main()

"""Path-traced exit profile of a homogeneous sphere under a narrow beam (see scripts/sphere-reference)."""
import argparse
import json
import math
import os
import sys
import tempfile
import time

import numpy as np
import mitsuba as mi

# Jensen et al. 2001 (src/materials.rs): sigma_s' (= sigma_s, g = 0), sigma_a per mm, eta.
MATERIALS = {
    "skin1": ([0.74, 0.88, 1.01], [0.032, 0.17, 0.48], 1.3),
    "ketchup": ([0.18, 0.07, 0.03], [0.061, 0.97, 1.45], 1.3),
    "marble": ([2.19, 2.62, 3.00], [0.0021, 0.0041, 0.0071], 1.5),
    "potato": ([0.68, 0.70, 0.55], [0.0024, 0.0090, 0.12], 1.3),
}


def screen_obj(path, hole, outer, height, segments=512):
    """A black annulus at z = height: the beam's aperture. Vertices alternate inner, outer."""
    with open(path, "w") as f:
        for k in range(segments):
            a = 2 * math.pi * k / segments
            f.write(f"v {hole * math.cos(a)} {hole * math.sin(a)} {height}\n")
            f.write(f"v {outer * math.cos(a)} {outer * math.sin(a)} {height}\n")
        for k in range(segments):
            i0, o0 = 2 * k + 1, 2 * k + 2
            i1, o1 = 2 * ((k + 1) % segments) + 1, 2 * ((k + 1) % segments) + 2
            f.write(f"f {i0} {o0} {o1}\nf {i0} {o1} {i1}\n")


def scene(a, screen_path, seed, transmittance):
    T = mi.ScalarTransform4f
    sigma_s, sigma_a, eta = MATERIALS[a.material]
    sigma_t = [s + k for s, k in zip(sigma_s, sigma_a)]
    scale = max(sigma_t)
    R, H, delta = a.radius, a.height, math.radians(a.cone)
    D = 1000.0 * R
    return {
        "type": "scene",
        "integrator": {"type": "volpathmis", "max_depth": -1, "rr_depth": 1 << 30},
        "sensor": {
            "type": "orthographic",
            "near_clip": 1e-4,
            "far_clip": 4.0 * R + H,
            "to_world": T().look_at(origin=[0, 0, H / 2], target=[0, 0, -1], up=[0, 1, 0]) @ T().scale([a.extent, a.extent, 1]),
            "film": {"type": "hdrfilm", "width": a.pixels, "height": a.pixels, "pixel_format": "rgb", "rfilter": {"type": "box"}},
            "sampler": {"type": "independent", "sample_count": a.spp, "seed": seed},
        },
        "sphere": {
            "type": "sphere",
            "center": [0, 0, -R],
            "radius": R,
            "bsdf": {"type": "dielectric", "int_ior": eta, "ext_ior": 1.0, "specular_transmittance": transmittance},
            "interior": {
                "type": "homogeneous",
                "sigma_t": {"type": "rgb", "value": [v / scale for v in sigma_t]},
                "scale": scale,
                "albedo": {"type": "rgb", "value": [s / t for s, t in zip(sigma_s, sigma_t)]},
                "phase": {"type": "isotropic"},
            },
        },
        "screen": {"type": "obj", "filename": screen_path, "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": 0.0}}},
        # A far disk of angular radius delta facing -z, radiance 1/(pi sin^2 delta): irradiance 1.
        "light": {
            "type": "disk",
            "to_world": T().translate([0, 0, D]) @ T().rotate([1, 0, 0], 180) @ T().scale([D * math.tan(delta), D * math.tan(delta), 1]),
            "emitter": {"type": "area", "radiance": {"type": "rgb", "value": 1.0 / (math.pi * math.sin(delta) ** 2)}},
        },
    }


def main():
    p = argparse.ArgumentParser(prog="scripts/sphere-reference")
    p.add_argument("material", choices=sorted(MATERIALS))
    p.add_argument("--radius", type=float, required=True, help="mm")
    p.add_argument("--hole", type=float, default=0.5, help="aperture radius, mm")
    p.add_argument("--height", type=float, default=0.2, help="screen above the pole, mm")
    p.add_argument("--cone", type=float, default=30.0, help="light's angular radius, degrees")
    p.add_argument("--extent", type=float, default=None, help="half width of the view, mm (default R)")
    p.add_argument("--pixels", type=int, default=128)
    p.add_argument("--spp", type=int, default=256)
    p.add_argument("--seeds", type=int, default=4)
    p.add_argument("--out", required=True, help="JSON file")
    a = p.parse_args()
    a.extent = a.extent or a.radius
    mi.set_variant("llvm_ad_rgb" if os.environ.get("DRJIT_LIBLLVM_PATH") else "scalar_rgb")
    tmp = tempfile.mkdtemp()
    screen_path = os.path.join(tmp, "screen.obj")
    screen_obj(screen_path, a.hole, 4.0 * a.radius, a.height)
    # Rings of image radius (mm) by pixel centre: one pixel's width, then x1.5.
    pix = 2 * a.extent / a.pixels
    c = (np.arange(a.pixels) + 0.5) * pix - a.extent
    rho = np.hypot(c[None, :], c[:, None])
    edges = [0.0, 2 * pix]
    while edges[-1] * 1.5 < a.extent:
        edges.append(edges[-1] * 1.5)
    edges.append(a.extent)
    ring = np.digitize(rho, edges) - 1
    start = time.time()
    per_seed = []
    for seed in range(a.seeds):
        full = np.array(mi.render(mi.load_dict(scene(a, screen_path, seed, 1.0))), dtype=np.float64)
        refl = np.array(mi.render(mi.load_dict(scene(a, screen_path, seed, 0.0))), dtype=np.float64)
        img = full[..., :3] - refl[..., :3]
        per_seed.append([[float(img[..., ch][ring == k].mean()) for k in range(len(edges) - 1)] for ch in range(3)])
        print(f"seed {seed}: {time.time() - start:.0f} s", file=sys.stderr, flush=True)
    s = np.array(per_seed)  # seed, channel, ring
    mean = s.mean(axis=0)
    err = s.std(axis=0, ddof=1) / math.sqrt(a.seeds)
    sigma_s, sigma_a, eta = MATERIALS[a.material]
    report = {
        "material": a.material,
        "sigma_s_per_mm": sigma_s,
        "sigma_a_per_mm": sigma_a,
        "eta": eta,
        "radius_mm": a.radius,
        "hole_mm": a.hole,
        "height_mm": a.height,
        "cone_deg": a.cone,
        "extent_mm": a.extent,
        "pixels": a.pixels,
        "spp_per_seed": a.spp,
        "seeds": a.seeds,
        "variant": mi.variant(),
        "mitsuba": mi.__version__,
        "seconds": round(time.time() - start, 1),
        "ring_edges_mm": edges,
        "ring_pixels": [int((ring == k).sum()) for k in range(len(edges) - 1)],
        "radiance": mean.tolist(),
        "standard_error": err.tolist(),
        "command": "scripts/sphere-reference " + " ".join(sys.argv[1:]),
    }
    os.makedirs(os.path.dirname(os.path.abspath(a.out)), exist_ok=True)
    json.dump(report, open(a.out, "w"), indent=1)
    for ch in range(3):
        print(f"channel {ch}: " + " ".join(f"{m:.3g}({100 * e / m if m else 0:.0f}%)" for m, e in zip(mean[ch], err[ch])))


if __name__ == "__main__":
    main()

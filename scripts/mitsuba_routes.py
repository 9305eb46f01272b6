"""A volumetric path tracer that splits the light through a translucent object by its route
(scripts/reference --routes).

Every model translucent draws carries light along one route: in at the pixel's point, through
the medium (internal reflections included), out once and straight to a light. A path-traced
object that is not convex also gets light along others, which no BSSRDF under direct light
can: light that leaves the object and enters it again (or reflects off it) before it reaches a
light, and, with `--no-specular`, the object's own subsurface light seen in the boundary's
reflection at the pixel. This integrator counts each route apart:

- `one_exit`: the first surface event at the pixel is a transmission, the next event outside the
  medium is the light;
- `reenters`: the path went through the medium but left it and met the object again;
- `seen_in_reflection`: the pixel's first event is a reflection and the path entered the medium
  later;
- `one_exit_single`: the one-exit route's light scattered once, internal reflections included;
- `one_exit_single_direct`: the same without any internal reflection, the light a single-scattering
  term draws (straight in along the refracted view ray, straight out toward the light). On a thin
  back-lit lens 12 / 10 / 8% of the light scattered once had reflected inside: light entering its
  rim, guided along the sheet by total internal reflection.

Their sum is the subsurface light `volpathmis` less the boundary's reflection gives (checked on
the default Skin1 bunny: within 0.2 / 0.05 / 0.8% of it, the path tracer's noise). The
estimator is volpathmis's for these scenes: each path's free flights drawn in one channel and
weighted by the balance heuristic over the channels (spectral MIS); lights behind a smooth boundary
are found by chance (no light sampling: none can be connected through a smooth dielectric).
Russian roulette starts after 64 scatterings once the throughput is under 1/8 (unbiased, and gentle:
Marble's walks are hundreds of scatterings long and a fixed survival rate would weight them 1e5; Mitsuba's own roulette
darkened Marble's slabs, scripts/mitsuba_reference.py).
"""
import drjit as dr
import mitsuba as mi

# Output channels after RGBA: one_exit is the image itself (RGB); AOVs hold the others.
ROUTES = ["one_exit", "reenters", "seen_in_reflection", "one_exit_single", "one_exit_single_direct"]
ROULETTE_AFTER = 64


def in_channel(spectrum, channel):
    """spectrum[channel] per lane."""
    value = mi.Float(spectrum[0])
    value[channel == 1] = spectrum[1]
    value[channel == 2] = spectrum[2]
    return value


class RouteSplit(mi.SamplingIntegrator):
    def aov_names(self):
        return [f"{route}.{c}" for route in ROUTES[1:] for c in "RGB"]

    @dr.syntax
    def sample(self, scene, sampler, ray, medium=None, active=True, aovs=None):
        ray = mi.Ray3f(ray)
        active = mi.Bool(active)
        first = scene.ray_intersect(ray, active)
        covered = first.is_valid() & (first.emitter(scene, active) == None)
        throughput = mi.Spectrum(1.0)
        one_exit = mi.Spectrum(0.0)
        one_exit_single = mi.Spectrum(0.0)
        one_exit_single_direct = mi.Spectrum(0.0)
        reenters = mi.Spectrum(0.0)
        seen_in_reflection = mi.Spectrum(0.0)
        medium = dr.zeros(mi.MediumPtr)
        transmissions = mi.UInt32(0)
        # Surface events of the route: events outside the medium and exits; an internal
        # reflection belongs to the medium's walk, as in a BSSRDF.
        route_events = mi.UInt32(0)
        reflected_first = mi.Bool(False)
        scatterings = mi.UInt32(0)
        internal_reflections = mi.UInt32(0)
        # Spectral MIS over the path (volpathmis'): every free flight of a path is drawn in its
        # hero channel h, and the estimate is f / mean_c(p_c) with p_c the path's density had
        # channel c drawn them. `throughput` is f / p_h and `density` p_c / p_h (1 in h), so the
        # weight throughput / mean(density) is at most 3 × the albedo's power: bounded however
        # long the walk, where a channel drawn afresh per flight multiplies per-flight weights
        # and Marble's walks of hundreds of flights came out with fireflies (5.6% noise in blue).
        channels = dr.size_v(mi.Spectrum)
        hero = mi.UInt32(dr.minimum(channels * sampler.next_1d(active), channels - 1))
        density = mi.Spectrum(1.0)
        while dr.hint(active, label="route split"):
            si = scene.ray_intersect(ray, active)
            inside = active & (medium != None)
            mei = medium.sample_interaction(ray, sampler.next_1d(inside), hero, inside)
            scatter = inside & mei.is_valid() & (mei.t < si.t)
            mei.t[inside & ~scatter] = dr.inf
            transmittance, pdf = medium.transmittance_eval_pdf(mei, si, inside)
            hero_pdf = in_channel(pdf, hero)
            throughput[inside] *= dr.select(hero_pdf > 0, transmittance / hero_pdf, 0.0)
            density[inside] *= dr.select(hero_pdf > 0, pdf / hero_pdf, 0.0)
            throughput[scatter] *= mei.sigma_s
            scatterings[scatter] += 1
            roulette = scatter & (scatterings > ROULETTE_AFTER)
            keep = dr.minimum(dr.max(throughput) / dr.mean(density) * 8.0, 1.0)
            survives = sampler.next_1d(roulette) < keep
            throughput[roulette] = dr.select(survives, throughput / keep, 0.0)
            phase = mei.medium.phase_function()
            wo, phase_weight, _ = phase.sample(
                mi.PhaseFunctionContext(sampler), mei, sampler.next_1d(scatter), sampler.next_2d(scatter), scatter
            )
            throughput[scatter] *= phase_weight
            ray[scatter] = mei.spawn_ray(wo)

            at_surface = active & ~scatter
            emitter = si.emitter(scene, at_surface)
            reaches_light = at_surface & si.is_valid() & (emitter != None)
            emitted = throughput / dr.mean(density) * emitter.eval(si, reaches_light)
            is_one_exit = (transmissions == 2) & (route_events == 2) & ~reflected_first
            through_medium = transmissions > 0
            one_exit[reaches_light & is_one_exit] += emitted
            one_exit_single[reaches_light & is_one_exit & (scatterings == 1)] += emitted
            one_exit_single_direct[reaches_light & is_one_exit & (scatterings == 1) & (internal_reflections == 0)] += emitted
            reenters[reaches_light & through_medium & ~is_one_exit & ~reflected_first] += emitted
            seen_in_reflection[reaches_light & through_medium & reflected_first] += emitted

            on_object = at_surface & si.is_valid() & (emitter == None)
            bsdf = si.bsdf(ray)
            bs, bsdf_weight = bsdf.sample(
                mi.BSDFContext(), si, sampler.next_1d(on_object), sampler.next_2d(on_object), on_object
            )
            on_object &= bs.pdf > 0
            transmitted = mi.has_flag(bs.sampled_type, mi.BSDFFlags.Transmission)
            reflected_first[on_object & (route_events == 0) & ~transmitted] = True
            internal_reflections[on_object & ~transmitted & (medium != None)] += 1
            transmissions[on_object & transmitted] += 1
            route_events[on_object & (transmitted | (medium == None))] += 1
            throughput[on_object] *= bsdf_weight
            direction = si.to_world(bs.wo)
            ray[on_object] = si.spawn_ray(direction)
            medium[on_object] = si.target_medium(direction)
            active = (on_object | scatter) & (dr.max(throughput) > 0)
        others = [reenters, seen_in_reflection, one_exit_single, one_exit_single_direct]
        return one_exit, covered, [route[c] for route in others for c in range(3)]


def check_scene(scene):
    """Refuses scenes this integrator would render wrong: it finds lights only by hitting them
    (delta lights never) and follows only dielectric boundaries."""
    if any(mi.has_flag(e.flags(), mi.EmitterFlags.Delta) for e in scene.emitters()):
        return "a delta light (point, spot or directional emitter) cannot be hit by a path"
    for shape in scene.shapes():
        if shape.emitter() is not None:
            continue
        bsdf = shape.bsdf()
        if bsdf is None or "dielectric" not in str(bsdf).lower().split("[")[0]:
            return f"shape {shape.id()} is not a smooth dielectric (--routes splits translucent objects only)"
    return None


mi.register_integrator("route_split", lambda props: RouteSplit(props))

// A colour over a mesh's uv (world::Reflectance on the GPU), the same in the surface pass and the
// sampling pass: `kind` 0: `tex1` everywhere; 1: pbrt-v4's 2D checkerboard, tex1.rgb where
// floor(u·uscale) + floor(v·vscale) is even, tex2.rgb where odd (uscale = tex1.w, vscale =
// tex2.w); 2: the image `map`, v running up it as pbrt-v4 reads it, repeated, filtered linearly.
// Opaque objects hold their Lambertian reflectance in it; translucent ones their scatter weight
// (gpu_world::SurfaceTexture: the square root of the texture's reflectance over the material's).
#ifndef SURFACE_TEXTURE_GLSL
#define SURFACE_TEXTURE_GLSL
const uint TEXTURE_CONSTANT = 0u;
const uint TEXTURE_CHECKERBOARD = 1u;
const uint TEXTURE_IMAGE = 2u;

vec3 surface_texture(uint kind, vec4 tex1, vec4 tex2, sampler2D map, vec2 uv) {
    if (kind == TEXTURE_IMAGE) return textureLod(map, vec2(uv.x, 1.0 - uv.y), 0.0).rgb;
    if (kind == TEXTURE_CHECKERBOARD) {
        int parity = int(floor(uv.x * tex1.w)) + int(floor(uv.y * tex2.w));
        if ((parity & 1) != 0) return tex2.rgb;
    }
    return tex1.rgb;
}
#endif

#version 460
// For tests/reflection.rs only: one binding of each kind a pipeline layout takes, with and
// without `readonly`, and a push-constant block whose std430 size (48) exceeds its last member's
// end (36).
layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Inputs { uint values[]; } inputs;
layout(std430, binding = 1) buffer Outputs { uint results[]; };
layout(std140, binding = 2) uniform Params { uint scale; } params;
layout(binding = 3) uniform sampler2D tex;
layout(binding = 4, rgba8) uniform readonly image2D src_image;
layout(binding = 5, rgba8) uniform writeonly image2D dst_image;
layout(push_constant) uniform Constants { vec4 offset; vec4 unused; uint count; } pc;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i < pc.count) {
        results[i] = inputs.values[i] * params.scale + i;
    }
    if (i == 0u) {
        vec4 texel = texelFetch(tex, ivec2(0), 0) + imageLoad(src_image, ivec2(0));
        imageStore(dst_image, ivec2(0), texel * pc.offset + pc.unused);
    }
}

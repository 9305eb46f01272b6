#version 460
// Tone mapping, the GPU twin of src/output.rs (`auto_exposure_scale`, `tonemap`), in three stages
// chosen by the push constant `stage`:
//   0: histogram of log2 luminance of covered pixels (per work group in shared memory, then added
//      to the global one);
//   1: one invocation walks the bins to the 95th-percentile rank and writes the exposure scale;
//   2: exposure → filmic → sRGB → RGBA8, one uint per pixel (R in the low byte), alpha = coverage.
// Binning and the scale use only bit operations, comparisons with tables computed in Rust and
// multiplications by powers of two, so they are exact and the CPU gets the same scale.
layout(local_size_x = 16, local_size_y = 16) in;

layout(binding = 0, rgba32f) uniform readonly image2D hdr;
// Mirrors `HistogramTables` in src/gpu/passes.rs (checked by tests/layouts.rs).
// A uniform buffer: llvmpipe loads its members once per SIMD group, storage buffers lane by lane.
// std140 keeps float[16] at a 16-byte stride, so the tables are 4 vec4s each (the bytes of
// float[16] in std430).
layout(std140, binding = 1) uniform HistogramTables {
    vec4 thresholds[4];   // lower bin edges within a stop, 2^(j/16)
    vec4 inv_centres[4];  // 2^(-(j+0.5)/16)
    int log2_min;
    uint bin_count;
} tables;
const int BINS_PER_STOP = 16;
float threshold(int j) { return tables.thresholds[j >> 2][j & 3]; }
float inv_centre(uint j) { return tables.inv_centres[j >> 2][j & 3u]; }
// Cleared by the pass before stage 0.
layout(std430, binding = 2) buffer Histogram {
    float scale;
    uint count;
    uint pad0;
    uint pad1;
    uint bins[];
} hist;
layout(std430, binding = 3) buffer Ldr { uint ldr[]; };
layout(push_constant) uniform TonemapConstants {
    uint stage;
    uint width;
    uint height;
    uint fixed_exposure;  // 1: use fixed_scale; 0: the scale of stage 1
    float fixed_scale;
} pc;

// Capacity, not the bin count: with more bins than this, stage 0 adds to the global histogram directly.
const uint SHARED_BINS = 1024u;
shared uint local_bins[SHARED_BINS];

bool is_nan(float v) { return (floatBitsToUint(v) & 0x7fffffffu) > 0x7f800000u; }

// -1 when the pixel does not count: uncovered, or luminance not finite, ≤ 0 or subnormal.
int luminance_bin(vec4 p) {
    // `precise`: no fused multiply-add, so the sum rounds as in Rust.
    precise float l = 0.2126 * p.r + 0.7152 * p.g + 0.0722 * p.b;
    uint bits = floatBitsToUint(l);
    if (!(p.a > 0.0) || bits < 0x00800000u || bits >= 0x7f800000u) return -1;
    int stop = int(bits >> 23) - 127 - tables.log2_min;
    if (stop < 0) return 0;
    float mantissa = uintBitsToFloat((bits & 0x007fffffu) | 0x3f800000u);
    int within = 0;
    for (int j = 1; j < BINS_PER_STOP; ++j) within += mantissa >= threshold(j) ? 1 : 0;
    return min(stop * BINS_PER_STOP + within, int(tables.bin_count) - 1);
}

float bin_scale(uint bin) {
    uint per_stop = uint(BINS_PER_STOP);
    int stop = tables.log2_min + int(bin / per_stop);
    precise float s = inv_centre(bin % per_stop) * uintBitsToFloat(uint(127 - stop) << 23);
    return s;
}

void histogram() {
    bool shared_bins = tables.bin_count <= SHARED_BINS;
    uint threads = gl_WorkGroupSize.x * gl_WorkGroupSize.y;
    if (shared_bins) {
        for (uint b = gl_LocalInvocationIndex; b < tables.bin_count; b += threads) local_bins[b] = 0u;
    }
    memoryBarrierShared();
    barrier();
    uvec2 p = gl_GlobalInvocationID.xy;
    if (p.x < pc.width && p.y < pc.height) {
        int bin = luminance_bin(imageLoad(hdr, ivec2(p)));
        if (bin >= 0) {
            if (shared_bins) atomicAdd(local_bins[bin], 1u);
            else atomicAdd(hist.bins[bin], 1u);
        }
    }
    memoryBarrierShared();
    barrier();
    if (shared_bins) {
        for (uint b = gl_LocalInvocationIndex; b < tables.bin_count; b += threads) {
            if (local_bins[b] != 0u) atomicAdd(hist.bins[b], local_bins[b]);
        }
    }
}

void percentile() {
    if (gl_LocalInvocationIndex != 0u) return;
    uint total = 0u;
    for (uint b = 0u; b < tables.bin_count; ++b) total += hist.bins[b];
    float scale = 1.0;
    if (total > 0u) {
        precise float r = float(total - 1u) * 0.95;
        uint rank = uint(r);
        uint seen = 0u;
        uint bin = tables.bin_count - 1u;
        for (uint b = 0u; b < tables.bin_count; ++b) {
            seen += hist.bins[b];
            if (seen > rank) {
                bin = b;
                break;
            }
        }
        scale = bin_scale(bin);
    }
    hist.scale = scale;
    hist.count = total;
}

float filmic(float x) {
    // Capped like FILMIC_INPUT_MAX in output.rs: +inf stays white instead of inf/inf.
    x = min(max(x, 0.0), 64.0);
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

float srgb_encode(float linear) {
    float c = clamp(linear, 0.0, 1.0);
    return c <= 0.0031308 ? 12.92 * c : 1.055 * pow(c, 1.0 / 2.4) - 0.055;
}

uint to8(float v, float scale) {
    precise float x = is_nan(v) ? 0.0 : v * scale;
    precise float q = srgb_encode(filmic(x)) * 255.0 + 0.5;
    return uint(q);
}

void map() {
    uvec2 p = gl_GlobalInvocationID.xy;
    if (p.x >= pc.width || p.y >= pc.height) return;
    vec4 c = imageLoad(hdr, ivec2(p));
    float scale = pc.fixed_exposure != 0u ? pc.fixed_scale : hist.scale;
    precise float a = clamp(is_nan(c.a) ? 0.0 : c.a, 0.0, 1.0) * 255.0 + 0.5;
    ldr[p.y * pc.width + p.x] = to8(c.r, scale) | (to8(c.g, scale) << 8) | (to8(c.b, scale) << 16) | (uint(a) << 24);
}

void main() {
    if (pc.stage == 0u) histogram();
    else if (pc.stage == 1u) percentile();
    else map();
}

// The displacement texture's height (displacement.py): bilinear between texel centres,
// clamped at the border (core:include/heightfield.glsl) or wrapped for tiled periodic
// textures; exact interpolation with texelFetch, so the alpha test is the CPU's.
#include "core:include/heightfield.glsl"
uniform bool u_wrap;

float disp_texel_wrapped(int i, int j) {
    ivec2 n = u_hf_size;
    ivec2 k = ivec2(i, j) - n * ivec2(floor(vec2(i, j) / vec2(n)));
    return texelFetch(u_height, clamp(k, ivec2(0), n - 1), 0).r;
}

// Height at texture coordinates st (tiled uv): texel coordinates p = st * (W, H).
float disp_height(vec2 st) {
    vec2 p = st * vec2(u_hf_size);
    if (!u_wrap) return hf_height(p);
    vec2 q = p - 0.5;
    vec2 c = floor(q);
    vec2 f = q - c;
    int i = int(c.x), j = int(c.y);
    float h00 = disp_texel_wrapped(i, j), h10 = disp_texel_wrapped(i + 1, j);
    float h01 = disp_texel_wrapped(i, j + 1), h11 = disp_texel_wrapped(i + 1, j + 1);
    return mix(mix(h00, h10, f.x), mix(h01, h11, f.x), f.y);
}

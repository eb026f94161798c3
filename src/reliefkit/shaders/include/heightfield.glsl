// A heightfield in texel coordinates: texel (i, j) holds the height at (i + 0.5, j + 0.5);
// bilinear between texel centres, clamped at the border (reference/heightfield.py).
uniform sampler2D u_height;   // R32F, sampled with texelFetch only (exact interpolation)
uniform ivec2 u_hf_size;      // (W, H)

float hf_texel(int i, int j) {
    return texelFetch(u_height, clamp(ivec2(i, j), ivec2(0), u_hf_size - 1), 0).r;
}

// The heights (h00, h10, h01, h11) of the texels lo..hi (corners of one bilinear cell).
vec4 hf_corners(ivec2 lo, ivec2 hi) {
    return vec4(hf_texel(lo.x, lo.y), hf_texel(hi.x, lo.y), hf_texel(lo.x, hi.y),
                hf_texel(hi.x, hi.y));
}

// The texels lo..hi whose bilinear mix is the height at texel coordinates p (clamped at the
// border) and the fractions f between them.
void hf_point_cell(vec2 p, out ivec2 lo, out ivec2 hi, out vec2 f) {
    vec2 q = clamp(p, vec2(0.5), vec2(u_hf_size) - 0.5) - 0.5;
    vec2 c = floor(q);
    f = q - c;
    lo = ivec2(c);
    hi = min(lo + 1, u_hf_size - 1);
}

// The bilinear mix of corner heights h (hf_corners) at fractions f.
float hf_mix(vec4 h, vec2 f) {
    return mix(mix(h.x, h.y, f.x), mix(h.z, h.w, f.x), f.y);
}

// Bilinear height at texel coordinates p (x = u * W, y = v * H).
float hf_height(vec2 p) {
    ivec2 lo, hi;
    vec2 f;
    hf_point_cell(p, lo, hi, f);
    return hf_mix(hf_corners(lo, hi), f);
}

// The bilinear surface's slope (dh/dx, dh/dy) per texel at texel coordinates p; flat where
// the border clamps it.
vec2 hf_slope(vec2 p) {
    ivec2 lo, hi;
    vec2 f;
    hf_point_cell(p, lo, hi, f);
    vec4 h = hf_corners(lo, hi);
    vec2 slope = vec2(mix(h.y - h.x, h.w - h.z, f.y), mix(h.z - h.x, h.w - h.y, f.x));
    bvec2 inside = bvec2(p.x > 0.5 && p.x < float(u_hf_size.x) - 0.5,
                         p.y > 0.5 && p.y < float(u_hf_size.y) - 0.5);
    return mix(vec2(0.0), slope, inside);
}

// Signed height of a ray point above the surface; negative means inside the solid.
// Height 0 is empty space: the box's bottom face is no surface, so a ray reaching it misses.
float hf_above(vec3 p) {
    float s = hf_height(p.xy);
    return s > 0.0 ? p.z - s : max(p.z, 1e-7);
}

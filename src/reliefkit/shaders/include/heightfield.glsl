// A heightfield in texel coordinates: texel (i, j) holds the height at (i + 0.5, j + 0.5);
// bilinear between texel centres, clamped at the border (represent/relief.py).
uniform sampler2D u_height;   // R32F, sampled with texelFetch only (exact interpolation)
uniform ivec2 u_hf_size;      // (W, H)

float hf_texel(int i, int j) {
    return texelFetch(u_height, clamp(ivec2(i, j), ivec2(0), u_hf_size - 1), 0).r;
}

// Bilinear height at texel coordinates p (x = u * W, y = v * H).
float hf_height(vec2 p) {
    vec2 q = clamp(p, vec2(0.5), vec2(u_hf_size) - 0.5) - 0.5;
    vec2 c = floor(q);
    vec2 f = q - c;
    int i = int(c.x), j = int(c.y);
    float h00 = hf_texel(i, j), h10 = hf_texel(i + 1, j);
    float h01 = hf_texel(i, j + 1), h11 = hf_texel(i + 1, j + 1);
    return mix(mix(h00, h10, f.x), mix(h01, h11, f.x), f.y);
}

// Signed height of a ray point above the surface; negative means inside the solid.
// Height 0 is empty space: the box's bottom face is no surface (represent/relief.py).
float hf_above(vec3 p) {
    float s = hf_height(p.xy);
    return s > 0.0 ? p.z - s : max(p.z, 1e-7);
}

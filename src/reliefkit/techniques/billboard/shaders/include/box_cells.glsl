// The cells of one billboard box (techniques/billboard/boxes.py): voxel (i, j, k) is
// [i, i+1] x [j, j+1] x [k, k+1] in voxel coordinates (box coordinates times u_res), every
// lookup a texelFetch of the cell (nearest, no filtering), so the occupied set is a union of
// cells (VOLUMETRIC) or of per-texel intervals in w (SHELL, THICK_SHELL).
uniform ivec3 u_res;            // (W, H, D) voxels
uniform sampler3D u_distance;   // (D, H, W) uint8: centre to nearest occupied centre (box_bake.py)
uniform float u_distance_scale;   // stored distance -> voxel coordinates (box_render.py) ...
uniform float u_distance_margin;  // ... minus this: a safe step

#if defined VOLUMETRIC
uniform sampler3D u_color;      // RGBA8 sRGB, decoded below (moderngl has no sRGB 3D format)
uniform sampler3D u_normal;     // (n + 1) / 2
#else
uniform sampler2D u_color;      // SRGB8_ALPHA8: the sampler decodes
uniform sampler2D u_normal;     // (n + 1) / 2
uniform usampler2D u_displacement;  // R16UI (shell: surface w) or RG16UI (thick shell: lo, hi)
uniform float u_half_thickness;     // shell: half the interval width in w
#endif

// The cell containing voxel-space point p; a point on a face belongs to the cell the ray
// (direction d) enters there, so a march never tests the cell it is just leaving.
ivec3 cell_at(vec3 p, vec3 d) {
    vec3 c = mix(floor(p), ceil(p) - 1.0, lessThan(d, vec3(0.0)));
    return clamp(ivec3(c), ivec3(0), u_res - 1);
}

bool inside_grid(ivec3 c) {
    return all(greaterThanEqual(c, ivec3(0))) && all(lessThan(c, u_res));
}

// Ray parameter where o + s d (voxel coordinates) leaves cell c, and the axis it leaves
// through; axes with d == 0 never end the cell. `axes` masks the axes that count (the
// shells' columns ignore z).
float cell_exit(ivec3 c, vec3 o, vec3 d, bvec3 axes, out int axis) {
    vec3 bound = vec3(c) + step(0.0, d);  // the face ahead along each axis
    vec3 t = vec3(1e30);
    for (int k = 0; k < 3; ++k) {
        if (axes[k] && d[k] != 0.0) t[k] = (bound[k] - o[k]) / d[k];
    }
    axis = t.x <= t.y ? (t.x <= t.z ? 0 : 2) : (t.y <= t.z ? 1 : 2);
    return t[axis];
}

// The neighbour of c across its face on `axis` in the direction of travel.
ivec3 next_cell(ivec3 c, int axis, vec3 d) {
    ivec3 e = ivec3(equal(ivec3(axis), ivec3(0, 1, 2)));
    return c + e * ivec3(sign(d));
}

// Sphere tracing's safe step (voxel coordinates) from anywhere in cell c, 0 where there is
// none: no occupied point lies closer (box_render.py's docstring).
float safe_step(ivec3 c) {
    float stored = floor(texelFetch(u_distance, c, 0).r * 255.0 + 0.5);
    return max(stored * u_distance_scale - u_distance_margin, 0.0);
}

vec3 decode_normal(vec3 t) {
    return normalize(2.0 * t - 1.0);
}

#if defined VOLUMETRIC
bool occupied(ivec3 c) {
    return texelFetch(u_color, c, 0).a >= 0.5;  // alpha >= 128 of 255
}

vec3 srgb_to_linear(vec3 c) {
    return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), greaterThan(c, vec3(0.04045)));
}

vec4 cell_color(ivec3 c) {
    vec4 t = texelFetch(u_color, c, 0);
    return vec4(srgb_to_linear(t.rgb), t.a);
}

vec3 cell_normal(ivec3 c) {
    return decode_normal(texelFetch(u_normal, c, 0).rgb);
}
#else
// The texel's occupied interval in w; empty (lo > hi) where its alpha is below 128.
vec2 texel_interval(ivec2 texel) {
    if (texelFetch(u_color, texel, 0).a < 0.5) return vec2(2.0, -1.0);
    uvec4 disp = texelFetch(u_displacement, texel, 0);
#if defined SHELL
    float w = float(disp.r) / 65535.0;
    return vec2(w - u_half_thickness, w + u_half_thickness);
#else
    return vec2(float(disp.r), float(disp.g)) / 65535.0;
#endif
}

// The first s in [s0, s1] where w0 + s dw lies in the interval; -1 if there is none.
float first_in_interval(float w0, float dw, float s0, float s1, vec2 interval) {
    if (interval.x > interval.y || s1 < s0) return -1.0;
    if (dw == 0.0) return (w0 >= interval.x && w0 <= interval.y) ? s0 : -1.0;
    float ta = (interval.x - w0) / dw, tb = (interval.y - w0) / dw;
    float lo = max(s0, min(ta, tb)), hi = min(s1, max(ta, tb));
    return lo <= hi ? lo : -1.0;
}

vec4 cell_color(ivec3 c) {
    return texelFetch(u_color, c.xy, 0);
}

vec3 cell_normal(ivec3 c) {
    return decode_normal(texelFetch(u_normal, c.xy, 0).rgb);
}
#endif

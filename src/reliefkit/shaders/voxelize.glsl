// Voxelization: rasterize a mesh through one slab of a box and accumulate, per pixel (one
// axis-parallel sample line through the box), what the surface leaves inside the slab.
// Every output is summed by additive blending (ONE, ONE), so several surface crossings of
// one line inside the slab add up; bake/voxelize.py reduces the lines to voxels.
//! defines: HAS_TEXTURE WINDING

#if defined VERTEX_SHADER
uniform mat4 u_box_to_slab;    // box (u, v, h) -> the sweep's (x', y', z'), z' = slab axis
uniform vec2 u_clip_z;         // the z' range mapped to clip z in [-1, 1] (the slab + margin)
uniform mat3 u_uv_transform;   // the material's affine map of (u, v, 1)
in vec3 in_box;                // vertex position in box coordinates (not world)
in vec3 in_normal;             // world-space normal
in vec4 in_color;
in vec2 in_uv;
out vec3 v_box;
out vec3 v_normal;
out vec4 v_color;
out vec2 v_uv;

void main() {
    vec3 b = (u_box_to_slab * vec4(in_box, 1.0)).xyz;
    v_box = b;
    v_normal = in_normal;
    v_color = in_color;
    v_uv = (u_uv_transform * vec3(in_uv, 1.0)).xy;
    // orthographic along z': x' and y' in [0, 1] fill the viewport; clipping keeps the slab
    float z = 2.0 * (b.z - u_clip_z.x) / (u_clip_z.y - u_clip_z.x) - 1.0;
    gl_Position = vec4(2.0 * b.x - 1.0, 2.0 * b.y - 1.0, z, 1.0);
}
#endif

#if defined FRAGMENT_SHADER
uniform vec2 u_slab;           // keep crossings with u_slab.x <= z' < u_slab.y (half open)
uniform float u_hole_alpha;    // base alpha <= this is a hole (cut-out leaves), not surface
uniform int u_alpha_mode;      // the material's: 0 OPAQUE, 1 MASK, 2 BLEND (as mesh.glsl)
uniform float u_alpha_cutoff;  // the material's MASK threshold
uniform vec4 u_base_color;     // the material's linear colour factor
#if defined HAS_TEXTURE
uniform sampler2D u_texture;   // sRGB texture: sampling returns linear colour
#endif
#if defined WINDING
uniform bool u_signed;         // true: +1/-1 by facing (nonzero rule); false: +1 (parity)
uniform vec4 u_threshold_a;    // channel c counts crossings with z' >= threshold c
uniform vec4 u_threshold_b;
#endif
in vec3 v_box;
in vec3 v_normal;
in vec4 v_color;
in vec2 v_uv;
layout(location = 0) out vec4 f_color;   // (rgb * alpha, alpha): premultiplied colour sum
layout(location = 1) out vec4 f_normal;  // (world unit normal sum, number of crossings)
#if defined WINDING
layout(location = 2) out vec4 f_count_a; // crossing counts above the thresholds (channels 0-3)
layout(location = 3) out vec4 f_count_b; // channels 4-7
#endif

void main() {
    if (v_box.z < u_slab.x || v_box.z >= u_slab.y) discard;  // each crossing in one slab
    vec4 base = v_color * u_base_color;
#if defined HAS_TEXTURE
    base *= texture(u_texture, v_uv);
#endif
    if (u_alpha_mode == 1) base.a = base.a < u_alpha_cutoff ? 0.0 : 1.0;
    else if (u_alpha_mode == 0) base.a = 1.0;
    float len = length(v_normal);
    if (base.a > u_hole_alpha) {
        f_color = vec4(base.rgb * base.a, base.a);
        f_normal = vec4(len > 0.0 ? v_normal / len : vec3(0.0), 1.0);
    } else {  // a hole in the surface; a closed mesh still counts it for the winding
        f_color = vec4(0.0);
        f_normal = vec4(0.0);
    }
#if defined WINDING
    // front facing = the surface faces up z' (for a right-handed box): leaving a closed
    // outward-oriented mesh upwards counts +1, entering it -1. A left-handed box flips
    // both signs, which the nonzero rule does not see.
    float w = u_signed ? (gl_FrontFacing ? 1.0 : -1.0) : 1.0;
    f_count_a = w * step(u_threshold_a, vec4(v_box.z));
    f_count_b = w * step(u_threshold_b, vec4(v_box.z));
#endif
}
#endif

// Image-based depth objects and visual hulls (§4-§5): slices through the cube, each fragment
// kept when it lies inside the volume of every tested image, then textured from the images
// closest to the view. Variants:
//   (default)   one pass: all tested images in this shader (§4.1's "imaginary graphics card")
//   TEST_ONE    stencil multi-pass: only image u_face is tested, nothing is written but the
//               stencil (render.py counts passes there, as §4.1's algorithm does)
//   COLOR_ONLY  stencil multi-pass: no test, the texturing pass where the count is complete
//   RAYCAST     the cube's faces drawn, the pixel's ray walked through the N^3 voxels
//               (exact for the nearest-texel images, like the CPU reference)
//   SLAB        each slice tests exactly the slab of the cube around it (the ray from one
//               spacing in front of it to one spacing behind, overlapping its neighbours'
//               so that a ray crossing only one slice inside the cube is still covered),
//               with the voxel walk of RAYCAST: exact hits at any slice count (beyond the
//               paper)
//   HULL        a visual hull: three silhouettes (one per axis) are tested
//   TEXTURING_NEAREST  the single closest image instead of the three-image blend
//   UNLIT       the blended colour without lighting
//   INSTANCED   with RAYCAST: at every placement of render/instancing.py, the ray walked in
//               the object as it is (core:include/instancing.glsl)
//! defines: TEST_ONE COLOR_ONLY RAYCAST SLAB HULL TEXTURING_NEAREST UNLIT INSTANCED

#if defined VERTEX_SHADER
#include "core:include/camera.glsl"
#include "core:include/instancing.glsl"
uniform vec3 u_model_offset;
in vec3 in_position;   // world, relative to the cube's centre
in vec3 in_cube;       // cube coordinates of the vertex
out vec3 v_world;
out vec3 v_cube;

void main() {
    v_world = placed(in_position, u_model_offset);
    v_cube = in_cube;
    gl_Position = u_proj * u_view * vec4(v_world, 1.0);
}
#endif

#if defined FRAGMENT_SHADER
#include "core:include/camera.glsl"
#include "core:include/shading.glsl"
#include "core:include/frame_outputs.glsl"
#include "core:include/iterations.glsl"
#include "core:include/raybox.glsl"
#include "include/cube_images.glsl"
#include "include/texturing.glsl"
#include "core:include/instancing.glsl"
uniform int u_face;                 // TEST_ONE: the image tested in this pass
uniform mat4 u_world_to_box;        // camera-relative world -> cube coordinates
uniform mat4 u_box_to_world;        // cube coordinates -> camera-relative world
uniform int u_max_steps;            // RAYCAST, SLAB: bound on the voxel walk
uniform vec3 u_slice_normal;        // SLAB: unit world normal of the slices
uniform float u_slice_spacing;      // SLAB: world distance between slices
in vec3 v_world;
in vec3 v_cube;

bool inside_all(vec3 q) {
#if defined HULL
    return inside_image(0, q) && inside_image(2, q) && inside_image(4, q);
#else
    for (int k = 0; k < 6; ++k)
        if (!inside_image(k, q)) return false;
    return true;
#endif
}

#if defined RAYCAST || defined SLAB
// An exact hit lies on a column's boundary, where a texel lookup could pick either side:
// the images are read this far (in texels) further along the ray, inside the hit box.
#define INSIDE_TEXELS 0.05
// Hard cap of the voxel walk: 3 N + 3 steps at the largest N (depth_images.MAX_RESOLUTION).
#define MAX_WALK 24579

// [lo, hi] of axis a inside voxel v: the two images looking along a, at v's column.
vec2 column(int a, ivec3 v) {
    vec3 centre = (vec3(v) + 0.5) / float(u_res);
    int lower = 2 * a + 1, upper = 2 * a;    // faces -a and +a
    vec3 fl = face_coords(lower, centre), fu = face_coords(upper, centre);
    return vec2(face_depth(lower, fl), 1.0 - face_depth(upper, fu));
}

// First point of the object on the cube-space segment q0 + t dq, t in [0, 1]: a 3D DDA over
// the voxels; inside each the object is one box (reference.py), intersected by slabs.
bool raycast(vec3 q0, vec3 dq, out vec3 hit, out int steps) {
    float n = float(u_res);
    vec3 p = q0 * n, d = dq * n;
    ivec3 v = clamp(ivec3(floor(p + 1e-6 * sign(d))), ivec3(0), ivec3(u_res - 1));
    ivec3 step = ivec3(sign(d));
    vec3 inv = vec3(1e30);
    for (int a = 0; a < 3; ++a) if (d[a] != 0.0) inv[a] = 1.0 / d[a];
    vec3 next = vec3(1e30);
    for (int a = 0; a < 3; ++a)
        if (d[a] != 0.0) next[a] = (float(v[a] + (step[a] > 0 ? 1 : 0)) - p[a]) * inv[a];
    vec3 delta = abs(inv);
    float t = 0.0;
    steps = 0;
    for (int i = 0; i < min(u_max_steps, MAX_WALK); ++i) {
        ++steps;
        float t_next = min(min(next.x, next.y), next.z);
        float t1 = min(t_next, 1.0);
        float lo = t, hi = t1;
        for (int a = 0; a < 3; ++a) {
            vec2 c = column(a, v);
            if (c.x > c.y) { lo = 2.0; break; }
            if (dq[a] == 0.0) {
                if (q0[a] < c.x || q0[a] > c.y) { lo = 2.0; break; }
            } else {
                float ta = (c.x - q0[a]) / dq[a], tb = (c.y - q0[a]) / dq[a];
                lo = max(lo, min(ta, tb));
                hi = min(hi, max(ta, tb));
            }
        }
        if (lo <= hi) { hit = q0 + lo * dq; return true; }
        if (t_next >= 1.0) break;
        int a = next.x <= next.y && next.x <= next.z ? 0 : (next.y <= next.z ? 1 : 2);
        v[a] += step[a];
        if (v[a] < 0 || v[a] >= u_res) break;
        t = next[a];
        next[a] += delta[a];
    }
    hit = vec3(0.0);
    return false;
}

#endif

#if defined SLAB
// The part of this pixel's ray within one spacing of the slice, in cube coordinates,
// nearest end first (clipped to the cube).
bool slab_segment(vec3 world, out vec3 q0, out vec3 dq) {
    vec3 towards = towards_eye(world);
    float c = abs(dot(towards, u_slice_normal));
    if (c < 1e-6) return false;
    vec3 half_ray = towards * (u_slice_spacing / c);
    vec3 qa = (u_world_to_box * vec4(world + half_ray, 1.0)).xyz;
    vec3 qb = (u_world_to_box * vec4(world - half_ray, 1.0)).xyz;
    vec2 span = unit_cube_interval(qa, qb - qa);
    span = clamp(span, 0.0, 1.0);
    if (span.y <= span.x) return false;
    q0 = qa + span.x * (qb - qa);
    dq = (span.y - span.x) * (qb - qa);
    return true;
}
#endif

#if defined RAYCAST
bool pixel_segment(out vec3 q0, out vec3 dq) {
    vec2 ndc = fragment_ndc();
    vec3 a = to_object(unproject(ndc, -1.0)), b = to_object(unproject(ndc, 1.0));
    vec3 qa = (u_world_to_box * vec4(a, 1.0)).xyz, qb = (u_world_to_box * vec4(b, 1.0)).xyz;
    vec2 span = unit_cube_interval(qa, qb - qa);
    span.x = max(span.x, 0.0);
    span.y = min(span.y, 1.0);
    if (span.y <= span.x) return false;
    q0 = qa + span.x * (qb - qa);
    dq = (span.y - span.x) * (qb - qa);
    return true;
}
#endif

void main() {
    vec3 q = v_cube, world = v_world;
    int steps = 0;
#if defined RAYCAST
    vec3 q0, dq;
    if (!pixel_segment(q0, dq) || !raycast(q0, dq, q, steps)) discard;
    world = (u_box_to_world * vec4(q, 1.0)).xyz;  // in the object as it is
    gl_FragDepth = window_depth(to_instance(world));
    q += normalize(dq) * (INSIDE_TEXELS / float(u_res));
#elif defined SLAB
    vec3 q0, dq;
    if (!slab_segment(world, q0, dq) || !raycast(q0, dq, q, steps)) discard;
    world = (u_box_to_world * vec4(q, 1.0)).xyz;
    gl_FragDepth = window_depth(world);
    q += normalize(dq) * (INSIDE_TEXELS / float(u_res));
#elif defined TEST_ONE
    if (!inside_image(u_face, q)) discard;
#elif !defined COLOR_ONLY
    if (!inside_all(q)) discard;
#endif
#if defined TEST_ONE
    write_frame(vec4(0.0), world, vec3(0.0));
#else
    vec3 towards = rotate_to_object(towards_eye(to_instance(world)));
    vec4 color;
    vec3 n;
    textured(q, towards, color, n);
    n = rotate_to_instance(n);
#if !defined UNLIT
    color.rgb = shade_phong(color.rgb, n, rotate_to_instance(towards), 1.0);
#endif
    write_frame(color, to_instance(world), n);
#endif
    write_iterations(steps, 0, true);
}
#endif

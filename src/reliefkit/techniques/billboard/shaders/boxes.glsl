// Displacement-mapped billboard boxes (Mantler, Jeschke & Wimmer §3.2, §3.4.1): rasterize each
// box and march the pixel's ray through its voxel cells (exact DDA, uniform samples or sphere
// tracing over the distance texture); the hit writes every AOV and its own depth, so boxes
// overlap and meet other objects correctly.
//! defines: VOLUMETRIC SHELL THICK_SHELL MARCH_EXACT MARCH_UNIFORM MARCH_SPHERE

#if defined VERTEX_SHADER
#include "core:include/camera.glsl"
in vec3 in_position;   // proxy vertex relative to its origin (box_render.py)
uniform vec3 u_model_offset;  // from the proxy's origin to the camera's (gl/uniforms.py)

void main() {
    gl_Position = u_proj * u_view * vec4(in_position + u_model_offset, 1.0);
}
#endif

#if defined FRAGMENT_SHADER
#include "core:include/camera.glsl"
#include "core:include/raybox.glsl"
#include "core:include/shading.glsl"
#include "core:include/frame_outputs.glsl"
#include "core:include/iterations.glsl"
#include "include/box_cells.glsl"
#include "include/box_march.glsl"
uniform mat4 u_world_to_box;  // relative to the camera's origin (box_render.py)
uniform mat4 u_box_to_world;

vec3 to_world(vec3 box) {
    vec4 w = u_box_to_world * vec4(box, 1.0);
    return w.xyz / w.w;
}

void main() {
    // the pixel's ray from the near to the far plane, clipped to the box (not the proxy's face)
    vec2 ndc = fragment_ndc();
    vec3 a, b;
    if (!box_segment(u_world_to_box, unproject(ndc, -1.0), unproject(ndc, 1.0), a, b)) discard;
    vec3 res = vec3(u_res);
    vec3 o = a * res, d = (b - a) * res;   // voxel coordinates
    if (dot(d, d) == 0.0) discard;
    float s_hit;
    ivec3 cell;
    int iters;
    if (!march(o, d, s_hit, cell, iters)) {
#if defined COUNT_ITERATIONS
        write_counted_miss(iters);  // count the work of a miss without drawing it
        return;
#else
        discard;
#endif
    }
    vec3 hit = to_world(clamp((o + s_hit * d) / res, 0.0, 1.0));
    vec3 n = cell_normal(cell);
    vec3 to_eye = towards_eye(hit);
    if (dot(n, to_eye) < 0.0) n = -n;  // two-sided, like the ground-truth mesh
    write_frame(vec4(shade_phong(cell_color(cell).rgb, n, to_eye, 1.0), 1.0), hit, n);
    write_iterations(iters, 0, true);
    gl_FragDepth = window_depth(hit);
}
#endif

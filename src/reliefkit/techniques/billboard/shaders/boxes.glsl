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
#if defined GL_ES
precision highp sampler2DArray;
#endif
#include "core:include/camera.glsl"
#include "core:include/raybox.glsl"
#include "core:include/shading.glsl"
#include "core:include/frame_outputs.glsl"
#include "core:include/iterations.glsl"
#include "include/box_cells.glsl"
#include "include/box_march.glsl"
uniform mat4 u_world_to_box;  // relative to the camera's origin (box_render.py)
uniform mat4 u_box_to_world;
// Handing over to the billboard cloud (lod auto, §3.4.2): as the box flattens, its colour and
// normal turn into the cloud's, filtered as the cloud filters them, and pixel by pixel (a
// stable per-pixel threshold below u_handoff) its coverage becomes the cloud's: the ray's
// crossing of the rectangle (w = 0.5) where the cloud's alpha test passes. At zero depth every
// pixel draws what the cloud draws, so the switch to it changes (almost) nothing, and each
// frame of the transition changes only its share of the pixels that differ.
// u_handoff = 1 - the flatten factor; 0 otherwise.
uniform float u_handoff;
uniform sampler2DArray u_bbc_color;   // the cloud's atlases (render.py: linear colour, normal)
uniform sampler2DArray u_bbc_normal;
uniform vec4 u_atlas_rect;            // this box's rectangle in the atlas: x, y, w, h (0..1)
uniform float u_atlas_page;

// Where the pixel's ray at window NDC `ndc` crosses the rectangle (w = 0.5), in (u, v).
vec2 rectangle_uv(vec2 ndc) {
    vec4 n = u_world_to_box * vec4(unproject(ndc, -1.0), 1.0);
    vec4 f = u_world_to_box * vec4(unproject(ndc, 1.0), 1.0);
    vec3 a = n.xyz / n.w, b = f.xyz / f.w;
    float s = abs(b.z - a.z) > 1e-30 ? (0.5 - a.z) / (b.z - a.z) : 0.0;
    return mix(a.xy, b.xy, s);
}

// The cloud's colour and normal at box point (u, v), filtered as the cloud's quad is: the
// gradients are the rectangle coordinates' change to the next pixel right and up, computed
// exactly (the hardware takes them from the quad's own fragments), so the mip level matches.
void cloud_sample(vec2 uv, out vec4 color, out vec3 normal) {
    vec2 ndc = fragment_ndc(), pixel = 2.0 / u_viewport;
    vec2 here = rectangle_uv(ndc);
    vec2 dx = (rectangle_uv(ndc + vec2(pixel.x, 0.0)) - here) * u_atlas_rect.zw;
    vec2 dy = (rectangle_uv(ndc + vec2(0.0, pixel.y)) - here) * u_atlas_rect.zw;
    vec3 at = vec3(u_atlas_rect.xy + uv * u_atlas_rect.zw, u_atlas_page);
    color = textureGrad(u_bbc_color, at, dx, dy);
    normal = textureGrad(u_bbc_normal, at, dx, dy).rgb * 2.0 - 1.0;
}

// A pixel's own threshold in [0, 1): an integer hash of its window position, the same in
// every frame, so the pixels handed over only grow as u_handoff does.
float pixel_threshold() {
    uvec2 p = uvec2(gl_FragCoord.xy);
    uint h = p.x * 1973u + p.y * 9277u + 26699u;
    h = (h ^ (h >> 13u)) * 1274126177u;
    h ^= h >> 16u;
    return float(h & 65535u) / 65536.0;
}

// Where the box segment a + s (b - a) crosses the rectangle (w = 0.5) and the cloud's
// coverage there passes its alpha test (at the base level, as the cloud tests it).
bool cloud_hit(vec3 a, vec3 ab, out float s_hit) {
    s_hit = 0.0;
    if (ab.z == 0.0) return false;
    s_hit = (0.5 - a.z) / ab.z;
    if (s_hit < 0.0 || s_hit > 1.0) return false;
    vec2 uv = clamp(a.xy + s_hit * ab.xy, 0.0, 1.0);
    vec3 at = vec3(u_atlas_rect.xy + uv * u_atlas_rect.zw, u_atlas_page);
    return textureLod(u_bbc_color, at, 0.0).a >= 0.5;
}

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
    ivec3 cell = ivec3(0);
    int iters = 1;
    bool shows_cloud = u_handoff > 0.0 && pixel_threshold() < u_handoff;
    bool found = shows_cloud ? cloud_hit(a, b - a, s_hit) : march(o, d, s_hit, cell, iters);
    if (!found) {
#if defined COUNT_ITERATIONS
        write_counted_miss(iters);  // count the work of a miss without drawing it
        return;
#else
        discard;
#endif
    }
    vec3 box_hit = clamp((o + s_hit * d) / res, 0.0, 1.0);
    vec3 hit = to_world(box_hit);
    vec3 base = cell_color(cell).rgb;
    vec3 n = cell_normal(cell);
    if (u_handoff > 0.0) {
        vec4 cloud_color;
        vec3 cloud_normal;
        cloud_sample(box_hit.xy, cloud_color, cloud_normal);
        float weight = shows_cloud ? 1.0 : u_handoff;
        base = mix(base, cloud_color.rgb, weight);
        vec3 blended = mix(n, cloud_normal, weight);
        n = dot(blended, blended) > 1e-12 ? normalize(blended) : n;
    }
    vec3 to_eye = towards_eye(hit);
    // two-sided like the ground-truth mesh; a pixel showing the cloud flips as the cloud's quad
    // does, by the side of the rectangle it is seen from
    vec3 facing = shows_cloud ? u_box_to_world[2].xyz : n;
    if (dot(facing, to_eye) < 0.0) n = -n;
    write_frame(vec4(shade_phong(base, n, to_eye, 1.0), 1.0), hit, n);
    write_iterations(iters, 0, true);
    gl_FragDepth = window_depth(hit);
}
#endif

// Displacement mapping by slicing (Kautz & Seidel 2001, §3): slice polygons through the
// displacement volume (displacement_slices.py) carry the exact box coordinates (u, v, h) of
// their vertices; each fragment reads the displacement texture at (u, v) and is kept by an
// alpha test against its h (a discard), then drawn opaque with the depth test:
//   u_test 0  fill (Dietrich, §3.1): height >= h, fills the inside, draws the base h = 0
//             (orthogonal and screen slicing too: their slices and the base, so height 0
//             is surface)
//   u_test 1  bound (Schaufler, §3.1): |height - h| <= u_bound (one slice spacing)
// Where the height is 0 and the colour's alpha is below 0.5 there is nothing (a projected
// mesh's background): no fragment is kept there. The colour is tinted by the base surface's
// own material at (u, v) (core:include/surface_tint.glsl; the layer of the base triangle).
// The normal is that of the displaced surface S(u, v) = X(u, v, height(u, v)) through the
// slice's tangent frame (the tetrahedron's Jacobian d X / d(u, v, h)).
//! defines: UNLIT

#if defined VERTEX_SHADER
#include "core:include/camera.glsl"
uniform vec3 u_model_offset;  // from the slices' origin to the camera's (gl/uniforms.py)
in vec3 in_position;
in vec3 in_uvh;
in vec3 in_ju;
in vec3 in_jv;
in vec3 in_jh;
in float in_layer;
out vec3 v_world;
out vec3 v_uvh;
out vec3 v_ju;
out vec3 v_jv;
out vec3 v_jh;
flat out float v_layer;

void main() {
    v_world = in_position + u_model_offset;
    v_uvh = in_uvh;
    v_ju = in_ju;
    v_jv = in_jv;
    v_jh = in_jh;
    v_layer = in_layer;
    gl_Position = u_proj * u_view * vec4(v_world, 1.0);
}
#endif

#if defined FRAGMENT_SHADER
#include "core:include/camera.glsl"
#include "core:include/shading.glsl"
#include "core:include/frame_outputs.glsl"
#include "core:include/iterations.glsl"
#include "core:include/surface_tint.glsl"
#include "include/displacement_height.glsl"
uniform sampler2D u_color;   // linear RGBA (repeat or clamp like the height)
uniform vec2 u_tile;
uniform int u_test;
uniform float u_bound;
in vec3 v_world;
in vec3 v_uvh;
in vec3 v_ju;
in vec3 v_jv;
in vec3 v_jh;
flat in float v_layer;

bool keep(float height, float h) {
    if (u_test == 1) return abs(height - h) <= u_bound;
    return height >= h;
}

void main() {
    vec2 st = v_uvh.xy * u_tile;
    float height = disp_height(st);
    vec4 base = texture(u_color, st);
    if (!keep(height, v_uvh.z) || (height <= 0.0 && base.a < 0.5)) discard;
    // the height gradient by central differences one texel apart, in base uv units
    vec2 texel = 1.0 / vec2(u_hf_size);
    float dhs = (disp_height(st + vec2(texel.x, 0.0)) - disp_height(st - vec2(texel.x, 0.0)))
        / (2.0 * texel.x);
    float dht = (disp_height(st + vec2(0.0, texel.y)) - disp_height(st - vec2(0.0, texel.y)))
        / (2.0 * texel.y);
    vec3 su = v_ju + v_jh * (dhs * u_tile.x);
    vec3 sv = v_jv + v_jh * (dht * u_tile.y);
    vec3 n = cross(su, sv);
    float len = length(n);
    n = len > 1e-20 ? n / len : normalize(v_jh);
    if (dot(n, v_jh) < 0.0) n = -n;  // away from the base, whatever the uv orientation
    vec3 albedo = base.rgb * surface_tint(v_uvh.xy, v_layer);
#if defined UNLIT
    vec3 rgb = albedo;
#else
    vec3 rgb = shade_phong(albedo, n, towards_eye(v_world), 1.0);
#endif
    write_frame(vec4(rgb, 1.0), v_world, n);
    write_iterations(1, 0, true);
}
#endif

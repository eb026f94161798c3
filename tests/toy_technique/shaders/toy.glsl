// The toy technique's quad: flat colour, opaque or transparent (tests/toy_technique).
//! defines: TRANSPARENT CHECKER

#if defined VERTEX_SHADER
#include "core:include/camera.glsl"
uniform vec3 u_model_offset;  // from the quad's centre to the camera's origin
in vec3 in_position;
out vec3 v_world;

void main() {
    v_world = in_position + u_model_offset;
    gl_Position = u_proj * u_view * vec4(v_world, 1.0);
}
#endif

#if defined FRAGMENT_SHADER
#include "core:include/camera.glsl"
#if defined TRANSPARENT
#include "core:include/transparency.glsl"
#else
#include "core:include/frame_outputs.glsl"
#include "core:include/iterations.glsl"
#endif
uniform vec4 u_color;      // linear straight colour; alpha is the quad's opacity
uniform vec3 u_normal;
in vec3 v_world;

void main() {
    vec3 color = u_color.rgb;
#if defined CHECKER
    ivec2 cell = ivec2(floor(gl_FragCoord.xy / 4.0));
    if ((cell.x + cell.y) % 2 == 0) color *= 0.5;
#endif
    vec3 n = dot(u_normal, towards_eye(v_world)) < 0.0 ? -u_normal : u_normal;
#if defined TRANSPARENT
    write_transparent(color, u_color.a, v_world, n);
#else
    write_frame(vec4(color, 1.0), v_world, n);
    write_iterations(1, 0, true);
#endif
}
#endif

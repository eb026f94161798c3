// The viewer's debug views (docs/viewer.md, web/src/debug_views.js): what a panel shows of
// its AOV targets instead of the picture. Display colours (not sRGB-encoded again), alpha 1
// where the view has something to show, transparent black elsewhere.
#include "core:viewer/include/heat_ramp.glsl"

#define DEBUG_NORMALS 1
#define DEBUG_DEPTH 2
#define DEBUG_ITERATIONS 3
#define DEBUG_MASK 4

uniform int u_debug;               // 0: the picture
uniform highp sampler2D u_normal;
uniform highp sampler2D u_iterations;  // (primary, secondary, ran, hit): iterations.glsl
uniform highp sampler2D u_reference;   // the mesh panel's coverage (R: 1 covered)
uniform vec3 u_eye;                // relative to the camera's origin, as the positions are
uniform vec2 u_depth_range;        // view distances shown white and black
uniform float u_iteration_scale;   // the count shown at the top of the ramp

vec4 debug_view(ivec2 p, bool covered, vec3 position) {
    if (u_debug == DEBUG_NORMALS) {
        return covered ? vec4(texelFetch(u_normal, p, 0).xyz * 0.5 + 0.5, 1.0) : vec4(0.0);
    }
    if (u_debug == DEBUG_DEPTH) {
        float d = distance(position, u_eye);
        float grey = clamp((u_depth_range.y - d) / (u_depth_range.y - u_depth_range.x), 0.0, 1.0);
        return covered ? vec4(vec3(grey), 1.0) : vec4(0.0);
    }
    if (u_debug == DEBUG_ITERATIONS) {
        vec4 counts = texelFetch(u_iterations, p, 0);
        return counts.z > 0.5 ? vec4(heat_ramp(counts.x / u_iteration_scale), 1.0) : vec4(0.0);
    }
    // DEBUG_MASK: metrics.error_image(this, the mesh, "mask")
    bool reference = texelFetch(u_reference, p, 0).r > 0.5;
    return vec4(covered && !reference, covered && reference, !covered && reference, 1.0);
}

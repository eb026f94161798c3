// Copies a frame drawn elsewhere (the stencil multi-pass target) into the frame's own
// target: colour, position and normal per pixel, the depth recomputed from the position.
#if defined VERTEX_SHADER
#include "core:include/fullscreen.glsl"
#endif

#if defined FRAGMENT_SHADER
#include "core:include/camera.glsl"
#include "core:include/frame_outputs.glsl"
#include "core:include/iterations.glsl"
uniform highp sampler2D u_src_color;
uniform highp sampler2D u_src_position;
uniform highp sampler2D u_src_normal;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 position = texelFetch(u_src_position, p, 0);
    if (position.w <= 0.0) discard;
    write_frame(texelFetch(u_src_color, p, 0), position.xyz, texelFetch(u_src_normal, p, 0).xyz);
    gl_FragDepth = window_depth(position.xyz);
    write_iterations(0, 0, true);
}
#endif

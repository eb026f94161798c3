// Depth peeling's composite (render.py, the "peel" baseline of §4.1): one full-screen
// triangle adds a peeled layer's premultiplied colour under what is in front of it.

#if defined VERTEX_SHADER
#include "core:include/fullscreen.glsl"
#endif

#if defined FRAGMENT_SHADER
uniform highp sampler2D u_layer;
layout(location = 0) out vec4 f_color;
layout(location = 1) out vec4 f_position;
layout(location = 2) out vec4 f_normal;

void main() {
    f_color = texelFetch(u_layer, ivec2(gl_FragCoord.xy), 0);
    f_position = vec4(0.0);
    f_normal = vec4(0.0);
}
#endif

// The browser viewer's copy of the opaque pass's depth as a float colour (what
// render/multipass/opaque_depth.py reads back on the CPU: a transparent plan samples it while
// the depth attachment itself is being tested). Built as GLSL ES by the shader loader and
// handed to the page in inputs.json (reliefkit.viewer.site).
#if defined VERTEX_SHADER
#include "core:include/fullscreen.glsl"
#endif

#if defined FRAGMENT_SHADER
uniform highp sampler2D u_depth;
out vec4 f_out;

void main() {
    f_out = vec4(texelFetch(u_depth, ivec2(gl_FragCoord.xy), 0).r);
}
#endif

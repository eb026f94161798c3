#version 300 es
// The opaque pass's depth as a float colour (render/multipass/opaque_depth.py: a transparent
// plan samples it while the depth attachment itself is being tested). VERTEX_SHADER /
// FRAGMENT_SHADER pick the stage.
precision highp float;
#ifdef VERTEX_SHADER
void main() {  // one full-screen triangle
    vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
#else
uniform highp sampler2D u_depth;
out vec4 f_out;

void main() {
    f_out = vec4(texelFetch(u_depth, ivec2(gl_FragCoord.xy), 0).r);
}
#endif

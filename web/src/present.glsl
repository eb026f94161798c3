#version 300 es
// The picture `reliefkit render` writes (render/frame.py Frame.rgba8, colorspace.to_rgba8):
// where the opaque pass covered a pixel (position.w > 0.5), its linear colour sRGB-encoded
// with straight alpha; elsewhere transparent. VERTEX_SHADER / FRAGMENT_SHADER pick the stage.
precision highp float;
#ifdef VERTEX_SHADER
void main() {  // one full-screen triangle
    vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
#else
uniform sampler2D u_color;
uniform sampler2D u_position;
out vec4 f_out;

vec3 srgb_encode(vec3 x) {
    x = clamp(x, 0.0, 1.0);
    return mix(1.055 * pow(x, vec3(1.0 / 2.4)) - 0.055, 12.92 * x, lessThanEqual(x, vec3(0.0031308)));
}

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 color = texelFetch(u_color, p, 0);
    bool covered = texelFetch(u_position, p, 0).w > 0.5;
    f_out = covered ? vec4(srgb_encode(color.rgb), clamp(color.a, 0.0, 1.0)) : vec4(0.0);
}
#endif

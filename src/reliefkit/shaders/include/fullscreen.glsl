// A vertex stage drawing one triangle over the whole viewport (3 vertices, no buffers):
// include it inside `#if defined VERTEX_SHADER`.
void main() {
    vec2 corner = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
    gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
}

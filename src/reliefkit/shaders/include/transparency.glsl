// Outputs of transparent drawables (gl/targets.py, transparent pass): colour composited
// front to back with the under operator, and the world position and normal of the point
// where the accumulated opacity first reaches 0.5, gated so the first such write wins.
layout(location = 0) out vec4 f_color;
layout(location = 1) out vec4 f_position;
layout(location = 2) out vec4 f_normal;
uniform sampler2D u_front_opacity;  // .a: opacity accumulated by the drawables in front

// Opacity accumulated in front of this drawable at this pixel.
float front_opacity() {
    return texelFetch(u_front_opacity, ivec2(gl_FragCoord.xy), 0).a;
}

// A fragment of straight `color` and `opacity` whose AOV point is world_pos / world_normal;
// `reaches_half`: the accumulated opacity reaches 0.5 at that point.
void write_transparent_at(vec3 color, float opacity, vec3 world_pos, vec3 world_normal,
                          bool reaches_half) {
    float gate = reaches_half ? 1.0 : 0.0;
    f_color = vec4(color * opacity, opacity);
    f_position = vec4(world_pos * gate, gate);
    f_normal = vec4(world_normal * gate, gate);
}

// A thin layer (a surface of uniform opacity): it is the 0.5 point if it brings the
// accumulated opacity to 0.5 or more.
void write_transparent(vec3 color, float opacity, vec3 world_pos, vec3 world_normal) {
    float front = front_opacity();
    write_transparent_at(color, opacity, world_pos, world_normal,
                         front + (1.0 - front) * opacity >= 0.5);
}

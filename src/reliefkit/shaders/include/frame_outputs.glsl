// The render targets every opaque drawable writes (gl/targets.py reads them back):
// 0: linear colour with straight alpha, 1: world position + coverage, 2: world normal.
// Further attachments start at RK_FRAME_ATTACHMENTS (see iterations.glsl).
layout(location = 0) out vec4 f_color;
layout(location = 1) out vec4 f_position;
layout(location = 2) out vec4 f_normal;

void write_frame(vec4 color, vec3 world_pos, vec3 world_normal) {
    f_color = color;
    f_position = vec4(world_pos, 1.0);
    f_normal = vec4(world_normal, 0.0);
}

// Ground truth: rasterize a triangle mesh with Phong shading and write every AOV.
//! defines: HAS_TEXTURE

#if defined VERTEX_SHADER
uniform mat4 u_view;
uniform mat4 u_proj;
in vec3 in_position;
in vec3 in_normal;
in vec4 in_color;
in vec2 in_uv;
out vec3 v_world;
out vec3 v_normal;
out vec4 v_color;
out vec2 v_uv;

void main() {
    v_world = in_position;
    v_normal = in_normal;
    v_color = in_color;
    v_uv = in_uv;
    gl_Position = u_proj * u_view * vec4(in_position, 1.0);
}
#endif

#if defined FRAGMENT_SHADER
#include "include/shading.glsl"
#include "include/frame_outputs.glsl"
uniform vec3 u_eye;
uniform bool u_orthographic;
uniform vec3 u_view_dir;      // for orthographic cameras: from the scene towards the eye
#if defined HAS_TEXTURE
uniform sampler2D u_texture;  // sRGB texture: sampling returns linear colour
#endif
in vec3 v_world;
in vec3 v_normal;
in vec4 v_color;
in vec2 v_uv;

void main() {
    vec4 base = v_color;
#if defined HAS_TEXTURE
    base *= texture(u_texture, v_uv);
#endif
    vec3 to_eye = u_orthographic ? u_view_dir : normalize(u_eye - v_world);
    vec3 n = normalize(v_normal);
    if (!gl_FrontFacing) n = -n;  // two-sided: leaves and open meshes shade from both sides
    write_frame(vec4(shade_phong(base.rgb, n, to_eye, 1.0), base.a), v_world, n);
}
#endif

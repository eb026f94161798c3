// Ground truth: rasterize a triangle mesh with Phong shading and write every AOV.
// One draw per material: its colour factor, its alpha mode (u_alpha_mode: 0 OPAQUE, alpha drawn
// as 1; 1 MASK, fragments with alpha < u_alpha_cutoff discarded, the rest drawn as 1; 2 BLEND,
// alpha kept), and with HAS_TEXTURE its texture and UV transform. SHADOWS: lit only where the
// shadow map (render/shadows.py) sees the light; SHADOW_MAP: the depth pass from the light
// that draws it (the alpha test only, no outputs). INSTANCED: at every placement of
// render/instancing.py (include/instancing.glsl).
//! defines: HAS_TEXTURE SHADOWS SHADOW_MAP INSTANCED

#if defined VERTEX_SHADER
#include "include/camera.glsl"
#include "include/instancing.glsl"
uniform vec3 u_model_offset;  // from the mesh's origin to the camera's (gl/uniforms.py)
in vec3 in_position;
in vec3 in_normal;
in vec4 in_color;
out vec3 v_world;
out vec3 v_local;  // relative to the mesh's origin: the shadow map's coordinates
out vec3 v_normal;
out vec4 v_color;
#if defined HAS_TEXTURE
uniform mat3 u_uv_transform;  // the material's affine map of (u, v, 1)
in vec2 in_uv;
out vec2 v_uv;
#endif

void main() {
    v_world = placed(in_position, u_model_offset);
    v_local = in_position;
    v_normal = rotate_to_instance(in_normal);
    v_color = in_color;
#if defined HAS_TEXTURE
    v_uv = (u_uv_transform * vec3(in_uv, 1.0)).xy;
#endif
    gl_Position = u_proj * u_view * vec4(v_world, 1.0);
}
#endif

#if defined FRAGMENT_SHADER
#include "include/camera.glsl"
#include "include/shading.glsl"
#if !defined SHADOW_MAP
#include "include/frame_outputs.glsl"
#include "include/iterations.glsl"
#endif
#if defined SHADOWS
#include "include/shadow_map.glsl"
#endif
uniform vec4 u_base_color;  // the material's linear colour factor
uniform int u_alpha_mode;  // 0 OPAQUE, 1 MASK, 2 BLEND (ALPHA_MODE_CODES in render/mesh.py)
uniform float u_alpha_cutoff;  // MASK threshold
#if defined HAS_TEXTURE
uniform sampler2D u_texture;  // sRGB texture: sampling returns linear colour
in vec2 v_uv;
#endif
in vec3 v_world;
in vec3 v_local;
in vec3 v_normal;
in vec4 v_color;

void main() {
    vec4 base = v_color * u_base_color;
#if defined HAS_TEXTURE
    base *= texture(u_texture, v_uv);
#endif
    if (u_alpha_mode == 1 && base.a < u_alpha_cutoff) discard;
    if (u_alpha_mode == 2 && base.a <= 0.0) discard;  // nothing there: no coverage, no AOVs
#if !defined SHADOW_MAP
    if (u_alpha_mode != 2) base.a = 1.0;
    vec3 n = normalize(v_normal);
    if (!gl_FrontFacing) n = -n;  // two-sided: leaves and open meshes shade from both sides
    float lit = 1.0;
#if defined SHADOWS
    lit = light_visibility(v_local, dot(n, u_light_dir) >= 0.0 ? n : -n);
#endif
    write_frame(vec4(shade_phong(base.rgb, n, towards_eye(v_world), lit), base.a), v_world, n);
    write_iterations(0, 0, true);
#endif
}
#endif

// Billboard cloud (Décoret et al. 2003): one textured quad per rectangle, all in one draw.
// Atlas pages are layers of two texture arrays (render.py): colour (linear, straight alpha =
// coverage, mipmapped) and world normals (encoded (n + 1) / 2). Coverage is alpha-tested at
// 0.5 on the base level, so minification never erodes thin parts (a mip level averages them
// with the empty texels around them); colour and normal are sampled with mipmaps.
// Two-sided as the ground truth (shaders/mesh.glsl): a rectangle seen from its back shades
// with its stored normal negated. INSTANCED: at every placement of render/instancing.py.
//! defines: INSTANCED

#if defined VERTEX_SHADER
#include "core:include/camera.glsl"
#include "core:include/instancing.glsl"
uniform vec3 u_model_offset;  // from the cloud's origin to the camera's (gl/uniforms.py)
in vec3 in_position;          // quad corner relative to the cloud's origin
in vec3 in_atlas;             // (u, v) in the page, page index
in vec3 in_plane_normal;      // unit normal of the rectangle's plane (u x v)
out vec3 v_world;
out vec2 v_uv;
flat out float v_page;
flat out vec3 v_plane_normal;

void main() {
    v_world = placed(in_position, u_model_offset);
    v_uv = in_atlas.xy;
    v_page = in_atlas.z;
    v_plane_normal = in_plane_normal;
    gl_Position = u_proj * u_view * vec4(v_world, 1.0);
}
#endif

#if defined FRAGMENT_SHADER
#if defined GL_ES
precision highp sampler2DArray;
#endif
#include "core:include/camera.glsl"
#include "core:include/shading.glsl"
#include "core:include/frame_outputs.glsl"
#include "core:include/iterations.glsl"
#include "core:include/instancing.glsl"
uniform sampler2DArray u_color_atlas;   // linear colour, alpha = coverage
uniform sampler2DArray u_normal_atlas;  // world normal as (n + 1) / 2
in vec3 v_world;
in vec2 v_uv;
flat in float v_page;
flat in vec3 v_plane_normal;

// The stored normal, decoded and renormalized; where filtering averaged opposite normals to
// nearly nothing, the rectangle's plane normal stands in.
vec3 stored_normal(vec3 encoded) {
    vec3 n = 2.0 * encoded - 1.0;
    float len = length(n);
    return len > 1e-3 ? n / len : v_plane_normal;
}

void main() {
    vec3 at = vec3(v_uv, v_page);
    // mipmapped lookups first: implicit derivatives are undefined after a discard
    vec3 base = texture(u_color_atlas, at).rgb;
    vec3 encoded = texture(u_normal_atlas, at).rgb;
    if (textureLod(u_color_atlas, at, 0.0).a < 0.5) discard;
    vec3 n = rotate_to_instance(stored_normal(encoded));  // the atlas holds the object's
    if (!gl_FrontFacing) n = -n;  // two-sided, the rule of shaders/mesh.glsl
    write_frame(vec4(shade_phong(base, n, towards_eye(v_world), 1.0), 1.0), v_world, n);
    write_iterations(0, 0, true);
}
#endif

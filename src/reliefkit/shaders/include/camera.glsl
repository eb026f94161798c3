// The camera, as gl/uniforms.py camera_uniforms() sets it for every program.
uniform mat4 u_view;
uniform mat4 u_proj;
uniform mat4 u_inv_view_proj;
uniform vec2 u_viewport;     // (W, H) in pixels
uniform vec3 u_eye;
uniform bool u_orthographic;
uniform vec3 u_view_dir;     // for orthographic cameras: from the scene towards the eye

// World point at normalized device coordinates (x, y, z).
vec3 unproject(vec2 ndc_xy, float ndc_z) {
    vec4 w = u_inv_view_proj * vec4(ndc_xy, ndc_z, 1.0);
    return w.xyz / w.w;
}

#if defined FRAGMENT_SHADER
// NDC x, y of this fragment's pixel centre.
vec2 fragment_ndc() {
    return gl_FragCoord.xy / u_viewport * 2.0 - 1.0;
}
#endif

// Unit vector from a world point towards the eye.
vec3 towards_eye(vec3 world) {
    return u_orthographic ? u_view_dir : normalize(u_eye - world);
}

// Window depth in [0, 1] of a world point.
float window_depth(vec3 world) {
    vec4 clip = u_proj * u_view * vec4(world, 1.0);
    return clamp(0.5 * clip.z / clip.w + 0.5, 0.0, 1.0);
}

// Phong shading with one directional light (see scene/light.py for the uniforms).
uniform vec3 u_light_dir;     // unit vector from the surface towards the light
uniform vec3 u_light_color;
uniform float u_ambient;
uniform float u_specular;
uniform float u_shininess;

// `n` and `view_dir` (surface towards eye) are unit vectors; `lit` is 0 in shadow, 1 in light.
vec3 shade_phong(vec3 base, vec3 n, vec3 view_dir, float lit) {
    float diffuse = max(dot(n, u_light_dir), 0.0) * lit;
    vec3 h = normalize(u_light_dir + view_dir);
    float spec = (diffuse > 0.0) ? pow(max(dot(n, h), 0.0), u_shininess) * u_specular * lit : 0.0;
    return base * (u_ambient + diffuse * u_light_color) + spec * u_light_color;
}

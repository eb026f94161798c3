// Shadows from a shadow map of the directional light (render/shadows.py draws it).
uniform highp sampler2DShadow u_shadow_map;  // depth from the light, compared on lookup
uniform mat4 u_light_matrix;   // the drawable's own coordinates -> the light's clip space
uniform float u_shadow_texel;  // one shadow-map texel in those coordinates' units
uniform float u_shadow_bias;   // one texel's depth in the light's window depth

// The fraction of the light reaching point p (0 in shadow, 1 lit), filtered over 3 x 3
// texels. p is pushed off its surface along `towards_light` (its normal, turned to face
// the light) by 2.5 texels, so a lit surface never shadows itself (no acne), also where the
// filter reaches across an edge onto a neighbouring face.
float light_visibility(vec3 p, vec3 towards_light) {
    vec4 c = u_light_matrix * vec4(p + towards_light * (2.5 * u_shadow_texel), 1.0);
    vec3 s = c.xyz / c.w * 0.5 + 0.5;
    if (any(lessThan(s.xy, vec2(0.0))) || any(greaterThan(s.xy, vec2(1.0)))) return 1.0;
    vec2 texel = 1.0 / vec2(textureSize(u_shadow_map, 0));
    float lit = 0.0;
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            lit += texture(u_shadow_map, vec3(s.xy + vec2(dx, dy) * texel, s.z - u_shadow_bias));
        }
    }
    return lit / 9.0;
}

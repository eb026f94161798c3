// The colour of a base surface's own material at a base uv, from its material atlas
// (bake/uv_atlas.py: one layer per material over the uv rectangle u_surface_box, uniforms
// from uv_atlas.atlas_uniforms); white without one. What grows on the surface (a shell's
// volume, a displacement) is multiplied by it.
uniform mediump sampler2DArray u_surface;
uniform bool u_tinted;              // whether there is an atlas
uniform vec4 u_surface_box;         // u0, v0, 1 / (u1 - u0), 1 / (v1 - v0)

vec3 surface_tint(vec2 uv, float layer) {
    if (!u_tinted) return vec3(1.0);
    vec2 st = (uv - u_surface_box.xy) * u_surface_box.zw;
    return textureLod(u_surface, vec3(st, layer), 0.0).rgb;
}

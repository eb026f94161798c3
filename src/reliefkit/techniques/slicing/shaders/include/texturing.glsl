// View-dependent texturing of a depth object (§4.2). Include after cube_images.glsl and
// core:include/camera.glsl.
uniform highp sampler2DArray u_color;    // linear RGBA, straight alpha, layer k = face k
uniform highp sampler2DArray u_normals;  // world normals, as sampled
uniform vec2 u_normals_decode;           // (scale, bias) from the sampled value to the normal
uniform vec3 u_face_normal[6];           // outward world normal of face k
uniform float u_visible_depth;           // how far behind image k's surface q may lie and
                                         // still be seen by it (cube-side units)
uniform bool u_check_visibility;         // false: the paper's texturing, no visibility

// Whether image k saw the point q (it is its first surface from face k), given the depth
// tested for visibility; a hull (depths 0) sees nothing this way, nor does an empty texel
// (met by points on a column's boundary).
bool image_sees(int k, vec3 q) {
    vec3 f = face_coords(k, q);
    float d = face_depth(k, f);
    return d <= 1.0 && 1.0 - f.z - d <= u_visible_depth;
}

// Weights of the images for a point q seen along `towards` (unit, towards the eye): the
// three faces closest to the view direction, weighted by how much less than 90 degrees
// their angle is (summing to one), among the images that see q where any does (NEAREST:
// the single closest such image).
void image_weights(vec3 q, vec3 towards, out float w[6]) {
    float best = -2.0;
    int nearest = 0;
    float total = 0.0;
    bool any_sees = false;
    for (int k = 0; k < 6; ++k) any_sees = any_sees || (u_check_visibility &&
        dot(u_face_normal[k], towards) > 0.0 && image_sees(k, q));
    for (int k = 0; k < 6; ++k) {
        float c = dot(u_face_normal[k], towards);
        bool usable = c > 0.0 && (!any_sees || image_sees(k, q));
        w[k] = usable ? 1.5707963 - acos(min(c, 1.0)) : 0.0;
        if (usable && c > best) { best = c; nearest = k; }
        total += w[k];
    }
#if defined TEXTURING_NEAREST
    for (int k = 0; k < 6; ++k) w[k] = k == nearest ? 1.0 : 0.0;
#else
    if (total <= 0.0) {  // exactly edge-on to all three: take the nearest
        for (int k = 0; k < 6; ++k) w[k] = k == nearest ? 1.0 : 0.0;
        total = 1.0;
    }
    for (int k = 0; k < 6; ++k) w[k] /= total;
#endif
}

// Image k's premultiplied colour and normal at f, bilinear over its four nearest texels
// (clamped to the edge, as GL_LINEAR), each weighted by whether its column is set in the
// exact depth image: an empty texel adds nothing whatever its colour and normal decode to
// (block-compressed, a stored 0 decodes near 0 but not to it; docs/compact.md).
void masked_bilinear(int k, vec2 f, out vec4 color, out vec3 normal) {
    vec2 p = clamp(f, 0.0, 1.0) * float(u_res) - 0.5;
    ivec2 base = ivec2(floor(p));
    vec2 t = p - vec2(base);
    color = vec4(0.0);
    normal = vec3(0.0);
    for (int i = 0; i < 4; ++i) {
        ivec2 o = ivec2(i & 1, i >> 1);
        ivec3 texel = ivec3(clamp(base + o, ivec2(0), ivec2(u_res - 1)), k);
        if (texelFetch(u_depth, texel, 0).r > 1.0) continue;  // empty column
        float w = (o.x == 1 ? t.x : 1.0 - t.x) * (o.y == 1 ? t.y : 1.0 - t.y);
        vec4 c = texelFetch(u_color, texel, 0);
        color += w * vec4(c.rgb * c.a, c.a);
        normal += w * (texelFetch(u_normals, texel, 0).xyz * u_normals_decode.x
                       + u_normals_decode.y);
    }
}

// Colour (straight alpha) and world normal blended from the images at q.
void textured(vec3 q, vec3 towards, out vec4 color, out vec3 normal) {
    float w[6];
    image_weights(q, towards, w);
    vec4 sum = vec4(0.0);
    vec3 n = vec3(0.0);
    for (int k = 0; k < 6; ++k) {
        if (w[k] <= 0.0) continue;
        vec4 c;
        vec3 nk;
        masked_bilinear(k, face_coords(k, q).xy, c, nk);
        sum += w[k] * c;
        n += w[k] * nk;
    }
    color = sum.a > 0.0 ? vec4(sum.rgb / sum.a, 1.0) : vec4(0.5, 0.5, 0.5, 1.0);
    normal = dot(n, n) > 1e-12 ? normalize(n) : towards;
}

// Six depth images on a cube (depth_images.py): nearest-texel reconstruction, as the CPU
// reference (reference.py) defines the object. q is a point in cube coordinates [0, 1]^3.
uniform highp sampler2DArray u_depth;   // R32F, layer k = face k; empty texels hold 2
uniform int u_res;                      // N texels per side
uniform mat4 u_cube_to_face[6];         // cube coordinates -> face k's (u, v, h), h outward

// Face k's box coordinates of q: (u, v) on the face, h = 1 on the face itself.
vec3 face_coords(int k, vec3 q) {
    return (u_cube_to_face[k] * vec4(q, 1.0)).xyz;
}

ivec3 face_texel(int k, vec3 f) {
    ivec2 t = clamp(ivec2(floor(f.xy * float(u_res))), ivec2(0), ivec2(u_res - 1));
    return ivec3(t, k);
}

// Distance from face k to its first surface along the inward normal above f (>1: empty).
float face_depth(int k, vec3 f) {
    return texelFetch(u_depth, face_texel(k, f), 0).r;
}

// The alpha test of image k (§4.1): q lies in its displaced volume when q's own distance
// from the face, 1 - h, is at least the stored depth.
bool inside_image(int k, vec3 q) {
    vec3 f = face_coords(k, q);
    return 1.0 - f.z >= face_depth(k, f);
}

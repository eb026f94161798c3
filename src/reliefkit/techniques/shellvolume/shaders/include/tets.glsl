// The tetrahedra of a shell, one block of TET_TEXELS texels each in an RGBA32F texture
// (render.py, tet_texels): texels 0-3 vertex f and in .w its height over face f (the plane
// value there, < 0), 4-7 the face planes (face f opposite vertex f, outward unit normal,
// inside <= 0), 8-10 the rows of the object-to-texture map with the tiling folded in
// (s = row . (p, 1) gives the lookup coordinate along u, v, w), 11-14 the shell's smooth
// normal at vertex f, 15.x the longest segment a ray can have in the tetrahedron or in a face
// neighbour it may come from (render.py, ray_reach), 15.y its layer of the base surface's
// material atlas (TexturedShell.surface_layers).
// Everything is relative to the shell's origin (u_model_offset places it, camera.glsl).
#include "scale_free.glsl"
#define TET_TEXELS 16
#define TET_ROW_TEXELS 2048
uniform highp sampler2D u_tets;

vec4 tet_texel(int tet, int k) {
    int i = tet * TET_TEXELS + k;
    return texelFetch(u_tets, ivec2(i % TET_ROW_TEXELS, i / TET_ROW_TEXELS), 0);
}

vec3 tet_vertex(int tet, int corner) { return tet_texel(tet, corner).xyz; }
vec4 tet_plane(int tet, int face) { return tet_texel(tet, 4 + face); }
float tet_ray_reach(int tet) { return tet_texel(tet, 15).x; }
float tet_surface_layer(int tet) { return tet_texel(tet, 15).y; }

// Texture coordinates (u U, v V, w) of shell-local point p in tetrahedron `tet`.
vec3 tet_texture_coords(int tet, vec3 p) {
    vec4 q = vec4(p, 1.0);
    return vec3(dot(tet_texel(tet, 8), q), dot(tet_texel(tet, 9), q), dot(tet_texel(tet, 10), q));
}

// A world-space normal from a texture-space one: gradients transform with the transpose of
// the object-to-texture map (n_vox: voxel units of a level of `size` voxels per tile).
vec3 tet_normal(int tet, vec3 n_vox, vec3 size) {
    vec3 g = n_vox * size;
    vec3 n = g.x * tet_texel(tet, 8).xyz + g.y * tet_texel(tet, 9).xyz
             + g.z * tet_texel(tet, 10).xyz;
    return unit_or(n, vec3(0.0, 1.0, 0.0));
}

// The shell's normal at p, interpolated from its vertices (the paper's interpolated frame,
// §5.3): barycentric weights are plane values over the heights.
vec3 tet_smooth_normal(int tet, vec3 p) {
    vec3 n = vec3(0.0);
    for (int f = 0; f < 4; ++f) {
        vec4 plane = tet_plane(tet, f);
        float weight = (dot(plane.xyz, p) + plane.w) / tet_texel(tet, f).w;
        n += clamp(weight, 0.0, 1.0) * tet_texel(tet, 11 + f).xyz;
    }
    return unit_or(n, vec3(0.0, 1.0, 0.0));
}

// A texture-space normal at p in world space: mapped by the tetrahedron's own affine map
// (right for anisotropic u, v, w scales), then bent from the tetrahedron's flat w direction
// to the smooth normal, so a shell over a curved mesh shades without facets.
vec3 shading_normal(int tet, vec3 n_vox, vec3 size, vec3 p) {
    vec3 n = tet_normal(tet, n_vox, size);
    vec3 flat_w = tet_normal(tet, vec3(0.0, 0.0, 1.0), size);
    vec3 bent = n + (tet_smooth_normal(tet, p) - flat_w) * dot(n, flat_w);
    return unit_or(bent, n);
}

// Corner k (0..2) of face f, counter-clockwise seen from outside (a tetrahedron of positive
// volume), so the front faces are exactly the faces where the rays enter.
int tet_face_corner(int face, int k) {
    const int corners[12] = int[12](1, 2, 3, 0, 3, 2, 0, 1, 3, 0, 2, 1);
    return corners[face * 3 + k];
}

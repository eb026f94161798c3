// The 3D texture and its mip pyramid (filtering.py, §5.2), one sampler per level (up to
// MAX_LEVELS; the levels differ in size, and a 3D texture's levels cannot be uploaded one
// by one through moderngl). Colour + optical density per unit length in u_color<l>, the density normal
// (u, v, w components, voxel units) + glow in u_normal<l>. Lookups use textureLod(.., 0.0)
// so they are valid in any control flow; two levels are blended by hand.
#define MAX_LEVELS 4
uniform highp sampler3D u_color0;
uniform highp sampler3D u_color1;
uniform highp sampler3D u_color2;
uniform highp sampler3D u_color3;
uniform highp sampler3D u_normal0;
uniform highp sampler3D u_normal1;
uniform highp sampler3D u_normal2;
uniform highp sampler3D u_normal3;
uniform int u_levels;          // levels present
uniform vec3 u_level_size[MAX_LEVELS];  // (W, H, D) voxels of each level per tile
uniform bool u_mip;            // pick the level from the screen footprint (else level 0)
uniform float u_density_floor; // textures.density_floor of the shell

vec4 color_level(int level, vec3 s) {
    if (level == 0) return textureLod(u_color0, s, 0.0);
    if (level == 1) return textureLod(u_color1, s, 0.0);
    if (level == 2) return textureLod(u_color2, s, 0.0);
    return textureLod(u_color3, s, 0.0);
}

vec4 normal_level(int level, vec3 s) {
    if (level == 0) return textureLod(u_normal0, s, 0.0);
    if (level == 1) return textureLod(u_normal1, s, 0.0);
    if (level == 2) return textureLod(u_normal2, s, 0.0);
    return textureLod(u_normal3, s, 0.0);
}

// The level of detail of a segment entering at lookup coordinate `s`: log2 of the pixel's
// footprint in level-0 texels along u and v (w is filtered by the pyramid's layering, not
// by the screen). Call in uniform control flow (it takes derivatives).
float volume_lod(vec3 s) {
    vec2 texels = s.xy * u_level_size[0].xy;
    vec2 dx = dFdx(texels), dy = dFdy(texels);
    float footprint = max(length(dx), length(dy));
    float top = float(u_levels - 1);
    return u_mip ? clamp(log2(max(footprint, 1e-8)), 0.0, top) : 0.0;
}

struct VolumeSample {
    vec4 rgba;      // straight colour, optical density per unit length
    vec3 normal;    // voxel units of level `level` (tet_normal converts it)
    float glow;
    vec3 size;      // voxels per tile of that level
};

// Trilinear within the two levels around `lod`, linear between them.
VolumeSample volume_sample(vec3 s, float lod) {
    int lo = int(floor(lod));
    int hi = min(lo + 1, u_levels - 1);
    float f = lod - float(lo);
    vec4 c = color_level(lo, s);
    vec4 n = normal_level(lo, s);
    if (f > 0.0 && hi != lo) {
        c = mix(c, color_level(hi, s), f);
        n = mix(n, normal_level(hi, s), f);
    }
    // colour is stored times density + floor (textures.marched_volume)
    c.rgb /= max(c.a, 0.0) + u_density_floor;
    return VolumeSample(c, n.xyz, n.w, u_level_size[f > 0.5 ? hi : lo]);
}

// The textures hold the optical density sigma = -ln(1 - alpha) per unit length in .a
// (render.py, textures.optical_density): interpolated, it keeps its precision where alpha
// is within a float of 1. A sample of object-space length dt has the optical depth
// sigma dt and the opacity 1 - exp(-sigma dt) = 1 - (1 - alpha)^dt (§4.3).
float sample_optical_depth(float density, float dt) {
    return max(density, 0.0) * dt;
}

float sample_opacity(float density, float dt) {
    return 1.0 - exp(-sample_optical_depth(density, dt));
}

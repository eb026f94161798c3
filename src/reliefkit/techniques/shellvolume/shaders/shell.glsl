// Semi-transparent 3D textures on a shell of tetrahedra (Dufort, Leblanc & Poulin 2005).
// Each tetrahedron is one instance of 12 vertices (its four faces); back faces are culled,
// so every pixel a tetrahedron covers gets one fragment, on the face where its ray enters
// (§4.2). The fragment finds where the ray leaves (the nearest of the other planes, per
// fragment; EXIT_VERTEX: from the paper's per-vertex intersections, interpolated with the
// perspective correction), marches the segment in texture space with u_samples samples
// (§5.1) and corrects each sample's opacity for its length (§4.3).
//   default      colour composited front to back in the instances' (visibility) order
//   OPAQUE       the first point where the segment reaches opacity 0.5, depth-tested
//   AOV_BINS     optical depth of the segment, summed into 16 rank bins (render.py's search
//                for the point where the accumulated opacity reaches 0.5)
//   AOV_FINAL    the tetrahedron found by that search writes that point's position, normal
//   SHADOW_MAP   from the light: depth of the first sample dense enough to cast a shadow
//   PEEL         (with the default) depth peeling, the baseline: only fragments behind the
//                layer peeled before (u_peel_depth) are drawn, the nearest one wins and
//                writes its own depth to attachment 1 for the next layer
//! defines: OPAQUE AOV_BINS AOV_FINAL SHADOW_MAP EXIT_VERTEX LIT SHADOWS PEEL

#if defined VERTEX_SHADER
#include "core:include/camera.glsl"
#include "include/tets.glsl"
uniform vec3 u_model_offset;  // from the shell's origin to the camera's (gl/uniforms.py)
in int in_tet;                // per instance: the tetrahedron drawn at this rank
out vec3 v_local;             // shell-local position on the entry face
flat out int v_tet;
flat out int v_rank;
#if defined EXIT_VERTEX
// Per other plane, a quantity linear over the face whatever the projection (so the
// rasterizer's perspective-correct interpolation is exact): orthographic, the distance t
// from the entry to the plane; perspective, 1 / lambda for the ray eye + lambda (p - eye).
// Planes the ray cannot leave through get a sentinel that never wins.
out vec3 v_exit;
#endif

void main() {
    int face = gl_VertexID / 3;
    vec3 p = tet_vertex(in_tet, tet_face_corner(face, gl_VertexID - 3 * face));
    v_local = p;
    v_tet = in_tet;
    v_rank = gl_InstanceID;
    gl_Position = u_proj * u_view * vec4(p + u_model_offset, 1.0);
#if defined EXIT_VERTEX
    vec3 eye = u_eye - u_model_offset;
    vec3 dir = -u_view_dir;
    int k = 0;
    for (int f = 0; f < 4; ++f) {
        if (f == face) continue;
        vec4 plane = tet_plane(in_tet, f);
        float value;
        if (u_orthographic) {
            float nd = dot(plane.xyz, dir);
            value = nd > 0.0 ? -(dot(plane.xyz, p) + plane.w) / nd : 1e30;
        } else {
            float side = dot(plane.xyz, eye) + plane.w;  // < 0: the eye is inside this plane
            value = side < 0.0 ? -dot(plane.xyz, p - eye) / side : -1e30;
        }
        if (k == 0) v_exit.x = value; else if (k == 1) v_exit.y = value; else v_exit.z = value;
        ++k;
    }
#endif
}
#endif

#if defined FRAGMENT_SHADER
#include "core:include/camera.glsl"
#include "include/tets.glsl"
#include "include/volume.glsl"
#if defined LIT
#include "core:include/shading.glsl"
#endif
#if defined OPAQUE
#include "core:include/frame_outputs.glsl"
#elif defined AOV_BINS
layout(location = 0) out vec4 f_bins0;
layout(location = 1) out vec4 f_bins1;
layout(location = 2) out vec4 f_bins2;
layout(location = 3) out vec4 f_bins3;
#elif !defined SHADOW_MAP
#include "core:include/transparency.glsl"
#endif
#include "core:include/surface_tint.glsl"
uniform vec3 u_model_offset;
uniform int u_samples;              // samples per segment (§5.1)
uniform bool u_clip_opaque;         // stop segments at the opaque pass's surfaces
uniform highp sampler2D u_opaque_depth;
uniform float u_time;               // animation time (the texture sways with it)
uniform float u_sway;               // sway amplitude in texture tiles (0: still)
uniform vec2 u_tile;                // the texture's repetitions over the uvs
#if defined AOV_BINS || defined AOV_FINAL
uniform highp sampler2D u_search;   // per pixel, see render.py (half_opacity_search)
#endif
#if defined SHADOW_MAP
uniform float u_shadow_length;      // length over which a sample must reach opacity 0.5
#endif
#if defined PEEL
uniform highp sampler2D u_peel_depth;  // .xy: gl_FragCoord.z and tetrahedron peeled before
#endif
#if defined SHADOWS
uniform highp sampler2D u_shadow_map;
uniform mat4 u_light_matrix;        // shell-local point -> the light's clip space
uniform float u_shadow_bias;       // window depth: the depth buffer's rounding
uniform float u_shadow_texel;      // a shadow-map texel's width, world units
#endif
in vec3 v_local;
flat in int v_tet;
flat in int v_rank;
#if defined EXIT_VERTEX
in vec3 v_exit;
#endif

vec3 eye_local() { return u_eye - u_model_offset; }

vec3 ray_direction() {
    return u_orthographic ? -u_view_dir : unit_or(v_local - eye_local(), -u_view_dir);
}

// Distance from the entry point to where the ray leaves the tetrahedron.
float exit_distance(vec3 dir) {
#if defined EXIT_VERTEX
    if (u_orthographic) return max(min(min(v_exit.x, v_exit.y), v_exit.z), 0.0);
    float mu = max(max(v_exit.x, v_exit.y), v_exit.z);
    return mu > 0.0 ? max(1.0 / mu - 1.0, 0.0) * scale_free_length(v_local - eye_local()) : 0.0;
#else
    float t = 1e30;
    for (int f = 0; f < 4; ++f) {
        vec4 plane = tet_plane(v_tet, f);
        float nd = dot(plane.xyz, dir);
        if (nd > 1e-12) t = min(t, -(dot(plane.xyz, v_local) + plane.w) / nd);
    }
    return t < 1e30 ? max(t, 0.0) : 0.0;
#endif
}

// Distance to the opaque surface drawn at this pixel (1e30: none).
float opaque_distance(vec3 dir) {
    if (!u_clip_opaque) return 1e30;
    float z = texelFetch(u_opaque_depth, ivec2(gl_FragCoord.xy), 0).r;
    if (z >= 1.0) return 1e30;
    vec3 p = unproject(fragment_ndc(), 2.0 * z - 1.0) - u_model_offset;
    return max(dot(p - v_local, dir), 0.0);
}

// The base surface's own colour under lookup coordinate s (the tiling undone: the base's
// uv), from the tetrahedron's material layer (render.py); the volume's colours are
// multiplied by it.
vec3 base_tint(vec3 s) { return surface_tint(s.xy / u_tile, tet_surface_layer(v_tet)); }

// The texture moving over time: strands sway, more at the top of the shell.
vec3 animated(vec3 s) {
    float w = clamp(s.z, 0.0, 1.0);
    float phase = 6.2831853 * (u_time + 0.25 * s.y);
    return s + vec3(u_sway * w * w * sin(phase), u_sway * w * w * cos(phase), 0.0);
}

#if defined SHADOWS
// 1 where the light reaches the surface a sample at shell-local p stands for, 0 behind the
// first dense voxel the light meets. That surface lies between the sample before (`back`
// along the ray) and this one, and the shadow map's nearest texel holds the depth of a light
// ray up to half a texel diagonal beside p, on a surface sloped by the angle to the light:
// tested at the sample before, lifted off the surface along its normal `n` by one texel,
// neither error darkens a lit surface (no shadow acne).
float light_visibility(vec3 p, vec3 dir, float back, vec3 n) {
    vec3 receiver = p - dir * back + n * u_shadow_texel;
    vec4 q = u_light_matrix * vec4(receiver, 1.0);
    vec3 c = q.xyz / q.w * 0.5 + 0.5;
    if (any(lessThan(c.xy, vec2(0.0))) || any(greaterThan(c.xy, vec2(1.0)))) return 1.0;
    return c.z - u_shadow_bias <= textureLod(u_shadow_map, c.xy, 0.0).r ? 1.0 : 0.0;
}
#endif

// Colour of a sample at shell-local p, the sample before `back` behind it along `dir`
// (unlit: the stored colour).
vec3 sample_color(VolumeSample v, vec3 p, vec3 dir, float back) {
#if defined LIT
    vec3 n = shading_normal(v_tet, v.normal, v.size, p);
    float lit = 1.0;
#if defined SHADOWS
    lit = light_visibility(p, dir, back, n);
#endif
    return shade_phong(v.rgba.rgb, n, -dir, lit);
#else
    return v.rgba.rgb;
#endif
}

void main() {
    vec3 dir = ray_direction();
    vec3 s_in = tet_texture_coords(v_tet, v_local);
    float lod = volume_lod(s_in);  // derivatives first, before any fragment is discarded
    float len = min(exit_distance(dir), opaque_distance(dir));
    if (!(len > 0.0)) discard;
#if defined PEEL
    // behind the layer before in (depth, tetrahedron) order: fragments at exactly equal
    // depth (rays through a shared vertex) are peeled one after the other, lowest index
    // first (the depth test keeps the first drawn of equal depths; instances go by index)
    vec2 before = texelFetch(u_peel_depth, ivec2(gl_FragCoord.xy), 0).xy;
    if (gl_FragCoord.z < before.x || (gl_FragCoord.z == before.x && float(v_tet) <= before.y))
        discard;
#endif
#if defined AOV_BINS
    vec2 range = texelFetch(u_search, ivec2(gl_FragCoord.xy), 0).xy;
    float rank = float(v_rank);
    if (rank < range.x || rank >= range.y) discard;
#elif defined AOV_FINAL
    vec2 search = texelFetch(u_search, ivec2(gl_FragCoord.xy), 0).xy;
    if (float(v_rank) != search.x) discard;
#endif
    vec3 p_out = v_local + dir * len;
    vec3 s_out = tet_texture_coords(v_tet, p_out);
    int n = max(u_samples, 1);
    float dt = len / float(n);
    vec3 color = vec3(0.0);
    float opacity = 0.0, optical_depth = 0.0;
    for (int k = 0; k < n; ++k) {
        float lambda = (float(k) + 0.5) / float(n);
        vec3 s_at = mix(s_in, s_out, lambda);
        VolumeSample v = volume_sample(animated(s_at), lod);
        v.rgba.rgb *= base_tint(s_at);
#if defined SHADOW_MAP
        if (sample_opacity(v.rgba.a, u_shadow_length) >= 0.5) {
            gl_FragDepth = window_depth(mix(v_local, p_out, lambda) + u_model_offset);
            return;
        }
#elif defined AOV_BINS
        optical_depth += sample_optical_depth(v.rgba.a, dt);
#elif defined AOV_FINAL
        optical_depth += sample_optical_depth(v.rgba.a, dt);
        if (optical_depth >= search.y || k == n - 1) {
            vec3 world = mix(v_local, p_out, lambda) + u_model_offset;
            write_transparent_at(vec3(0.0), 0.0, world,
                                 shading_normal(v_tet, v.normal, v.size, world - u_model_offset),
                                 true);
            return;
        }
#else
        vec3 p = mix(v_local, p_out, lambda);
        float a = sample_opacity(v.rgba.a, dt);
        // the sample before: in this segment, or the last one of the tetrahedron before
        float back = k > 0 ? dt : 0.5 * (dt + tet_ray_reach(v_tet) / float(n));
        color += (1.0 - opacity) * (a * sample_color(v, p, dir, back) + v.glow * v.rgba.rgb * dt);
        opacity += (1.0 - opacity) * a;
#if defined OPAQUE
        if (opacity >= 0.5) {
            vec3 world = p + u_model_offset;
            write_frame(vec4(color / opacity, 1.0), world,
                        shading_normal(v_tet, v.normal, v.size, p));
            gl_FragDepth = window_depth(world);
            return;
        }
#endif
#endif
    }
#if defined AOV_BINS
    float bins[16];
    for (int k = 0; k < 16; ++k) {
        float threshold = range.x + ceil((range.y - range.x) * float(k + 1) / 16.0);
        bins[k] = rank < threshold ? optical_depth : 0.0;
    }
    f_bins0 = vec4(bins[0], bins[1], bins[2], bins[3]);
    f_bins1 = vec4(bins[4], bins[5], bins[6], bins[7]);
    f_bins2 = vec4(bins[8], bins[9], bins[10], bins[11]);
    f_bins3 = vec4(bins[12], bins[13], bins[14], bins[15]);
#elif defined OPAQUE || defined SHADOW_MAP || defined AOV_FINAL
    discard;
#else
    f_color = vec4(color, opacity);  // premultiplied: the pass composites with "under"
    f_position = vec4(0.0);
    f_normal = vec4(0.0);
#if defined PEEL
    f_position = vec4(gl_FragCoord.z, float(v_tet), 0.0, 0.0);  // what the next layer is behind
#endif
#endif
}
#endif

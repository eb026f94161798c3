// Octahedral impostor: one camera-facing quad over the bounding sphere, billboarded in the
// vertex shader. Per fragment, the three grid frames around the view direction on the
// octahedral map (octahedral.py holds the same functions) are each looked up along the
// pixel's ray where it meets the frame's stored depth (u_parallax_steps samples front to
// back and a linear step between the two around the crossing; 0: where the ray crosses
// the frame's plane), and blended by their barycentric weights times their coverage
// (the instrumented pass counts the depth samples). The blended coverage is tested at 0.5; the ray distances of the frames
// that agree with the heaviest one give the surface point (position, gl_FragDepth); the
// blended object-space normals light it.
// SHADOWS: lit only where the light's shadow map (drawn with SHADOW_MAP: coverage and depth
// only, the quad facing the light) sees it.
// INSTANCED (render/instancing.py): each instance's quad faces the camera from its own centre;
// the frames are chosen and looked up in the object as it is (the view direction and the
// pixel's ray turned back by the instance's yaw and scale), the hit and its normal brought out.
//! defines: SHADOWS SHADOW_MAP INSTANCED

#include "core:include/camera.glsl"
#include "core:include/instancing.glsl"
uniform vec3 u_model_offset;  // the bounding sphere's centre, relative to the camera's origin
uniform float u_radius;       // the bounding sphere's radius

// From a sphere's centre (camera-relative) towards the viewer.
vec3 towards_viewer_from(vec3 center) {
    return u_orthographic ? u_view_dir : normalize(u_eye - center);
}

// The reference up of a view along -d: +y, -z at the poles (octahedral.frame_basis).
vec3 reference_up(vec3 d) {
    return abs(d.y) > 0.999 ? vec3(0.0, 0.0, -1.0) : vec3(0.0, 1.0, 0.0);
}

#if defined VERTEX_SHADER
in vec2 in_corner;  // (+-1, +-1)
out vec3 v_world;
flat out vec3 v_center;  // this instance's centre, camera-relative

void main() {
    v_center = placed(vec3(0.0), u_model_offset);
    float radius = instance_scale() * u_radius;
    vec3 d = towards_viewer_from(v_center);
    vec3 right = normalize(cross(reference_up(d), d));
    vec3 up = cross(d, right);
    // The quad through the centre that holds the sphere's outline: its radius seen from
    // the eye (orthographic), or where the sphere's tangent cone meets the quad's plane.
    float half_side = radius;
    if (!u_orthographic) {
        float dist = length(u_eye - v_center);
        half_side = radius * dist / sqrt(max(dist * dist - radius * radius,
                                              1e-4 * dist * dist));
    }
    v_world = v_center + (in_corner.x * right + in_corner.y * up) * half_side;
    gl_Position = u_proj * u_view * vec4(v_world, 1.0);
}
#endif

#if defined FRAGMENT_SHADER
#include "core:include/shading.glsl"
#if !defined SHADOW_MAP
#include "core:include/frame_outputs.glsl"
#include "core:include/iterations.glsl"
#endif
#if defined SHADOWS
#include "core:include/shadow_map.glsl"
#endif
uniform sampler2D u_color_atlas;   // sRGB: linear base colour, alpha = coverage
uniform sampler2D u_normal_atlas;  // object-space normal as (n + 1) / 2
uniform sampler2D u_depth_atlas;   // height above the frame's plane as (h / radius + 1) / 2
uniform int u_grid;                // frames on the grid's side
uniform bool u_hemi;               // the hemi map (else the full one)
uniform float u_frame_radius;      // half the side of the square a frame covers
uniform float u_frame_texels;      // texels on a frame's side
uniform int u_parallax_steps;
in vec3 v_world;
flat in vec3 v_center;

vec2 sign_not_zero(vec2 v) {
    return vec2(v.x >= 0.0 ? 1.0 : -1.0, v.y >= 0.0 ? 1.0 : -1.0);
}

// Direction -> point of the map in [-1, 1]^2 (octahedral.encode).
vec2 octahedral_encode(vec3 d) {
    if (u_hemi) d.y = max(d.y, 0.0);
    d /= max(abs(d.x) + abs(d.y) + abs(d.z), 1e-12);
    if (u_hemi) return vec2(d.x + d.z, d.z - d.x);
    if (d.y < 0.0) return (1.0 - abs(d.zx)) * sign_not_zero(d.xz);
    return d.xz;
}

// Point of the map -> unit direction (octahedral.decode).
vec3 octahedral_decode(vec2 p) {
    vec3 d;
    if (u_hemi) {
        float x = 0.5 * (p.x - p.y), z = 0.5 * (p.x + p.y);
        d = vec3(x, 1.0 - abs(x) - abs(z), z);
    } else {
        d = vec3(p.x, 1.0 - abs(p.x) - abs(p.y), p.y);
        if (d.y < 0.0) d.xz = (1.0 - abs(p.yx)) * sign_not_zero(p);
    }
    return normalize(d);
}

// The three frames around direction d and their barycentric weights (octahedral.blend_frames).
void blend_frames(vec3 d, out ivec2 f0, out ivec2 f1, out ivec2 f2, out vec3 w) {
    float last = float(u_grid - 1);
    vec2 g = (octahedral_encode(d) + 1.0) * 0.5 * last;
    vec2 cell = clamp(floor(g), 0.0, last - 1.0);
    vec2 f = clamp(g - cell, 0.0, 1.0);
    ivec2 c = ivec2(cell);
    if (f.x + f.y <= 1.0) {
        f0 = c; f1 = c + ivec2(1, 0); f2 = c + ivec2(0, 1);
        w = vec3(1.0 - f.x - f.y, f.x, f.y);
    } else {
        f0 = c + ivec2(1, 1); f1 = c + ivec2(0, 1); f2 = c + ivec2(1, 0);
        w = vec3(f.x + f.y - 1.0, 1.0 - f.x, 1.0 - f.y);
    }
}

// Atlas coordinate of point p (relative to the centre) in frame `cell` with axes right, up;
// kept half a texel inside the frame so filtering never reads a neighbour.
vec2 frame_uv(ivec2 cell, vec3 p, vec3 right, vec3 up) {
    vec2 st = vec2(dot(p, right), dot(p, up)) / u_frame_radius;
    vec2 inside = clamp(0.5 * st + 0.5, 0.5 / u_frame_texels, 1.0 - 0.5 / u_frame_texels);
    return (vec2(cell) + inside) / float(u_grid);
}

float height_at(vec2 uv) {
    return (2.0 * textureLod(u_depth_atlas, uv, 0.0).r - 1.0) * u_radius;
}

// Frame `cell` looked up along the ray origin + t dir (origin relative to the centre): its
// coverage, colour and normal there and the ray distance t of its surface; `samples`
// counts the depth samples taken. Without steps,
// where the ray crosses the frame's plane; with u_parallax_steps, the ray is walked through
// the frame's height range front to back, and between the last sample above the stored
// surface and the first below it the crossing is interpolated linearly.
void look_up(ivec2 cell, vec3 origin, vec3 dir, out float coverage, out vec3 color,
             out vec3 normal, out float t, inout int samples) {
    vec3 d = octahedral_decode(vec2(cell) * 2.0 / float(u_grid - 1) - 1.0);
    vec3 right = normalize(cross(reference_up(d), d));
    vec3 up = cross(d, right);
    float facing = min(dot(dir, d), -0.05);  // the ray runs against the frame's direction
    float above = dot(origin, d);            // the ray origin's height above the frame
    t = -above / facing;                     // where the ray crosses the frame's plane
    if (u_parallax_steps > 0) {
        float step_height = 2.0 * u_radius / float(u_parallax_steps);
        float ray_height = u_radius;         // the front of the frame's height range
        float gap = u_radius;                // ray height - stored height, last sample
        float previous_gap = gap;
        for (int s = 0; s <= u_parallax_steps; ++s) {
            t = (ray_height - above) / facing;
            gap = ray_height - height_at(frame_uv(cell, origin + t * dir, right, up));
            ++samples;
            if (gap <= 0.0) break;
            previous_gap = gap;
            ray_height -= step_height;
        }
        if (gap <= 0.0 && previous_gap > 0.0 && ray_height < u_radius) {
            float back = step_height * gap / (previous_gap - gap);  // < 0: step back up
            t = (ray_height - back - above) / facing;
        }
    }
    vec2 uv = frame_uv(cell, origin + t * dir, right, up);
    t = (height_at(uv) - above) / facing;
    coverage = textureLod(u_color_atlas, uv, 0.0).a;
    color = texture(u_color_atlas, uv).rgb;  // mipmapped: control flow is uniform again
    normal = 2.0 * texture(u_normal_atlas, uv).rgb - 1.0;
}

void main() {
    // In the object as it is (the identity without INSTANCED): the view direction, the
    // pixel's ray from the quad, relative to the sphere's centre.
    vec3 d = rotate_to_object(towards_viewer_from(v_center));
    ivec2 f0, f1, f2;
    vec3 w;
    blend_frames(d, f0, f1, f2, w);
    vec3 quad_point = to_object(v_world);
    vec3 origin = quad_point - u_model_offset;
    vec3 dir = rotate_to_object(u_orthographic ? -u_view_dir : normalize(v_world - u_eye));
    vec3 a, c0, c1, c2, n0, n1, n2, t;
    int samples = 0;
    look_up(f0, origin, dir, a.x, c0, n0, t.x, samples);
    look_up(f1, origin, dir, a.y, c1, n1, t.y, samples);
    look_up(f2, origin, dir, a.z, c2, n2, t.z, samples);
    vec3 wa = w * a;
    float coverage = wa.x + wa.y + wa.z;
    if (coverage < 0.5) {
#if defined COUNT_ITERATIONS && !defined SHADOW_MAP
        write_counted_miss(samples);
        return;
#else
        discard;
#endif
    }
    wa /= coverage;
    // The surface point: the frames' ray distances averaged over those that agree with the
    // heaviest frame's to a few texels (averaging across an occluding edge, where frames
    // see different surfaces, would float a surface between them).
    float heaviest = wa.x >= max(wa.y, wa.z) ? t.x : (wa.y >= wa.z ? t.y : t.z);
    vec3 agree = wa * step(abs(t - heaviest), vec3(4.0 * 2.0 * u_frame_radius / u_frame_texels));
    vec3 world = to_instance(quad_point + dot(agree, t) / (agree.x + agree.y + agree.z) * dir);
    gl_FragDepth = window_depth(world);
#if !defined SHADOW_MAP
    vec3 base = wa.x * c0 + wa.y * c1 + wa.z * c2;
    vec3 n = wa.x * n0 + wa.y * n1 + wa.z * n2;
    n = rotate_to_instance(length(n) > 1e-3 ? normalize(n) : d);  // 0: opposite normals averaged
    float lit = 1.0;
#if defined SHADOWS
    lit = light_visibility(world - u_model_offset, dot(n, u_light_dir) >= 0.0 ? n : -n);
#endif
    write_frame(vec4(shade_phong(base, n, towards_eye(world), lit), 1.0), world, n);
    write_iterations(samples, 0, true);
#endif
}
#endif

// Relief texture (Baboud & Decoret 2006): rasterize the box (or reverse frustum) and
// intersect each pixel's ray with the heightfield in normalized box coordinates.
// INSTANCED: at every placement of render/instancing.py; the ray is followed in the object as
// it is (core:include/instancing.glsl), the hit, its normal and the lighting are the
// instance's.
//! defines: METHOD_BINARY METHOD_EXACT METHOD_ROBUST METHOD_MAXMIP METHOD_CONE SAFETY_OCTANTS WRITE_DEPTH SHADOWS INSTANCED

#if defined VERTEX_SHADER
#include "core:include/camera.glsl"
#include "core:include/instancing.glsl"
in vec3 in_position;   // proxy vertex relative to its origin (render.py relief_proxy)
uniform vec3 u_model_offset;  // from the proxy's origin to the camera's (gl/uniforms.py)

void main() {
    gl_Position = u_proj * u_view * vec4(placed(in_position, u_model_offset), 1.0);
}
#endif

#if defined FRAGMENT_SHADER
#include "include/intersect.glsl"
#include "core:include/camera.glsl"
#include "core:include/raybox.glsl"
#include "core:include/shading.glsl"
#include "core:include/frame_outputs.glsl"
#include "core:include/iterations.glsl"
#include "core:include/instancing.glsl"
uniform mat4 u_world_to_box;
uniform mat4 u_box_to_world;
uniform sampler2D u_color;    // sRGB base colour (decoded to linear by the sampler)
uniform sampler2D u_normal;   // world-space normals
uniform vec2 u_normal_decode; // (scale, bias) from the sampled value to the normal

vec3 to_box(vec3 world) {
    vec4 b = u_world_to_box * vec4(world, 1.0);
    return b.xyz / b.w;
}

vec3 to_world(vec3 box) {
    vec4 w = u_box_to_world * vec4(box, 1.0);
    return w.xyz / w.w;
}

// The point of the ray through NDC (x, y) at NDC z, in the object as it is: the world of
// the box matrices and the baked normals (an instance's is placed, include/instancing.glsl).
vec3 object_ray_point(vec2 ndc_xy, float ndc_z) {
    return to_object(unproject(ndc_xy, ndc_z));
}

// The axis (0, 1, 2) of the box face nearest to box point p.
int box_face_axis(vec3 p) {
    vec3 dist = min(p, 1.0 - p);
    return dist.x < dist.y ? (dist.x < dist.z ? 0 : 2) : (dist.y < dist.z ? 1 : 2);
}

// The world plane through box point `hit` whose box normal is nb: box_h = W x_h, so
// (nb, -nb.hit) . box_h = (W^T plane) . x_h; its xyz is the world normal (unnormalized).
vec4 world_plane(vec3 hit, vec3 nb) {
    return transpose(u_world_to_box) * vec4(nb, -dot(nb, hit));
}

// World normal of the box face that box point p lies on (the side walls of the solid).
vec3 box_face_normal(vec3 p) {
    int k = box_face_axis(p);
    vec3 nb = vec3(0.0);
    nb[k] = p[k] < 0.5 ? -1.0 : 1.0;  // out of the box
    return normalize(world_plane(p, nb).xyz);
}

// The world tangent plane of the surface at box point `hit`: the box face the ray entered by
// (`on_face`) or the bilinear heightfield's own.
vec4 tangent_plane(vec3 hit, bool on_face) {
    vec3 nb = vec3(0.0);
    if (on_face) nb[box_face_axis(hit)] = 1.0;
    else nb = vec3(-hf_slope(hit.xy * vec2(u_hf_size)) * vec2(u_hf_size), 1.0);
    return world_plane(hit, nb);
}

// A heightfield hit on a surface steeper than 75 degrees from the box's h lines is on a
// wall: a step between texels of different heights; below 60 degrees it is not. In between
// the two normals are blended, so no hard switch draws a seam or a dot.
const float WALL_COS = 0.2588, SLOPE_COS = 0.5;

// The shading normal at a hit on the heightfield (`plane`: its tangent_plane). The bake saw
// the topmost surface at texel centres, so a wall that the bilinear surface builds between a
// high texel and a low one (a box's side, a roof's edge) has no normal of its own in the map:
// the lookup there gives the top's or the floor's, or a blend of them with a steep texel's
// (bright dots and stripes on walls). On a wall the heightfield's own normal is the surface's;
// elsewhere the baked one keeps the mesh's smooth shading and detail, and where a real surface
// is that steep the two agree.
vec3 baked_normal(vec2 uv) {
    return normalize(textureLod(u_normal, uv, 0.0).xyz * u_normal_decode.x
                     + u_normal_decode.y);  // not mipmapped
}

vec3 heightfield_normal(vec3 hit, vec4 plane) {
    vec3 baked = baked_normal(hit.xy);
    vec3 geometric = normalize(plane.xyz);
    vec3 level = normalize(world_plane(hit, vec3(0.0, 0.0, 1.0)).xyz);  // along the h lines
    if (dot(geometric, baked) < 0.0) geometric = -geometric;  // the same side, up the h lines
    float wall = 1.0 - smoothstep(WALL_COS, SLOPE_COS, abs(dot(geometric, level)));
    return normalize(mix(baked, geometric, wall));
}

// The colour's texture gradients at box point `hit`: where the rays of the next pixels right
// and up meet the surface's tangent plane there (`plane`, ray differentials), in box (u, v).
// The plane is the box face's or the bilinear surface's, not the shading normal's, which is
// smoothed across edges. Hardware derivatives would be taken from the 2x2 quad's other
// fragments, whose rays end on other surfaces or were discarded after their own march:
// blurred colours along every depth edge, and different colours from two methods that find
// the same hits.
void hit_gradients(vec2 ndc, vec3 hit, vec4 plane, out vec2 dx, out vec2 dy) {
    vec2 pixel = 2.0 / u_viewport;
    vec2 uv[2];
    for (int i = 0; i < 2; ++i) {
        vec2 next = ndc + (i == 0 ? vec2(pixel.x, 0.0) : vec2(0.0, pixel.y));
        vec3 o = object_ray_point(next, -1.0), e = object_ray_point(next, 1.0);
        float fo = dot(plane, vec4(o, 1.0)), fe = dot(plane, vec4(e, 1.0));
        float t = fo != fe ? clamp(fo / (fo - fe), -1e6, 1e6) : 1e6;  // parallel: far away
        uv[i] = clamp(to_box(mix(o, e, t)).xy - hit.xy, -1.0, 1.0);
    }
    dx = uv[0];
    dy = uv[1];
}

void main() {
    vec2 ndc = fragment_ndc();
    // the pixel's ray from the near to the far plane inside the box: s = 0 where it enters
    // (or at the near plane), s = 1 where it leaves; a projective box_to_world maps lines to
    // lines, so it stays a line there, and no proxy depth is involved
    vec3 a, b;
    if (!box_segment(u_world_to_box, object_ray_point(ndc, -1.0), object_ray_point(ndc, 1.0),
                     a, b)) discard;
    vec3 d = b - a;
    if (dot(d, d) == 0.0) discard;
    float s0 = 0.0, s1 = 1.0;
    bool entered_side = a.z < 1.0 && a.z > 0.0 && (min(a.x, a.y) <= 0.0 || max(a.x, a.y) >= 1.0);
    vec3 scale = vec3(vec2(u_hf_size), 1.0);  // box -> texel coordinates
    vec3 o_t = a * scale, d_t = d * scale;
    int iters = 0;
    float s_hit;
    if (!relief_intersect(o_t, d_t, s0, s1, s_hit, iters)) {
#if defined COUNT_ITERATIONS
        write_counted_miss(iters);  // count the work of a miss without drawing it
        return;
#else
        discard;
#endif
    }
    vec3 hit_box = clamp(a + s_hit * d, 0.0, 1.0);
    vec3 hit = to_world(hit_box);
    bool at_entry = s_hit <= s0;  // on the face the ray entered by
    bool on_face = at_entry && (entered_side || a.z <= 0.0);
    vec4 plane = tangent_plane(hit_box, on_face);
    vec3 n;
    if (at_entry && entered_side) n = box_face_normal(hit_box);  // a side wall of the box
    else if (on_face) n = baked_normal(hit_box.xy);  // underside
    else n = heightfield_normal(hit_box, plane);
    vec2 uv_dx, uv_dy;
    hit_gradients(ndc, hit_box, plane, uv_dx, uv_dy);
    vec4 base = textureGrad(u_color, hit_box.xy, uv_dx, uv_dy);
    vec3 to_eye = rotate_to_object(towards_eye(to_instance(hit)));
    if (dot(n, to_eye) < 0.0) n = -n;  // seen from behind (side walls): shade the visible side

    float lit = 1.0;
    int shadow_iters = 0;
#if defined SHADOWS
    // Cast from where the light enters the box towards the hit: that ray is unblocked until
    // its first hit, as the safety radii assume; the point is lit if that first hit is it.
    vec3 light_dir = rotate_to_object(u_light_dir);
    vec3 towards_light = to_box(hit + light_dir * 1e-3 * length(u_box_to_world[0].xyz)) - hit_box;
    vec3 ld = -towards_light;
    vec2 lspan = unit_cube_interval(hit_box, ld);   // s = 0 at the hit; entry at lspan.x < 0
    vec3 l_origin = hit_box + lspan.x * ld;
    // stop 1.5 texels short of the hit so the surface does not shadow itself
    float texel_len = length(ld * vec3(scale.xy, float(max(u_hf_size.x, u_hf_size.y))));
    float l_end = -lspan.x - 1.5 / max(texel_len, 1e-20);
    float l_hit;
    if (dot(n, light_dir) <= 0.0) {
        lit = 0.0;  // facing away from the light
    } else if (l_end > 0.0 &&
               relief_intersect(l_origin * scale, ld * scale, 0.0, l_end, l_hit, shadow_iters)) {
        lit = 0.0;
    }
#endif
    vec3 placed_hit = to_instance(hit), placed_n = rotate_to_instance(n);
    write_frame(vec4(shade_phong(base.rgb, placed_n, rotate_to_instance(to_eye), lit), 1.0),
                placed_hit, placed_n);  // a hit is opaque
    write_iterations(iters, shadow_iters, true);
#if defined WRITE_DEPTH
    gl_FragDepth = window_depth(placed_hit);
#elif defined COUNT_ITERATIONS
    gl_FragDepth = gl_FragCoord.z;  // the counted-miss path writes depth, so every path does
#endif
}
#endif

// Clipping rays to boxes: the unit cube in its own (possibly projective) coordinates.

// Parameter interval where o + s * d lies in the unit cube (empty when s_exit < s_enter).
vec2 unit_cube_interval(vec3 o, vec3 d) {
    vec3 inv = 1.0 / d;
    vec3 ta = (vec3(0.0) - o) * inv, tb = (vec3(1.0) - o) * inv;
    vec3 lo = min(ta, tb), hi = max(ta, tb);
    return vec2(max(max(lo.x, lo.y), lo.z), min(min(hi.x, hi.y), hi.z));
}

// Clip t in [0, 1] of the homogeneous segment a + t (b - a) to one halfspace f(X) >= 0.
void clip_linear(float fa, float fb, inout vec2 span) {
    if (fa < 0.0 && fb < 0.0) { span = vec2(1.0, 0.0); return; }
    if (fa >= 0.0 && fb >= 0.0) return;
    float t = fa / (fa - fb);
    if (fa < 0.0) span.x = max(span.x, t); else span.y = min(span.y, t);
}

// The segment between world points w0 and w1 clipped to the unit cube of box coordinates
// X = world_to_box * w, in homogeneous coordinates (0 <= x, y, z <= w, w > 0), so a
// projective world_to_box needs no care about its singular plane. Returns false when the
// segment misses the box; else the clipped end points in box coordinates.
bool box_segment(mat4 world_to_box, vec3 w0, vec3 w1, out vec3 p0, out vec3 p1) {
    vec4 a = world_to_box * vec4(w0, 1.0);
    vec4 b = world_to_box * vec4(w1, 1.0);
    vec2 span = vec2(0.0, 1.0);
    clip_linear(a.w, b.w, span);
    for (int k = 0; k < 3; ++k) {
        clip_linear(a[k], b[k], span);
        clip_linear(a.w - a[k], b.w - b[k], span);
    }
    p0 = vec3(0.0);
    p1 = vec3(0.0);
    if (span.y <= span.x) return false;
    vec4 h0 = mix(a, b, span.x), h1 = mix(a, b, span.y);
    p0 = clamp(h0.xyz / h0.w, 0.0, 1.0);
    p1 = clamp(h1.xyz / h1.w, 0.0, 1.0);
    return true;
}

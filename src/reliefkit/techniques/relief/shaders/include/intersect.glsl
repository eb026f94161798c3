// Ray vs heightfield, in texel coordinates: p(s) = o + s * d for s in [s0, s1].
// One method is compiled in (Baboud & Decoret 2006, section 3):
//   METHOD_BINARY  fixed linear steps, then binary search (Policarpo et al. 2005)
//   METHOD_EXACT   walk from centreline to centreline (Amanatides-Woo in 2D, section 3.3)
//   METHOD_ROBUST  jump by safety radii along the major axis, then binary search (section 3.4)
//   METHOD_MAXMIP  descend a maximum mipmap (Tevs et al. 2008), the exact walk in its cells
//   METHOD_CONE    relaxed cone stepping (Policarpo & Oliveira, GPU Gems 3 ch. 18)
// `iters` counts loop iterations (one height evaluation each) for the benchmarks.
#include "core:include/heightfield.glsl"

#define HARD_CAP 16384
uniform int u_linear_steps;   // binary: number of fixed pre-steps
uniform int u_binary_steps;   // binary search steps once the hit is bracketed
uniform int u_max_iterations; // bound on every walk (besides HARD_CAP)

// Bisection between sa (above) and sb (below), then the linear root of the last bracket.
float refine_hit(vec3 o, vec3 d, float sa, float sb, inout int iters) {
    float fa = hf_above(o + sa * d), fb = hf_above(o + sb * d);
    for (int k = 0; k < HARD_CAP && k < u_binary_steps; ++k) {
        float sm = 0.5 * (sa + sb);
        float fm = hf_above(o + sm * d);
        iters++;
        if (fm < 0.0) { sb = sm; fb = fm; } else { sa = sm; fa = fm; }
    }
    return (fa - fb) > 0.0 ? sa + (sb - sa) * fa / (fa - fb) : sb;
}

#if defined METHOD_BINARY
bool relief_intersect(vec3 o, vec3 d, float s0, float s1, out float s_hit, inout int iters) {
    s_hit = s0;
    if (hf_above(o + s0 * d) < 0.0) return true;
    float ds = (s1 - s0) / float(max(u_linear_steps, 1));
    float sa = s0;
    for (int k = 1; k < HARD_CAP && k <= u_linear_steps; ++k) {
        float sb = (k == u_linear_steps) ? s1 : s0 + float(k) * ds;
        iters++;
        if (hf_above(o + sb * d) < 0.0) {
            s_hit = refine_hit(o, d, sa, sb, iters);
            return true;
        }
        sa = sb;
    }
    return false;
}
#endif

#if defined METHOD_EXACT || defined METHOD_ROBUST || defined METHOD_MAXMIP || defined METHOD_CONE
// Parameter of the next centreline (x = k + 0.5) strictly after coordinate x moving with dx.
float next_centerline(float x, float ox, float dx) {
    if (dx == 0.0) return 3.0e38;
    float c = dx > 0.0 ? floor(x - 0.5) + 1.5 : ceil(x - 0.5) - 0.5;
    return (c - ox) / dx;
}

// Parameters of the next vertical and horizontal centrelines strictly after o + s d, and
// the parameter steps between consecutive ones.
vec2 next_crossings(vec3 o, vec3 d, float s) {
    vec3 p = o + s * d;
    return vec2(next_centerline(p.x, o.x, d.x), next_centerline(p.y, o.y, d.y));
}

vec2 crossing_steps(vec3 d) {
    return vec2(d.x != 0.0 ? 1.0 / abs(d.x) : 3.0e38, d.y != 0.0 ? 1.0 / abs(d.y) : 3.0e38);
}

uniform bool u_quadratic_cells;  // test the exact quadratic inside each cell (see below)

// The bilinear cell that holds the ray between two consecutive centreline crossings
// sa < sb: its corner texels lo and hi, the ray's cell coordinates a at sa and their rate dd
// (in the border strips the clamped coordinate is constant and the strip has one column or
// row: lo = hi there).
void ray_cell(vec3 o, vec3 d, float sa, float sb, out ivec2 lo, out ivec2 hi, out vec2 a,
              out vec2 dd) {
    vec2 last = vec2(u_hf_size) - 1.0;
    vec2 qm = o.xy + 0.5 * (sa + sb) * d.xy - 0.5;          // the segment's middle
    vec2 c = floor(clamp(qm, vec2(0.0), last));
    bvec2 strip = bvec2(qm.x <= 0.0 || qm.x >= last.x, qm.y <= 0.0 || qm.y >= last.y);
    a = o.xy + sa * d.xy - 0.5 - c;
    dd = d.xy;
    if (strip.x) { a.x = 0.0; dd.x = 0.0; }
    if (strip.y) { a.y = 0.0; dd.y = 0.0; }
    lo = ivec2(c);
    hi = ivec2(strip.x ? lo.x : lo.x + 1, strip.y ? lo.y : lo.y + 1);
}

// F(s) = z(s) - height(s) in a cell with corner heights h = (h00, h10, h01, h11), the ray at
// height za and cell coordinates a at t = 0: F = c.x + c.y t + c.z t^2, exactly. A cell whose
// corners are all 0 is empty space (hf_above): it is never hit.
vec3 cell_quadratic(vec4 h, vec2 a, vec2 dd, float za, float dz) {
    if (max(max(h.x, h.y), max(h.z, h.w)) <= 0.0) return vec3(1.0, 0.0, 0.0);  // empty
    float ex = h.y - h.x, ey = h.z - h.x, g = h.w - h.y - h.z + h.x;
    return vec3(za - (h.x + ex * a.x + ey * a.y + g * a.x * a.y),
                dz - (ex * dd.x + ey * dd.y + g * (a.x * dd.y + a.y * dd.x)),
                -g * dd.x * dd.y);
}

// F on the cell between crossings sa < sb (its four corners fetched once).
vec3 cell_poly(vec3 o, vec3 d, float sa, float sb) {
    ivec2 lo, hi;
    vec2 a, dd;
    ray_cell(o, d, sa, sb, lo, hi, a, dd);
    return cell_quadratic(hf_corners(lo, hi), a, dd, o.z + sa * d.z, d.z);
}

// First t in [0, len] where the quadratic c goes below zero, or -1. With `ends_only` the
// cell counts as hit only when its far end is below (the paper's walk, section 3.3, which
// takes F linear between crossings and misses grazes, Fig. 3); the hit is still the exact
// root. A start value below zero by rounding counts as zero.
float cell_hit(vec3 c, float len, bool ends_only) {
    c.x = max(c.x, 0.0);
    float f_end = c.x + len * (c.y + len * c.z);
    bool end_below = f_end < 0.0;
    if (!end_below) {
        if (ends_only || c.z <= 0.0) return -1.0;
        float tv = -c.y / (2.0 * c.z);                       // convex: the dip's bottom
        if (tv <= 0.0 || tv >= len || c.x + tv * (c.y + tv * c.z) >= 0.0) return -1.0;
    }
    if (c.z == 0.0) return c.y < 0.0 ? clamp(-c.x / c.y, 0.0, len) : 0.0;
    float disc = max(c.y * c.y - 4.0 * c.z * c.x, 0.0);
    float q = -0.5 * (c.y + (c.y >= 0.0 ? sqrt(disc) : -sqrt(disc)));  // stable roots
    float r1 = q / c.z, r2 = q != 0.0 ? c.x / q : 0.0;
    float lo = min(r1, r2), hi = max(r1, r2);
    float t = lo >= 0.0 ? lo : hi;                            // the first root at or after 0
    return clamp(t, 0.0, len);
}

// Walk centreline crossings from sa (above) to s_end, one bilinear cell per iteration; true
// with s_hit on the first hit.
bool walk_exact(vec3 o, vec3 d, float sa, float s_end, out float s_hit, inout int iters) {
    vec2 t = next_crossings(o, d, sa), dt = crossing_steps(d);
    for (int k = 0; k < HARD_CAP && k < u_max_iterations; ++k) {
        float sb = min(min(t.x, t.y), s_end);
        iters++;
        float th = cell_hit(cell_poly(o, d, sa, sb), sb - sa, !u_quadratic_cells);
        if (th >= 0.0) {
            s_hit = sa + th;
            return true;
        }
        if (sb >= s_end) break;
        if (t.x <= t.y) t.x += dt.x; else t.y += dt.y;
        sa = sb;
    }
    s_hit = s_end;
    return false;
}
#endif

#if defined METHOD_EXACT
bool relief_intersect(vec3 o, vec3 d, float s0, float s1, out float s_hit, inout int iters) {
    s_hit = s0;
    if (hf_above(o + s0 * d) < 0.0) return true;
    return walk_exact(o, d, s0, s1, s_hit, iters);
}
#endif

#if defined METHOD_ROBUST
#if defined SAFETY_OCTANTS
uniform highp sampler2DArray u_safety_octants;  // R32F radii per direction octant (safety.py)
#else
uniform sampler2D u_height_safety;  // RG32F: height and safety radius (texels) per texel
#endif
uniform bool u_zero_exact;    // radius 0: exact walk to the next centreline (else clamp to 1)
uniform float u_exact_below;  // rays crossing fewer texels than this are walked exactly

// The corner heights (h00, h10, h01, h11) of texels lo..hi and, for corner 0-3 (-1: none),
// that texel's safety radius: with the packed texture one fetch gives both.
vec4 robust_corners(ivec2 lo, ivec2 hi, int corner, int octant, out float radius) {
#if defined SAFETY_OCTANTS
    radius = 0.0;
    if (corner >= 0) {
        ivec2 texel = ivec2((corner & 1) != 0 ? hi.x : lo.x, (corner & 2) != 0 ? hi.y : lo.y);
        radius = texelFetch(u_safety_octants, ivec3(texel, octant), 0).r;
    }
    return hf_corners(lo, hi);
#else
    vec2 c00 = texelFetch(u_height_safety, lo, 0).rg;
    vec2 c10 = texelFetch(u_height_safety, ivec2(hi.x, lo.y), 0).rg;
    vec2 c01 = texelFetch(u_height_safety, ivec2(lo.x, hi.y), 0).rg;
    vec2 c11 = texelFetch(u_height_safety, hi, 0).rg;
    radius = corner == 0 ? c00.y : (corner == 1 ? c10.y : (corner == 2 ? c01.y : c11.y));
    return vec4(c00.x, c10.x, c01.x, c11.x);
#endif
}

#define ROBUST_WALK 0    // the exact walk, one cell per iteration, up to s_to
#define ROBUST_JUMP 1    // jump by the radius r of centreline ci
#define ROBUST_BISECT 2  // halve the bracket [sa, s_to] of a jump that ended below

// The paper's walk (section 3.4) as one loop whose every iteration fetches the four texels
// around one point or cell, whatever it does: a jump, a bisection step, or one cell of the
// exact walk. Jumps and walks end on a major centreline, and the texel that holds the end
// point (whose radius the next jump takes) is one of the four: with the packed texture the
// radius comes with the heights. The entry point's texel, texels of radius 0 (u_zero_exact)
// and the last centreline before the exit are walked exactly to the next major centreline;
// a jump that ends below the surface is bisected down to two texels, which are walked
// exactly (an exact hit); a shorter last jump keeps the guarantee. Rays shorter than
// u_exact_below texels and vertical ones are walked exactly. With the jumps, bisections and
// walks in nested loops (and a fetch of its own for the radius after each walk) a SIMD group
// waited in each loop for its slowest ray: on llvmpipe that took up to 1.3x this loop's time
// for the same hits and iterations (CHANGELOG.md, 2026-12-04).
bool relief_intersect(vec3 o, vec3 d, float s0, float s1, out float s_hit, inout int iters) {
    s_hit = s0;
    if (hf_above(o + s0 * d) < 0.0) return true;
    bool x_major = abs(d.x) >= abs(d.y);
    float om = x_major ? o.x : o.y, dm = x_major ? d.x : d.y;
    float dn = x_major ? d.y : d.x;
    bool walk_all = dm == 0.0 || (abs(d.x) + abs(d.y)) * (s1 - s0) < u_exact_below;
    // the major centrelines (x = c + 0.5): the last at or before the entry point, and the
    // last strictly before the exit
    float xm0 = om + s0 * dm, xm1 = om + s1 * dm;
    float dir = dm > 0.0 ? 1.0 : -1.0;
    float ci = dm > 0.0 ? floor(xm0 - 0.5) : ceil(xm0 - 0.5);
    float ci_last = dm > 0.0 ? ceil(xm1 - 0.5) - 1.0 : floor(xm1 - 0.5) + 1.0;
    // the octant of this ray's direction (safety.octant): major axis, its sign, the minor's
    int octant = (x_major ? 0 : 4) + (dm < 0.0 ? 2 : 0) + (dn < 0.0 ? 1 : 0);
    // first the walk from the entry to the next major centreline (the one behind the entry
    // lies outside the box, or its texel's guarantee starts after the entry)
    int mode = ROBUST_WALK;
    float sa = s0;    // the ray is above the surface up to sa
    float s_to = s1;  // the end of the walk, or of the bracket
    if (!walk_all) {
        ci += dir;
        s_to = min((ci + 0.5 - om) / dm, s1);
    }
    vec2 t = next_crossings(o, d, sa), dt = crossing_steps(d);
    float r = 0.0;    // the radius at centreline ci
    bool bracketed = false;
    int bisections = 0;
    for (int k = 0; k < HARD_CAP && k < u_max_iterations; ++k) {
        // where to look: the walk's next cell, the bracket's middle or the jump's end
        float s = 0.0, target = ci;
        ivec2 lo, hi;
        vec2 a = vec2(0.0), dd = vec2(0.0), f = vec2(0.0);
        int corner = -1;  // which of the four holds the end point (-1: no radius needed)
        if (mode == ROBUST_WALK) {
            s = min(min(t.x, t.y), s_to);
            ray_cell(o, d, sa, s, lo, hi, a, dd);
            if (s >= s_to && !walk_all && s_to < s1) {  // the walk's last cell: centreline ci
                ivec2 end = ivec2(int(ci), int(floor((x_major ? o.y : o.x) + s_to * dn)));
                if (!x_major) end = end.yx;
                end = clamp(end, ivec2(0), u_hf_size - 1);
                corner = (end.x == lo.x ? 0 : 1) + (end.y == lo.y ? 0 : 2);
            }
        } else {
            if (mode == ROBUST_BISECT) {
                s = 0.5 * (sa + s_to);
            } else {
                target = ci + dir * min(max(r, 1.0), dir * (ci_last - ci));
                s = (target + 0.5 - om) / dm;
            }
            vec2 p = o.xy + s * d.xy;
            if (mode == ROBUST_JUMP) {  // exactly on the centreline
                if (x_major) p.x = target + 0.5; else p.y = target + 0.5;
            }
            hf_point_cell(p, lo, hi, f);
            if (mode == ROBUST_JUMP) corner = (f.x >= 0.5 ? 1 : 0) + (f.y >= 0.5 ? 2 : 0);
        }
        float radius;
        vec4 h = robust_corners(lo, hi, corner, octant, radius);
        if (mode == ROBUST_WALK) {
            iters++;
            vec3 c = cell_quadratic(h, a, dd, o.z + sa * d.z, d.z);
            float th = cell_hit(c, s - sa, !u_quadratic_cells);
            if (th >= 0.0) {
                s_hit = sa + th;
                return true;
            }
            if (s < s_to) {
                if (t.x <= t.y) t.x += dt.x; else t.y += dt.y;
                sa = s;
                continue;
            }
            if (bracketed) {  // below at the jump's end, above in every cell by rounding
                s_hit = s_to;
                return true;
            }
            if (walk_all || s_to >= s1) return false;
            sa = s_to;  // on centreline ci
            r = radius;
        } else {
            float height = hf_mix(h, f);
            bool below = height > 0.0 && o.z + s * d.z < height;
            iters++;
            if (mode == ROBUST_BISECT) {
                if (below) s_to = s; else sa = s;
                ++bisections;
            } else if (below) {  // the hit is in this jump
                s_to = s;
                bracketed = true;
                mode = ROBUST_BISECT;
            }
            if (mode == ROBUST_BISECT) {
                if (bisections >= 32 || abs(dm) * (s_to - sa) <= 2.0) {
                    mode = ROBUST_WALK;
                    t = next_crossings(o, d, sa);
                }
                continue;
            }
            sa = s;  // jumped: the ray is above up to the jump's end
            ci = target;
            r = radius;
        }
        // on centreline ci with radius r: jump next, or walk exactly to the next centreline
        // at a zero radius and after the last centreline
        if (dir * (ci_last - ci) < 0.5 || (r < 0.5 && u_zero_exact)) {
            ci += dir;
            s_to = min((ci + 0.5 - om) / dm, s1);
            mode = ROBUST_WALK;
            t = next_crossings(o, d, sa);
        } else {
            mode = ROBUST_JUMP;
        }
    }
    return false;
}
#endif

#if defined METHOD_MAXMIP
uniform sampler2D u_maxmip;   // R32F max pyramid (maxmip.py): level L node = 2^L texels
uniform int u_top_level;      // its 1 x 1 level
uniform int u_leaf_level;     // nodes at or below this level are walked cell by cell

// Parameter where the ray leaves the node [lo, lo + size]^2 (texel coordinates).
float node_exit(vec3 o, vec3 d, vec2 lo, float size) {
    float tx = d.x > 0.0 ? (lo.x + size - o.x) / d.x : (d.x < 0.0 ? (lo.x - o.x) / d.x : 3.0e38);
    float ty = d.y > 0.0 ? (lo.y + size - o.y) / d.y : (d.y < 0.0 ? (lo.y - o.y) / d.y : 3.0e38);
    return min(tx, ty);
}

// Quadtree traversal: a node whose maximum stays below the ray over the ray's span in it is
// skipped whole (and the walk climbs a level); otherwise the walk descends to the child the
// ray is in, first moving down to where the ray meets the node's maximum. In a node at the
// leaf level (2^L texels square; Tevs et al. descend to single texels, L = 0) the exact walk
// tests the bilinear cells exactly: a few cells cost less than the descents and climbs.
bool relief_intersect(vec3 o, vec3 d, float s0, float s1, out float s_hit, inout int iters) {
    s_hit = s0;
    if (hf_above(o + s0 * d) < 0.0) return true;
    // start in the node of the entry point at the level of the ray's footprint: a short ray
    // need not descend from the 1 x 1 top
    float span = length(d.xy) * (s1 - s0);
    int level = clamp(int(ceil(log2(max(span, 1.0)))), u_leaf_level, u_top_level);
    ivec2 node = clamp(ivec2(floor((o.xy + s0 * d.xy) / float(1 << level))), ivec2(0),
                       ivec2((1 << (u_top_level - level)) - 1));
    ivec2 step = ivec2(d.x >= 0.0 ? 1 : -1, d.y >= 0.0 ? 1 : -1);
    float s = s0;
    for (int k = 0; k < HARD_CAP && k < u_max_iterations; ++k) {
        iters++;
        float size = float(1 << level);
        vec2 lo = vec2(node) * size;
        float s_exit = min(node_exit(o, d, lo, size), s1);
        float top = texelFetch(u_maxmip, node, level).r;
        bool skip = min(o.z + s * d.z, o.z + s_exit * d.z) > top;
        if (!skip && level <= u_leaf_level) {
            if (walk_exact(o, d, s, s_exit, s_hit, iters)) return true;
            skip = true;
        }
        if (!skip) {
            // descend: first down to where the ray meets the node's maximum
            if (d.z < 0.0 && o.z + s * d.z > top) s = max(s, (top - o.z) / d.z);
            skip = s >= s_exit;
        }
        if (!skip) {
            level--;
            vec2 p = o.xy + s * d.xy;
            vec2 mid = lo + 0.5 * size;
            ivec2 child = ivec2(p.x > mid.x || (p.x == mid.x && d.x > 0.0) ? 1 : 0,
                                p.y > mid.y || (p.y == mid.y && d.y > 0.0) ? 1 : 0);
            node = node * 2 + child;
            continue;
        }
        if (s_exit >= s1) return false;
        s = s_exit;
        // into the neighbour the ray enters (across the side it leaves by), then up a level
        // when that neighbour has another parent
        float tx = d.x != 0.0 ? (lo.x + (step.x > 0 ? size : 0.0) - o.x) / d.x : 3.0e38;
        float ty = d.y != 0.0 ? (lo.y + (step.y > 0 ? size : 0.0) - o.y) / d.y : 3.0e38;
        ivec2 next = node;
        if (tx <= ty) next.x += step.x; else next.y += step.y;
        int count = 1 << (u_top_level - level);
        if (any(lessThan(next, ivec2(0))) || any(greaterThanEqual(next, ivec2(count))))
            return false;
        bool other_parent = (next.x >> 1) != (node.x >> 1) || (next.y >> 1) != (node.y >> 1);
        if (level < u_top_level && other_parent) {
            node = next >> 1;
            level++;
        } else {
            node = next;
        }
    }
    s_hit = s1;
    return false;
}
#endif

#if defined METHOD_CONE
uniform sampler2D u_cone;      // R32F relaxed cone ratios, texels per unit height (cone.py)
uniform int u_cone_steps;      // cone steps, then the ray stops where it is

// Step to where the ray leaves the relaxed cone under it, until a step ends inside the
// solid (at most one crossing lies in it: bisect it). As in the chapter, a ray still above
// the surface after u_cone_steps steps stops where it is: a hit there, unless no surface
// lies under it (height 0 is empty here). Rays going up (shadow rays from below, side
// entries) are walked exactly: the cones only bound descents.
bool relief_intersect(vec3 o, vec3 d, float s0, float s1, out float s_hit, inout int iters) {
    s_hit = s0;
    if (hf_above(o + s0 * d) < 0.0) return true;
    if (d.z >= 0.0) return walk_exact(o, d, s0, s1, s_hit, iters);
    float ray_ratio = length(d.xy) / -d.z;   // texels travelled per unit of descent
    float s = s0, s_prev = s0;
    for (int k = 0; k < HARD_CAP && k < u_cone_steps; ++k) {
        iters++;
        vec3 p = o + s * d;
        float above = hf_above(p);
        if (above < 0.0) {
            s_hit = refine_hit(o, d, s_prev, s, iters);
            return true;
        }
        ivec2 texel = clamp(ivec2(floor(p.xy)), ivec2(0), u_hf_size - 1);
        float c = texelFetch(u_cone, texel, 0).r;
        float descent = c * above / (ray_ratio + c);
        s_prev = s;
        s += descent / -d.z;
        if (s >= s1) {
            if (hf_above(o + s1 * d) < 0.0) {
                s_hit = refine_hit(o, d, s_prev, s1, iters);
                return true;
            }
            return false;
        }
    }
    s_hit = s;
    return hf_height((o + s * d).xy) > 0.0;
}
#endif

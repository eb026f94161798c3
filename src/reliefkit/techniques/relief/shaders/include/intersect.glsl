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

uniform bool u_quadratic_cells;  // test the exact quadratic inside each cell (see below)

// F(s) = z(s) - height(s) on the bilinear cell that holds the ray between two consecutive
// centreline crossings sa < sb: F = c.x + c.y t + c.z t^2 with t = s - sa, exactly (the
// four corners fetched once; in the border strips the clamped coordinate is constant). A cell
// whose corners are all 0 is empty space (hf_above): it is never hit.
vec3 cell_poly(vec3 o, vec3 d, float sa, float sb) {
    vec2 last = vec2(u_hf_size) - 1.0;
    vec2 qm = o.xy + 0.5 * (sa + sb) * d.xy - 0.5;          // the segment's middle
    vec2 c = floor(clamp(qm, vec2(0.0), last));
    bvec2 strip = bvec2(qm.x <= 0.0 || qm.x >= last.x, qm.y <= 0.0 || qm.y >= last.y);
    vec2 a = o.xy + sa * d.xy - 0.5 - c;                     // cell coordinates at sa
    vec2 dd = d.xy;
    if (strip.x) { a.x = 0.0; dd.x = 0.0; }
    if (strip.y) { a.y = 0.0; dd.y = 0.0; }
    int i = int(c.x), j = int(c.y);
    int i1 = strip.x ? i : i + 1, j1 = strip.y ? j : j + 1;  // a strip has one column (row)
    float h00 = hf_texel(i, j), h10 = hf_texel(i1, j);
    float h01 = hf_texel(i, j1), h11 = hf_texel(i1, j1);
    if (max(max(h00, h10), max(h01, h11)) <= 0.0) return vec3(1.0, 0.0, 0.0);  // empty
    float ex = h10 - h00, ey = h01 - h00, g = h11 - h10 - h01 + h00;
    float za = o.z + sa * d.z;
    return vec3(za - (h00 + ex * a.x + ey * a.y + g * a.x * a.y),
                d.z - (ex * dd.x + ey * dd.y + g * (a.x * dd.y + a.y * dd.x)),
                -g * dd.x * dd.y);
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
    vec3 p = o + sa * d;
    vec2 t = vec2(next_centerline(p.x, o.x, d.x), next_centerline(p.y, o.y, d.y));
    vec2 dt = vec2(d.x != 0.0 ? 1.0 / abs(d.x) : 3.0e38, d.y != 0.0 ? 1.0 / abs(d.y) : 3.0e38);
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

// Height and safety radius where the ray crosses the major centreline ci + 0.5 at minor
// coordinate `minor`. On a centreline the bilinear height varies along the minor axis only:
// two texels, and the radius's texel (the one holding the point) is one of them, so a jump
// costs two fetches of the packed texture instead of four heights and a radius.
vec2 centerline_height_radius(float ci, float minor, bool x_major, int octant) {
    ivec2 size = x_major ? u_hf_size : u_hf_size.yx;  // (major, minor) extents
    float q = clamp(minor, 0.5, float(size.y) - 0.5) - 0.5;
    float j = floor(q), f = q - j;
    int c = clamp(int(ci), 0, size.x - 1), j0 = int(j), j1 = min(j0 + 1, size.y - 1);
    ivec2 t0 = x_major ? ivec2(c, j0) : ivec2(j0, c);
    ivec2 t1 = x_major ? ivec2(c, j1) : ivec2(j1, c);
#if defined SAFETY_OCTANTS
    float h0 = texelFetch(u_height, t0, 0).r, h1 = texelFetch(u_height, t1, 0).r;
    float r = texelFetch(u_safety_octants, ivec3(f < 0.5 ? t0 : t1, octant), 0).r;
#else
    vec2 a = texelFetch(u_height_safety, t0, 0).rg, b = texelFetch(u_height_safety, t1, 0).rg;
    float h0 = a.x, h1 = b.x, r = f < 0.5 ? a.y : b.y;
#endif
    return vec2(mix(h0, h1, f), r);
}

// The radius jumps stop at a texel of radius 0; the exact walk then covers up to the next
// major centreline and the jumps resume. Every jump ends on a major centreline inside the box
// (the last one before the exit at most: a shorter jump keeps the guarantee), so one sample
// there gives the height to test and the next jump's radius. A jump that ends below the
// surface is bisected (the paper) down to two texels, which the exact walk then tests cell
// by cell (an exact hit instead of the linear root of the last bracket). Rays shorter than
// u_exact_below texels (an option, 0 by default) and vertical ones are walked exactly from
// the start. The exact walk has one call site, so the shader inlines it once: with the walk
// nested in the jumps (inlined twice) robust ran 1.1-1.5x slower than the exact walk on
// llvmpipe.
bool relief_intersect(vec3 o, vec3 d, float s0, float s1, out float s_hit, inout int iters) {
    s_hit = s0;
    if (hf_above(o + s0 * d) < 0.0) return true;
    bool x_major = abs(d.x) >= abs(d.y);
    float om = x_major ? o.x : o.y, dm = x_major ? d.x : d.y;
    float on = x_major ? o.y : o.x, dn = x_major ? d.y : d.x;
    bool walk_all = dm == 0.0 || (abs(d.x) + abs(d.y)) * (s1 - s0) < u_exact_below;
    // the major centrelines (x = c + 0.5): the last at or before the entry point, and the
    // last strictly before the exit
    float xm0 = om + s0 * dm, xm1 = om + s1 * dm;
    float dir = dm > 0.0 ? 1.0 : -1.0;
    float ci = dm > 0.0 ? floor(xm0 - 0.5) : ceil(xm0 - 0.5);
    float ci_last = dm > 0.0 ? ceil(xm1 - 0.5) - 1.0 : floor(xm1 - 0.5) + 1.0;
    float sa = s0;  // last parameter known to be above the surface
    // the octant of this ray's direction (safety.octant): major axis, its sign, the minor's
    int octant = (x_major ? 0 : 4) + (dm < 0.0 ? 2 : 0) + (dn < 0.0 ? 1 : 0);
    float r = -1.0;  // the radius at centreline ci; -1 until sampled
    int k = 0;
    bool bracketed = false;
    for (int round = 0; round < HARD_CAP && k < u_max_iterations; ++round) {
        float walk_from = s0, walk_to = s1;
        if (!walk_all) {
            walk_from = -1.0;
            for (; k < HARD_CAP && k < u_max_iterations; ++k) {
                float s = (ci + 0.5 - om) / dm;
                float room = dir * (ci_last - ci);  // centrelines left before the exit
                // from the entry point (k == 0: the centreline behind it lies outside the
                // box, or its texel's guarantee starts after the entry), at a zero radius and
                // after the last centreline, walk exactly to the next one (or the exit)
                if (k == 0 || room < 0.5 || (r >= 0.0 && r < 0.5 && u_zero_exact)) {
                    ci += dir;
                    walk_from = max(s, s0);
                    walk_to = min((ci + 0.5 - om) / dm, s1);
                    r = -1.0;
                    break;
                }
                // jump by the radius, or sample the radius here first
                float target = r < 0.0 ? ci : ci + dir * min(max(r, 1.0), room);
                float st = (target + 0.5 - om) / dm;
                vec2 hr = centerline_height_radius(target, on + st * dn, x_major, octant);
                if (r >= 0.0) {
                    iters++;
                    if (hr.x > 0.0 && o.z + st * d.z < hr.x) {  // the hit is in this jump
                        walk_from = max(sa, s0);
                        walk_to = st;
                        bracketed = true;
                        break;
                    }
                    sa = st;
                    ci = target;
                }
                r = hr.y;
            }
            if (walk_from < 0.0) return false;
        }
        // a long jump that ends below: bisect it (the paper) down to two texels, then walk
        // those exactly
        for (int b = 0; bracketed && b < 32 && abs(dm) * (walk_to - walk_from) > 2.0; ++b) {
            float sm = 0.5 * (walk_from + walk_to);
            iters++;
            if (hf_above(o + sm * d) < 0.0) walk_to = sm; else walk_from = sm;
        }
        if (walk_exact(o, d, walk_from, walk_to, s_hit, iters)) return true;
        if (bracketed) {  // below at the jump's end, above in every cell by rounding
            s_hit = walk_to;
            return true;
        }
        if (walk_all || walk_to >= s1) return false;
        sa = walk_to;
        ++k;
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

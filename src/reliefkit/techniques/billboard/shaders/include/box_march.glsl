// The three marches through one box's cells (techniques/billboard/box_render.py): the ray is
// o + s d in voxel coordinates, s in [0, 1] from where it enters the box to where it leaves.
// Each returns true with the hit's s and the cell whose colour and normal it shows, and
// counts its loop iterations; it gives up (a miss) after u_max_iterations.
// Include after box_cells.glsl.
uniform int u_max_iterations;
uniform int u_samples;          // MARCH_UNIFORM: samples per voxel along the ray

#if defined MARCH_UNIFORM
// Linear sampling: points 1 / u_samples voxel apart, the first inside the occupied set.
bool march(vec3 o, vec3 d, out float s_hit, out ivec3 cell, out int iters) {
    float ds = 1.0 / (float(u_samples) * length(d));
    s_hit = 0.0;
    cell = ivec3(0);
    for (iters = 0; iters < u_max_iterations;) {
        float s = float(iters) * ds;
        if (s > 1.0) return false;
        ++iters;
        vec3 p = o + s * d;
        cell = cell_at(p, d);
#if defined VOLUMETRIC
        bool inside = occupied(cell);
#else
        vec2 interval = texel_interval(cell.xy);
        float w = p.z / float(u_res.z);
        bool inside = w >= interval.x && w <= interval.y;
#endif
        if (inside) {
            s_hit = s;
            return true;
        }
    }
    return false;
}

#else
// Exact (a DDA over the cells, Amanatides & Woo) and, with MARCH_SPHERE, sphere tracing
// (§3.4.1): where the distance texture allows a positive safe step, jump that far; where it
// does not, take one exact DDA step, so no occupied cell is ever skipped.
bool march(vec3 o, vec3 d, out float s_hit, out ivec3 cell, out int iters) {
    float inv_len = 1.0 / length(d);
#if defined VOLUMETRIC
    bvec3 axes = bvec3(true);       // a 3D DDA over voxels
#else
    bvec3 axes = bvec3(true, true, false);  // a 2D DDA over texel columns
#endif
    float s = 0.0;
    s_hit = 0.0;
    cell = cell_at(o, d);
    for (iters = 0; iters < u_max_iterations;) {
        ++iters;
#if defined MARCH_SPHERE
        ivec3 voxel = cell;
#if !defined VOLUMETRIC
        voxel.z = cell_at(o + s * d, d).z;  // the column's voxel the ray is in
#endif
        float r = safe_step(voxel);
        if (r > 0.0) {
            s += r * inv_len;
            if (s > 1.0) return false;
            cell = cell_at(o + s * d, d);
            continue;
        }
#endif
        int axis;
        float exit_s = cell_exit(cell, o, d, axes, axis);
#if defined VOLUMETRIC
        if (occupied(cell)) {
            s_hit = s;  // the entry point of the first occupied cell
            return true;
        }
#else
        vec2 interval = texel_interval(cell.xy);
        float w0 = o.z / float(u_res.z), dw = d.z / float(u_res.z);
        float h = first_in_interval(w0, dw, s, min(exit_s, 1.0), interval);
        if (h >= 0.0) {
            s_hit = h;
            return true;
        }
#endif
        if (exit_s >= 1.0) return false;
        s = max(s, exit_s);
        cell = next_cell(cell, axis, d);
        if (!inside_grid(cell)) return false;
    }
    return false;
}
#endif

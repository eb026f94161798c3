// Lengths and directions of vectors of any magnitude. A shell's size is the mesh's own (1e-20
// and 1e20 units are both valid), and float32 squares of components below about 1e-19 flush to
// zero or above about 1e19 overflow, so normalize() and length() are taken of the vector
// divided by its largest component (tets.glsl includes this file).

float largest_component(vec3 v) { return max(max(abs(v.x), abs(v.y)), abs(v.z)); }

// Unit vector along v; `fallback` where v is zero.
vec3 unit_or(vec3 v, vec3 fallback) {
    float m = largest_component(v);
    return m > 0.0 ? normalize(v / m) : fallback;
}

float scale_free_length(vec3 v) {
    float m = largest_component(v);
    return m > 0.0 ? m * length(v / m) : 0.0;
}

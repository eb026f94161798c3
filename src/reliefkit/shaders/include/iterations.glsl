// Loop counters of the instrumented variant (COUNT_ITERATIONS): one extra colour attachment
// after the Frame's, read back by render/registry.py into frame.stats.
// (primary iterations, secondary iterations, 1 = the fragment ran, 1 = it hit).
// Include after frame_outputs.glsl.
#if defined COUNT_ITERATIONS
layout(location = RK_FRAME_ATTACHMENTS) out vec4 f_iterations;
#endif

void write_iterations(int primary, int secondary, bool hit) {
#if defined COUNT_ITERATIONS
    f_iterations = vec4(float(primary), float(secondary), 1.0, hit ? 1.0 : 0.0);
#endif
}

#if defined COUNT_ITERATIONS
// Depth of a counted miss: just in front of the cleared far value (1.0), so a miss lands
// only on pixels where nothing has been drawn, and anything drawn later covers it.
#define RK_MISS_DEPTH 0.999999

// A fragment that did work but found nothing: its count is kept, the picture is not changed
// (background, coverage 0, and never over something drawn). A shader that calls this writes
// gl_FragDepth on its other paths too (gl_FragCoord.z where it keeps the rasterized depth).
void write_counted_miss(int primary) {
    f_color = vec4(0.0);
    f_position = vec4(0.0);
    f_normal = vec4(0.0);
    write_iterations(primary, 0, false);
    gl_FragDepth = RK_MISS_DEPTH;
}
#endif

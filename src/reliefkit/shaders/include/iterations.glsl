// Loop counters of the instrumented variant (COUNT_ITERATIONS): one extra colour attachment
// after the Frame's, read back by render/registry.py into frame.stats.
// (primary iterations, secondary iterations, 1 = the fragment ran, 1 = it hit).
#if defined COUNT_ITERATIONS
layout(location = RK_FRAME_ATTACHMENTS) out vec4 f_iterations;
#endif

void write_iterations(int primary, int secondary, bool hit) {
#if defined COUNT_ITERATIONS
    f_iterations = vec4(float(primary), float(secondary), 1.0, hit ? 1.0 : 0.0);
#endif
}

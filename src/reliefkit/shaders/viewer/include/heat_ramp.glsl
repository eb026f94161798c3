// reliefkit.metrics.heat_ramp in GLSL: values in [0, 1] (clipped) to display colours by
// linear interpolation between the ramp's stops. The stops are not written here: the viewer
// sets u_heat_ramp from metrics.heat_ramp_stops() (inputs.json) and the shader loader
// defines HEAT_RAMP_STOPS, their count.
uniform vec3 u_heat_ramp[HEAT_RAMP_STOPS];

vec3 heat_ramp(float value) {
    float t = clamp(value, 0.0, 1.0) * float(HEAT_RAMP_STOPS - 1);
    int i = min(int(t), HEAT_RAMP_STOPS - 2);
    return mix(u_heat_ramp[i], u_heat_ramp[i + 1], t - float(i));
}

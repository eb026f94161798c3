// The browser viewer's picture: what `reliefkit render` writes (render/frame.py
// frame_from_passes, Frame.rgba8, colorspace.to_rgba8): the opaque pass's colour where it
// covered a pixel (position.w > 0.5), under the transparent pass's premultiplied colour,
// straight again and sRGB-encoded; transparent where neither drew. With u_debug, one of the
// debug views of the opaque pass's targets instead (include/debug_views.glsl). Built as GLSL ES by the
// shader loader and handed to the page in inputs.json (reliefkit.viewer.site).
//! defines: HEAT_RAMP_STOPS
#if defined VERTEX_SHADER
#include "core:include/fullscreen.glsl"
#endif

#if defined FRAGMENT_SHADER
uniform highp sampler2D u_color;
uniform highp sampler2D u_position;
uniform highp sampler2D u_transparent;  // premultiplied, accumulated front to back
out vec4 f_out;

#include "core:viewer/include/debug_views.glsl"

vec3 srgb_encode(vec3 x) {  // colorspace.srgb_encode
    x = clamp(x, 0.0, 1.0);
    return mix(1.055 * pow(x, vec3(1.0 / 2.4)) - 0.055, 12.92 * x,
               vec3(lessThanEqual(x, vec3(0.0031308))));
}

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 position = texelFetch(u_position, p, 0);
    bool covered = position.w > 0.5;
    if (u_debug != 0) {
        f_out = debug_view(p, covered, position.xyz);
        return;
    }
    vec4 opaque = covered ? texelFetch(u_color, p, 0) : vec4(0.0);
    vec4 front = texelFetch(u_transparent, p, 0);
    float alpha = front.a + (1.0 - front.a) * opaque.a;
    vec3 rgb = front.rgb + (1.0 - front.a) * opaque.rgb * opaque.a;
    vec3 straight = alpha > 0.0 ? rgb / alpha : vec3(0.0);
    f_out = covered || front.a > 0.0 ? vec4(srgb_encode(straight), clamp(alpha, 0.0, 1.0))
                                     : vec4(0.0);
}
#endif

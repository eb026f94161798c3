// The maximum mipmap (maxmip.py, Tevs, Ihrke & Seidel 2008) built on the GPU from the height
// texture already there: one pass per level, each invocation one node. Level 0 is the 3 x 3
// maximum of the border-clamped field (the largest height the bilinear surface reaches over
// the texel square), 0 outside it (the padding to a power-of-two square is empty); level L is
// the maximum of its four children on level L - 1. Maxima are exact, so the result equals the
// CPU's max_pyramid bit for bit.
//! version: 430
//! defines: FROM_HEIGHT

#if defined COMPUTE_SHADER
layout(local_size_x = 8, local_size_y = 8) in;
layout(r32f, binding = 1) writeonly uniform image2D u_dst;  // the level being built
uniform ivec2 u_dst_size;
#if defined FROM_HEIGHT
uniform sampler2D u_height;  // R32F field, W x H
uniform ivec2 u_hf_size;
#else
layout(r32f, binding = 0) readonly uniform image2D u_src;   // the level below
#endif

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, u_dst_size))) return;
    float top = 0.0;
#if defined FROM_HEIGHT
    if (all(lessThan(p, u_hf_size))) {
        for (int dj = -1; dj <= 1; ++dj)
            for (int di = -1; di <= 1; ++di) {
                ivec2 q = clamp(p + ivec2(di, dj), ivec2(0), u_hf_size - 1);
                top = max(top, texelFetch(u_height, q, 0).r);
            }
    }
#else
    ivec2 q = 2 * p;
    top = max(max(imageLoad(u_src, q).r, imageLoad(u_src, q + ivec2(1, 0)).r),
              max(imageLoad(u_src, q + ivec2(0, 1)).r, imageLoad(u_src, q + ivec2(1, 1)).r));
#endif
    imageStore(u_dst, p, vec4(top));
}
#endif

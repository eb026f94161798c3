// GL objects freed when an executor's plans are replaced (the page's option controls).

/** Delete the textures, framebuffers and renderbuffers held anywhere in ``value`` (a
 *  multi-pass kind's cache entry). */
export function releaseAll(gl, value) {
  if (value instanceof WebGLTexture) gl.deleteTexture(value);
  else if (value instanceof WebGLFramebuffer) gl.deleteFramebuffer(value);
  else if (value instanceof WebGLRenderbuffer) gl.deleteRenderbuffer(value);
  else if (Array.isArray(value)) for (const v of value) releaseAll(gl, v);
  else if (value && typeof value === 'object' && Object.getPrototypeOf(value) === Object.prototype) {
    for (const v of Object.values(value)) releaseAll(gl, v);
  }
}

// Instanced drawing (render/instancing.py): one draw puts the object at every placement.
// With INSTANCED each instance has a similarity of the camera-relative world (a uniform scale,
// a rotation about +y, a translation) that maps the object as it is to where this instance
// stands; without it every function here is the identity, so a shader calls them always.
//
// Vertex stage: `placed(local, u_model_offset)` is the camera-relative world position of a
// vertex stored relative to the plan's origin, and hands the instance to the fragment stage
// through flat varyings. Fragment stage (ray casting kinds): `to_object` takes a point of
// the pixel's ray into the object as it is, where the baked textures and box matrices hold,
// `to_instance` and `rotate_to_instance` bring a hit and its normal back out. A camera-facing
// quad (an impostor) places its centre with `placed`, sizes itself by `instance_scale()`
// and looks its view direction up in the object's frame (`rotate_to_object`).
#if defined INSTANCED
#if defined VERTEX_SHADER
in vec4 in_instance;       // translation from the object's origin to the instance's, scale
in vec2 in_instance_yaw;   // cos, sin of the rotation about +y
flat out vec4 v_instance;  // camera-relative: translation, scale
flat out vec2 v_instance_yaw;
#else
flat in vec4 v_instance;
flat in vec2 v_instance_yaw;
#endif

// The instance's uniform scale (a camera-facing quad's size).
#if defined VERTEX_SHADER
float instance_scale() { return in_instance.w; }
#else
float instance_scale() { return v_instance.w; }
#endif

vec3 rotate_to_instance(vec3 v) {
    vec2 cs = v_instance_yaw;
    return vec3(cs.x * v.x + cs.y * v.z, v.y, -cs.y * v.x + cs.x * v.z);
}

vec3 rotate_to_object(vec3 v) {
    vec2 cs = v_instance_yaw;
    return vec3(cs.x * v.x - cs.y * v.z, v.y, cs.y * v.x + cs.x * v.z);
}

vec3 to_instance(vec3 object_point) {
    return v_instance.w * rotate_to_instance(object_point) + v_instance.xyz;
}

vec3 to_object(vec3 instance_point) {
    return rotate_to_object(instance_point - v_instance.xyz) / v_instance.w;
}

#if defined VERTEX_SHADER
// The camera-relative world position of `local` (relative to the plan's origin, which
// `model_offset` takes to the camera's) in this instance; sets the fragment stage's varyings.
vec3 placed(vec3 local, vec3 model_offset) {
    v_instance_yaw = in_instance_yaw;
    // the similarity of the camera-relative world, for the fragment stage
    v_instance = vec4(in_instance.xyz + model_offset
                      - in_instance.w * rotate_to_instance(model_offset), in_instance.w);
    // the vertex itself without that cancellation: small offsets added last
    return in_instance.w * rotate_to_instance(local) + in_instance.xyz + model_offset;
}
#endif

#else
float instance_scale() { return 1.0; }
vec3 rotate_to_instance(vec3 v) { return v; }
vec3 rotate_to_object(vec3 v) { return v; }
vec3 to_instance(vec3 object_point) { return object_point; }
vec3 to_object(vec3 instance_point) { return instance_point; }
#if defined VERTEX_SHADER
vec3 placed(vec3 local, vec3 model_offset) { return local + model_offset; }
#endif
#endif

// Twin: reference/raytrace/textures.py
// Textured hits (docs/conventions.md, "Textures in the ray tracer"; the data: renderer/core/
// ray_textures.py through renderer/gpu/raytracer.py). Included by trace.glsl only with
// TEXTURES (some material is textured), after its hit kinds, shapes and trace_sample_time:
// - the UV at a hit: a triangle's vertex UVs weighted by its barycentrics (1 - u - v, u, v); a
//   sphere's by the sphere rule on its object-space direction R (P - C) (no normalisation:
//   both angles are ratios), with texture_atan2 for both (asin y = atan2(y, |(x, z)|)); a
//   plane's by its affine map U (P, 1). With MOTION a sphere's or plane's hit is moved back
//   to the shape's time-0 frame first (the texture turns and slides with the shape);
// - the lookup at (u su + ou, v sv + ov): textureLod(u_textures[k], uv, 0.0) through the slot's
//   ray sampler (level 0, the magnification filter: the ray tracer's LOD rule). A sampler array
//   takes only constant indices in GLSL 3.30, so slot k is a branch `slot == k` of its own, up
//   to TEXTURE_SLOTS (renderer/core/ray_textures.py); NUM_TEXTURES of them are compiled;
// - the texel's RGB multiplies the coefficients its material names (texture_modulate).

uniform sampler2D u_textures[NUM_TEXTURES];
uniform sampler2D u_texture_materials;   // per object: (slot, k_a, k_d, k_s flags), (su, sv, ou, ov)
#ifdef MESHES
uniform sampler2D u_triangle_uvs;        // per original triangle: (uv A, uv B), (uv C, 0, 0)
#endif
#if NUM_SPHERES > 0
uniform vec3 u_sphere_rotation[3 * NUM_SPHERES];   // rows of each world-to-object rotation
#endif
#if NUM_PLANES > 0
uniform vec4 u_plane_uv[2 * NUM_PLANES];           // rows of each U: (u, v) = U (P, 1)
#endif

// atan2(y, x) in (-pi, pi] by our own polynomial (Mesa's atan is 1e-5 off, its asin worse):
// |y|, |x| reduced to a = min / max in [0, 1], then to [-tan pi/8, tan pi/8] by
// (a - 1) / (a + 1) + pi/4, Cephes' odd polynomial (atanf; |error| < 3e-7 in float32), the octant put
// back. atan2(0, 0) = 0; y = -0 counts as +0.
float texture_atan2(float y, float x) {
    float ax = abs(x);
    float ay = abs(y);
    float high = max(ax, ay);
    float a = high > 0.0 ? min(ax, ay) / high : 0.0;
    bool big = a > 0.41421356237309503;
    float z = big ? (a - 1.0) / (a + 1.0) : a;
    float z2 = z * z;
    float p = ((8.05374449538e-2 * z2 - 1.38776856032e-1) * z2 + 1.99777106478e-1) * z2
              - 3.33329491539e-1;
    float r = p * z2 * z + z;
    r = big ? r + 0.78539816339744831 : r;
    r = ay > ax ? 1.5707963267948966 - r : r;
    r = x < 0.0 ? 3.1415926535897932 - r : r;
    return y < 0.0 ? -r : r;
}

// The sphere rule for an object-space direction d from the centre, any length.
vec2 texture_sphere_uv(vec3 d) {
    float u = 0.5 + texture_atan2(d.x, d.z) * 0.15915494309189535;
    float v = 0.5 + texture_atan2(d.y, sqrt(d.x * d.x + d.z * d.z)) * 0.31830988618379067;
    return vec2(u, v);
}

float texture_dot3(vec3 a, vec3 b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}

#ifdef MOTION
// The hit P on sphere or plane `index` moved back into the shape's time-0 frame.
vec3 texture_time0(int kind, int index, vec3 P) {
    int k = 3 * index;
    float t = trace_sample_time();
    Motion m;
#if NUM_SPHERES > 0
    if (kind == TRACE_SPHERE)
        m = motion_at(u_sphere_motion[k], u_sphere_motion[k + 1], u_sphere_motion[k + 2], t);
#endif
#if NUM_PLANES > 0
    if (kind == TRACE_PLANE)
        m = motion_at(u_plane_motion[k], u_plane_motion[k + 1], u_plane_motion[k + 2], t);
#endif
    return motion_point_back(m, P);
}
#endif

// The UV of the hit at P (scene_hit's kind and index, the triangle's barycentrics `bary`).
vec2 texture_uv(int kind, int index, vec3 P, vec2 bary) {
    vec2 uv = vec2(0.0);
    vec3 Q = P;                           // a sphere's or plane's hit in its time-0 frame
#ifdef MOTION
    if (kind != TRACE_TRIANGLE) Q = texture_time0(kind, index, P);
#endif
#if NUM_SPHERES > 0
    if (kind == TRACE_SPHERE) {
        vec3 d = Q - u_spheres[index].xyz;
        uv = texture_sphere_uv(vec3(texture_dot3(u_sphere_rotation[3 * index], d),
                                    texture_dot3(u_sphere_rotation[3 * index + 1], d),
                                    texture_dot3(u_sphere_rotation[3 * index + 2], d)));
    }
#endif
#if NUM_PLANES > 0
    if (kind == TRACE_PLANE) {
        vec4 U0 = u_plane_uv[2 * index];
        vec4 U1 = u_plane_uv[2 * index + 1];
        uv = vec2(texture_dot3(U0.xyz, Q) + U0.w, texture_dot3(U1.xyz, Q) + U1.w);
    }
#endif
#ifdef MESHES
    if (kind == TRACE_TRIANGLE) {
        vec4 AB = trace_texel(u_triangle_uvs, 2 * index);
        vec2 C = trace_texel(u_triangle_uvs, 2 * index + 1).xy;
        uv = (1.0 - bary.x - bary.y) * AB.xy + bary.x * AB.zw + bary.y * C;
    }
#endif
    return uv;
}

// The texel of slot `slot` at uv: level 0 through the slot's sampler (one branch per slot).
#define TEXTURE_SLOT(k) if (slot == k) c = textureLod(u_textures[k], uv, 0.0).rgb;
vec3 texture_texel(int slot, vec2 uv) {
    vec3 c = vec3(1.0);
    TEXTURE_SLOT(0)
#if NUM_TEXTURES > 1
    TEXTURE_SLOT(1)
#endif
#if NUM_TEXTURES > 2
    TEXTURE_SLOT(2)
#endif
#if NUM_TEXTURES > 3
    TEXTURE_SLOT(3)
#endif
#if NUM_TEXTURES > 4
    TEXTURE_SLOT(4)
#endif
#if NUM_TEXTURES > 5
    TEXTURE_SLOT(5)
#endif
#if NUM_TEXTURES > 6
    TEXTURE_SLOT(6)
#endif
#if NUM_TEXTURES > 7
    TEXTURE_SLOT(7)
#endif
#if NUM_TEXTURES > 8
    TEXTURE_SLOT(8)
#endif
#if NUM_TEXTURES > 9
    TEXTURE_SLOT(9)
#endif
#if NUM_TEXTURES > 10
    TEXTURE_SLOT(10)
#endif
#if NUM_TEXTURES > 11
    TEXTURE_SLOT(11)
#endif
#if NUM_TEXTURES > 12
    TEXTURE_SLOT(12)
#endif
#if NUM_TEXTURES > 13
    TEXTURE_SLOT(13)
#endif
#if NUM_TEXTURES > 14
    TEXTURE_SLOT(14)
#endif
#if NUM_TEXTURES > 15
    TEXTURE_SLOT(15)
#endif
    return c;
}

// The hit's material (u_ka, u_kd, u_ks, set by trace) with the coefficients its texture
// modulates multiplied by the texel; an untextured object's (slot -1) left as it is.
void texture_modulate(int obj, int kind, int index, vec3 P, vec2 bary) {
    vec4 flags = trace_texel(u_texture_materials, 2 * obj);
    int slot = int(flags.x);
    if (slot >= 0) {
        vec4 transform = trace_texel(u_texture_materials, 2 * obj + 1);
        vec3 t = texture_texel(slot, texture_uv(kind, index, P, bary) * transform.xy + transform.zw);
        u_ka = flags.y > 0.5 ? u_ka * t : u_ka;
        u_kd = flags.z > 0.5 ? u_kd * t : u_kd;
#ifdef SPECULAR
        u_ks = flags.w > 0.5 ? u_ks * t : u_ks;
#endif
    }
}

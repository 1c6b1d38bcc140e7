// Twin: reference/raytrace/trace.py
// The ray tracer proper (docs/conventions.md, "Rays"): the closest hit among the analytic
// spheres, then planes, then the scene's triangles through its BVH; Phong shading through
// lighting.glsl (MATERIAL_VARIABLES: the hit's material; SHADOWS: a shadow ray per light); then
// reflected (k_r + k_t F) and transmitted (k_t (1 - F)) rays, F Schlick's, to MAX_DEPTH bounces
// and down to a weight cut-off, depth first (the reflected ray first, the transmitted one
// waiting on a fixed-size stack) in a loop of bounded length (no recursion in GLSL).
// Compile-time constants (renderer/gpu/raytracer.py): NUM_SPHERES, NUM_PLANES, MESHES,
// SECONDARY (some k_r or k_t > 0), GLOSSY (such a material has a finite gloss: reflected rays
// drawn from a lobe), MAX_DEPTH, MOTION and NUM_MOVING_MESHES
// (motion blur), and lighting.glsl's light counts and SPECULAR; AREA_LIGHTS (some point light
// has an area of size > 0: LIGHT_SAMPLES shadow rays to points of it per hit, area_light_term);
// PATH_TRACE: the path tracer (pathtrace.glsl) asks this file's scene queries and lights, and
// the Whitted loop (trace) is left out;
// TEXTURES and NUM_TEXTURES (some material is textured: textures.glsl's texture_modulate).

#include "raytrace/bvh.glsl"          // and intersect.glsl (an include is expanded once)
#include "raytrace/optics.glsl"
#include "raytrace/sampling.glsl"     // distributed_2d: the numbers a hit draws
#include "raytrace/warp.glsl"
#ifdef MESHES
uniform usampler2D u_nodes;          // renderer/core/bvh.py's Walk layout
uniform sampler2D u_triangles;
uniform sampler2D u_triangle_data;   // per original triangle: A, B, C, (nA, object), nB, nC
#endif

#ifndef NUM_SPHERES
#define NUM_SPHERES 0
#endif
#ifndef NUM_PLANES
#define NUM_PLANES 0
#endif
#ifndef MAX_DEPTH
#define MAX_DEPTH 4
#endif

#if NUM_SPHERES > 0
uniform vec4 u_spheres[NUM_SPHERES];            // (centre, radius), camera-relative
uniform int u_sphere_object[NUM_SPHERES];
#endif
#if NUM_PLANES > 0
uniform vec4 u_planes[NUM_PLANES];              // (unit N, d): P.N + d = 0
uniform int u_plane_object[NUM_PLANES];
#endif
uniform sampler2D u_materials;  // per object: (ka, n), (kd, two-sided), (ks, ior), (kr, gloss), (kt, Fresnel exact)

#ifndef NUM_MOVING_MESHES
#define NUM_MOVING_MESHES 0
#endif
#ifdef MOTION
// Motion blur (docs/conventions.md, "Motion blur"): each sphere's, plane's and moving mesh's
// motion as rows (c, rate), (v, 0), (axis, 0) (renderer/core/motion.py); trace_motion_at puts
// the spheres and planes where they are at the camera sample's time (g_spheres, g_planes) and
// takes each moving mesh's motion at that time (g_mesh_motion), once per camera sample: its
// reflected, transmitted and shadow rays see the scene at the same time. A moving mesh has its
// own tree in u_nodes (tree u_mesh_root), walked with the ray moved into its time-0 frame.
#include "raytrace/motion.glsl"
uniform vec2 u_shutter;
#if NUM_SPHERES > 0
uniform vec4 u_sphere_motion[3 * NUM_SPHERES];
vec4 g_spheres[NUM_SPHERES];
#endif
#if NUM_PLANES > 0
uniform vec4 u_plane_motion[3 * NUM_PLANES];
vec4 g_planes[NUM_PLANES];
#endif
#if NUM_MOVING_MESHES > 0
uniform vec4 u_mesh_motion[3 * NUM_MOVING_MESHES];
uniform int u_mesh_root[NUM_MOVING_MESHES];
uniform int u_mesh_object[NUM_MOVING_MESHES];
Motion g_mesh_motion[NUM_MOVING_MESHES];
#endif

void trace_motion_at(float t) {
#if NUM_SPHERES > 0
    for (int k = 0; k < NUM_SPHERES; ++k) {
        Motion m = motion_at(u_sphere_motion[3 * k], u_sphere_motion[3 * k + 1],
                             u_sphere_motion[3 * k + 2], t);
        g_spheres[k] = vec4(motion_point(m, u_spheres[k].xyz), u_spheres[k].w);
    }
#endif
#if NUM_PLANES > 0
    for (int k = 0; k < NUM_PLANES; ++k) {
        Motion m = motion_at(u_plane_motion[3 * k], u_plane_motion[3 * k + 1],
                             u_plane_motion[3 * k + 2], t);
        vec3 N;
        float d;
        motion_plane(m, u_planes[k].xyz, u_planes[k].w, N, d);
        g_planes[k] = vec4(N, d);
    }
#endif
#if NUM_MOVING_MESHES > 0
    for (int k = 0; k < NUM_MOVING_MESHES; ++k) {
        g_mesh_motion[k] = motion_at(u_mesh_motion[3 * k], u_mesh_motion[3 * k + 1],
                                     u_mesh_motion[3 * k + 2], t);
    }
#endif
}
#endif

// Sphere k (centre, radius) and plane k (unit N at time 0, d) at this camera sample's time.
#if NUM_SPHERES > 0
vec4 trace_sphere(int k) {
#ifdef MOTION
    return g_spheres[k];
#else
    return u_spheres[k];
#endif
}
#endif
#if NUM_PLANES > 0
vec4 trace_plane(int k) {
#ifdef MOTION
    return g_planes[k];
#else
    return u_planes[k];
#endif
}
#endif
uniform vec3 u_background;

#include "lighting.glsl"

const int TRACE_MISS = 0;
const int TRACE_SPHERE = 1;
const int TRACE_PLANE = 2;
const int TRACE_TRIANGLE = 3;
const float TRACE_INF = uintBitsToFloat(0x7f800000u);
// Hits closer than this, relative, are a tie: the surface found first keeps it (scene_hit);
// a secondary or shadow ray (unit direction) from O starts at s_min = TRACE_HIT_TIE |O|, so a
// surface met closer than that ties with the one it leaves (trace_s_min).
const float TRACE_HIT_TIE = 1.0 / 262144.0;

float trace_s_min(vec3 O) {
    return TRACE_HIT_TIE * sqrt(dot(O, O));
}

// Texel k of the materials or triangle data: the BVH textures' layout (bvh.glsl, bvh_texel).
vec4 trace_texel(sampler2D texture_, int k) {
    return bvh_texel(texture_, k);
}

// The nearest hit with s_min < s < s_max: its kind (TRACE_MISS on a miss), the sphere's,
// plane's or original triangle's index, s (s_max on a miss) and the triangle's (u, v).
// `from_shape`: the analytic shape the ray starts on (a sphere k, a plane NUM_SPHERES + k; -1
// for none), which it meets again only at a sphere's far side (convexity; no offset needed).
// Ties: a surface replaces the nearest found so far only when nearer by more than
// TRACE_HIT_TIE relative, so of surfaces closer than float32 can order (a triangle lying in a
// plane) the first found shows: spheres, then planes, then triangles (docs/conventions.md).
int scene_hit(vec3 O, vec3 D, float s_min, float s_max, int from_shape,
              out int index, out float s, out vec2 uv) {
    s = s_max;
    float s_limit = s_max;
    index = -1;
    uv = vec2(0.0);
    int kind = TRACE_MISS;
    float s_k;
#if NUM_SPHERES > 0
    for (int k = 0; k < NUM_SPHERES; ++k) {
        vec3 C = trace_sphere(k).xyz;
        float r = trace_sphere(k).w;
        if (ray_sphere_from(O, D, C, r, k == from_shape, s_min, s_limit, s_k)) {
            s = s_k; s_limit = s_k * (1.0 - TRACE_HIT_TIE); kind = TRACE_SPHERE; index = k;
        }
    }
#endif
#if NUM_PLANES > 0
    for (int k = 0; k < NUM_PLANES; ++k) {
        if (NUM_SPHERES + k != from_shape
                && ray_plane(O, D, trace_plane(k).xyz, trace_plane(k).w, s_min, s_limit, s_k)) {
            s = s_k; s_limit = s_k * (1.0 - TRACE_HIT_TIE); kind = TRACE_PLANE; index = k;
        }
    }
#endif
#ifdef MESHES
    vec2 uv_t;
    int triangle;
    if (bvh_closest_hit(u_nodes, u_triangles, 0, O, D, s_min, s_limit, s_k, uv_t, triangle)) {
        s = s_k; s_limit = s_k; kind = TRACE_TRIANGLE; index = triangle; uv = uv_t;
    }
#if NUM_MOVING_MESHES > 0
    for (int m = 0; m < NUM_MOVING_MESHES; ++m) {
        if (bvh_closest_hit(u_nodes, u_triangles, u_mesh_root[m],
                            motion_point_back(g_mesh_motion[m], O),
                            motion_direction_back(g_mesh_motion[m], D), s_min, s_limit, s_k, uv_t,
                            triangle)) {
            s = s_k; s_limit = s_k; kind = TRACE_TRIANGLE; index = triangle; uv = uv_t;
        }
    }
#endif
#endif
    return kind;
}

// The hit point, the outward geometric and shading unit normals, the object.
void surface(vec3 O, vec3 D, int kind, int index, float s, vec2 uv,
             out vec3 P, out vec3 Ng, out vec3 Ns, out int obj) {
    P = O + s * D;
    Ng = vec3(0.0);
    Ns = vec3(0.0);
    obj = 0;
#if NUM_SPHERES > 0
    if (kind == TRACE_SPHERE) {
        Ng = sphere_normal(P, trace_sphere(index).xyz, trace_sphere(index).w);
        Ns = Ng;
        obj = u_sphere_object[index];
    }
#endif
#if NUM_PLANES > 0
    if (kind == TRACE_PLANE) {
        Ng = plane_normal(trace_plane(index).xyz);
        Ns = Ng;
        obj = u_plane_object[index];
    }
#endif
#ifdef MESHES
    if (kind == TRACE_TRIANGLE) {
        vec3 A = trace_texel(u_triangle_data, 6 * index).xyz;
        vec3 B = trace_texel(u_triangle_data, 6 * index + 1).xyz;
        vec3 C = trace_texel(u_triangle_data, 6 * index + 2).xyz;
        Ng = triangle_normal(A, B, C);
        vec4 nA = trace_texel(u_triangle_data, 6 * index + 3);
        vec3 nB = trace_texel(u_triangle_data, 6 * index + 4).xyz;
        vec3 nC = trace_texel(u_triangle_data, 6 * index + 5).xyz;
        Ns = normalize_or_zero((1.0 - uv.x - uv.y) * nA.xyz + uv.x * nB + uv.y * nC);
        obj = int(nA.w);
#if NUM_MOVING_MESHES > 0
        for (int m = 0; m < NUM_MOVING_MESHES; ++m) {   // a moving mesh's normals, turned
            if (u_mesh_object[m] == obj) {
                Ng = motion_direction(g_mesh_motion[m], Ng);
                Ns = motion_direction(g_mesh_motion[m], Ns);
            }
        }
#endif
    }
#endif
}

// Whether anything is hit with trace_s_min(O) < s < s_max (a shadow ray from a point of
// `from_shape`, as scene_hit): any hit, not the nearest; the analytic shapes, then the BVH's
// any-hit walk unless one of them is hit. No early return: llvmpipe runs every test anyway,
// and a return inside these loops kept them from being unrolled.
bool occluded(vec3 O, vec3 D, float s_max, int from_shape) {
    float s_k;
    float s_min = trace_s_min(O);
    bool hit = false;
#if NUM_SPHERES > 0
    for (int k = 0; k < NUM_SPHERES; ++k) {
        bool hit_k = ray_sphere_from(O, D, trace_sphere(k).xyz, trace_sphere(k).w, k == from_shape,
                                     s_min, s_max, s_k);
        hit = hit || hit_k;
    }
#endif
#if NUM_PLANES > 0
    for (int k = 0; k < NUM_PLANES; ++k) {
        bool hit_k = ray_plane(O, D, trace_plane(k).xyz, trace_plane(k).w, s_min, s_max, s_k);
        hit = hit || (hit_k && NUM_SPHERES + k != from_shape);
    }
#endif
#ifdef MESHES
    if (!hit) hit = bvh_any_hit(u_nodes, u_triangles, 0, O, D, s_min, s_max);
#if NUM_MOVING_MESHES > 0
    for (int m = 0; m < NUM_MOVING_MESHES; ++m) {
        if (!hit) hit = bvh_any_hit(u_nodes, u_triangles, u_mesh_root[m],
                                    motion_point_back(g_mesh_motion[m], O),
                                    motion_direction_back(g_mesh_motion[m], D), s_min, s_max);
    }
#endif
#endif
    return hit;
}

vec3 g_geometric_normal;             // the outward Ng of the point being lit
int g_shape;                         // its analytic shape (scene_hit's from_shape), or -1
// Whose numbers a hit draws (sampling.glsl's distributed_2d at slot 1 + g_ray_key): the pixel
// and sample k being traced (set by raytrace.frag) and the key of the ray being shaded: the
// camera ray 0, the reflected child of ray r 2r + 1, the transmitted 2r + 2 (mod 2^32).
uvec2 g_pixel;
int g_sample;
uint g_ray_key;

// Where a secondary or shadow ray leaving P on the side of n starts: P itself on an analytic
// shape (scene_hit and occluded never meet it there again), else Waechter and Binder's offset.
vec3 ray_origin(vec3 P, vec3 n, int shape) {
    return shape >= 0 ? P : offset_ray_origin(P, n);
}

// The facet rule (docs/conventions.md, "The facet normal"): a point whose facet, on the side
// its lit normal N faces, is turned from the light (towards L) is not reached by it, with no
// shadow ray cast: on a closed mesh the ray would be blocked by the solid behind anyway; on an
// open one (a bowl's rim, a sheet) it would pass behind the facet and light its other side. A
// sphere's or plane's geometric normal is its lit normal: never turned where it is lit.
bool facet_turned_from(vec3 N, vec3 L) {
    vec3 facet = dot(g_geometric_normal, N) >= 0.0 ? g_geometric_normal : -g_geometric_normal;
    return dot(facet, L) < 0.0;
}

#if NUM_DIRECTIONAL_LIGHTS > 0
float light_visibility_directional(int i, vec3 P, vec3 N) {
    vec3 L = normalize(-u_directional_direction[i]);
    if (facet_turned_from(N, L)) {
        return 0.0;
    }
    vec3 n = dot(g_geometric_normal, L) >= 0.0 ? g_geometric_normal : -g_geometric_normal;
    return occluded(ray_origin(P, n, g_shape), L, TRACE_INF, g_shape) ? 0.0 : 1.0;
}
#endif
#if NUM_POINT_LIGHTS > 0 || defined(PATH_TRACE)
// 0 where the shadow ray from P to the point Q (a point light, or a point of an area light) is
// blocked, else 1. It ends short of Q by the hit tie (s_max = d (1 - TRACE_HIT_TIE)): a surface
// through Q itself (a light lying in a plane) ties with the light, which keeps it.
float light_visibility_at(vec3 Q, vec3 P) {
    vec3 n = dot(g_geometric_normal, Q - P) >= 0.0 ? g_geometric_normal : -g_geometric_normal;
    vec3 O = ray_origin(P, n, g_shape);
    vec3 to_light = Q - O;
    float d = sqrt(dot(to_light, to_light));
    return (d > 0.0 && occluded(O, to_light / d, d * (1.0 - TRACE_HIT_TIE), g_shape)) ? 0.0 : 1.0;
}
#endif
#if NUM_POINT_LIGHTS > 0

float light_visibility_point(int i, vec3 P, vec3 N) {
    if (facet_turned_from(N, u_point_position[i] - P)) {
        return 0.0;
    }
    return light_visibility_at(u_point_position[i], P);
}
#endif

#include "raytrace/area_lights.glsl"     // after light_visibility_at, which it calls

#include "raytrace/glossy.glsl"

// Hall and Greenberg's adaptive tree depth (1983): a secondary ray whose weight is below
// TRACE_WEIGHT_CUTOFF in every channel is not spawned (renderer/core/ray_depth.py: the rule,
// its RAY_WEIGHT_CUTOFF and max_rays, which these mirror). The energy rule kr + kt <= 1 makes
// the children's weights sum to at most their parent's in each channel, so at most
// 3 / cutoff = 1536 rays of one depth reach the cut-off: depth d has at most min(2^d, 1536)
// rays (2^d up to d = 10), which bounds the loop for any MAX_DEPTH.
const float TRACE_WEIGHT_CUTOFF = 1.0 / 512.0;
#define TRACE_RAYS_PER_DEPTH 1536
#if MAX_DEPTH <= 10
#define TRACE_MAX_RAYS ((2 << MAX_DEPTH) - 1)
#else
#define TRACE_MAX_RAYS (2047 + (MAX_DEPTH - 10) * TRACE_RAYS_PER_DEPTH)
#endif

#ifdef SECONDARY
// The rays waiting to be traced: a ray that spawns both a reflected and a transmitted ray goes
// on with the reflected one and leaves the transmitted one here, so at most one waits per depth
// (MAX_DEPTH in all). llvmpipe reads and writes an array at a per-lane index lane by lane (a
// store is a branch per lane and component), so a short stack compares the index with each
// slot instead (TRACE_STACK_SELECT: up to 12 slots that is fewer instructions).
#define TRACE_STACK MAX_DEPTH
#if TRACE_STACK <= 12
#define TRACE_STACK_SELECT
#endif
vec3 stack_O[TRACE_STACK];
vec3 stack_D[TRACE_STACK];
vec3 stack_w[TRACE_STACK];
int stack_depth[TRACE_STACK];
int stack_from[TRACE_STACK];            // the analytic shape a ray starts on, or -1
uint stack_key[TRACE_STACK];            // the ray's key (g_ray_key)

void trace_store(int i, vec3 O, vec3 D, vec3 w, int depth, int from_shape, uint key) {
    stack_O[i] = O;
    stack_D[i] = D;
    stack_w[i] = w;
    stack_depth[i] = depth;
    stack_from[i] = from_shape;
    stack_key[i] = key;
}

void trace_load(int i, out vec3 O, out vec3 D, out vec3 w, out int depth, out int from_shape,
                out uint key) {
    O = stack_O[i];
    D = stack_D[i];
    w = stack_w[i];
    depth = stack_depth[i];
    from_shape = stack_from[i];
    key = stack_key[i];
}

void trace_push(int top, vec3 O, vec3 D, vec3 w, int depth, int from_shape, uint key) {
#ifdef TRACE_STACK_SELECT
    for (int i = 0; i < TRACE_STACK; ++i) {
        if (i == top) trace_store(i, O, D, w, depth, from_shape, key);
    }
#else
    trace_store(top, O, D, w, depth, from_shape, key);
#endif
}

void trace_pop(int top, out vec3 O, out vec3 D, out vec3 w, out int depth, out int from_shape,
               out uint key) {
#ifdef TRACE_STACK_SELECT
    trace_load(0, O, D, w, depth, from_shape, key);
    for (int i = 1; i < TRACE_STACK; ++i) {
        if (i == top) trace_load(i, O, D, w, depth, from_shape, key);
    }
#else
    trace_load(top, O, D, w, depth, from_shape, key);
#endif
}
#endif

#ifdef MOTION
// The camera sample's time in the shutter: its TIME_DIMENSION number at slot 0 (the camera's).
float trace_sample_time() {
    return motion_time(u_shutter, distributed_1d(g_pixel, g_sample, 0u, TIME_DIMENSION));
}
#endif

#ifdef TEXTURES
#include "raytrace/textures.glsl"
#endif

// The nearest hit of a ray at `depth` of a tree or path (scene_hit): the camera ray's (depth 0)
// between s_min and s_max, its hit and s recorded in hit and s_hit; a later ray's from
// trace_s_min(O) on.
int ray_hit(vec3 O, vec3 D, int depth, float s_min, float s_max, int from_shape, out int index,
            out float s, out vec2 uv, inout bool hit, inout float s_hit) {
    int kind = scene_hit(O, D, depth == 0 ? s_min : trace_s_min(O), depth == 0 ? s_max : TRACE_INF,
                         from_shape, index, s, uv);
    if (depth == 0) {
        hit = kind != TRACE_MISS;
        s_hit = s;
    }
    return kind;
}

// The share of the light a refracted ray brings back through a surface of Fresnel reflectance F,
// eta = n_i / n_t the indices on the ray's side over the far side's: 1 - F, and under
// RADIANCE_SCALING (the physical model, renderer/core/physical.py) times eta^2, radiance being
// n^2 times as high in a medium of index n (renderer/core/raytrace_scene.py radiance_scaling).
float transmitted_share(float F, float eta) {
#ifdef RADIANCE_SCALING
    return (1.0 - F) * (eta * eta);
#else
    return 1.0 - F;
#endif
}

// The hit's material (rows m0, m1, m2 of u_materials) into lighting.glsl's variables, the viewer
// at the ray's origin O, its texture applied; and the hit's geometric normal, shape and ray key
// for its shadow rays and distributed numbers.
void shade_hit(vec4 m0, vec4 m1, vec4 m2, int obj, int kind, int index, vec3 P, vec2 uv, vec3 O,
               vec3 Ng, uint key) {
    u_ka = m0.xyz;
    u_kd = m1.xyz;
#ifdef SPECULAR
    u_ks = m2.xyz;
    u_n = m0.w;
    u_eye = O;
#endif
#ifdef TEXTURES
    texture_modulate(obj, kind, index, P, uv);
#endif
    g_geometric_normal = Ng;
    g_shape = kind == TRACE_SPHERE ? index : kind == TRACE_PLANE ? NUM_SPHERES + index : -1;
    g_ray_key = key;
}

#ifndef PATH_TRACE             // the path tracer has its own loop (pathtrace.glsl)
// The colour seen along the ray O + s D (s_min < s < s_max for this first ray; its children
// from 0 to infinity); hit and s: the first ray's hit.
vec3 trace(vec3 O0, vec3 D0, float s_min, float s_max, out bool hit, out float s_hit) {
    vec3 colour = vec3(0.0);
    vec3 O = O0;
    vec3 D = D0;
    vec3 w = vec3(1.0);
    int depth = 0;
    int from_shape = -1;
    uint key = 0u;
#ifdef SECONDARY
    int top = 0;
#endif
    hit = false;
    s_hit = s_max;
#ifdef MOTION
    trace_motion_at(trace_sample_time());
#endif
    // Whether to go on is tested at the end of the body, not at the top, and no `continue`:
    // llvmpipe runs a loop's body with lanes masked off until every lane of its SIMD group has
    // left, so a test at the top costs one more whole body, masked, per group.
    for (int k = 0; k < TRACE_MAX_RAYS; ++k) {
        int index;
        float s;
        vec2 uv;
        int kind = ray_hit(O, D, depth, s_min, s_max, from_shape, index, s, uv, hit, s_hit);
        bool next = false;                  // a child of this ray is traced next
        if (kind == TRACE_MISS) {
            colour += w * u_background;
        } else {
            vec3 P, Ng, Ns;
            int obj;
            surface(O, D, kind, index, s, uv, P, Ng, Ns, obj);
            vec3 Du = normalize(D);
            bool back = dot(Du, Ng) > 0.0;
            vec4 m0 = trace_texel(u_materials, 5 * obj);
            vec4 m1 = trace_texel(u_materials, 5 * obj + 1);
            vec4 m2 = trace_texel(u_materials, 5 * obj + 2);
            shade_hit(m0, m1, m2, obj, kind, index, P, uv, O, Ng, key);
            vec3 N = (back && m1.w > 0.5) ? -Ns : Ns;
            colour += w * lighting(P, N);
#ifdef SECONDARY
            if (depth < MAX_DEPTH) {
                vec3 kr = trace_texel(u_materials, 5 * obj + 3).xyz;
                vec4 m4 = trace_texel(u_materials, 5 * obj + 4);
                vec3 kt = m4.xyz;
                vec3 N_in = back ? -Ns : Ns;
                vec3 Ng_in = back ? -Ng : Ng;
                float eta = back ? m2.w : 1.0 / m2.w;
                float F = m4.w > 0.5 ? fresnel_exact(Du, N_in, eta) : fresnel_schlick(Du, N_in, eta);
                vec3 w_r = w * (kr + kt * F);
                vec3 w_t = w * (kt * transmitted_share(F, eta));
                vec3 T;
                bool refracted = ray_refract(Du, N_in, eta, T);
                bool transmit = any(greaterThanEqual(w_t, vec3(TRACE_WEIGHT_CUTOFF))) && refracted;
                bool reflect = any(greaterThanEqual(w_r, vec3(TRACE_WEIGHT_CUTOFF)));
                vec3 R = ray_reflect(Du, N_in);
#ifdef GLOSSY
                if (reflect)
                    reflect = glossy_direction(R, Ng_in, trace_texel(u_materials, 5 * obj + 3).w, R);
#endif
                vec3 O_t = ray_origin(P, -Ng_in, g_shape);
                if (transmit && reflect) {      // the reflected ray first, then this one
                    trace_push(top, O_t, T, w_t, depth + 1, g_shape, 2u * key + 2u);
                    ++top;
                }
                if (reflect) {
                    O = ray_origin(P, Ng_in, g_shape);
                    D = R;
                    w = w_r;
                    key = 2u * key + 1u;
                } else if (transmit) {
                    O = O_t;
                    D = T;
                    w = w_t;
                    key = 2u * key + 2u;
                }
                depth += 1;
                from_shape = g_shape;
                next = transmit || reflect;
            }
#endif
        }
#ifdef SECONDARY
        if (!next && top == 0) break;
        if (!next) {
            --top;
            trace_pop(top, O, D, w, depth, from_shape, key);
        }
#else
        break;
#endif
    }
    return colour;
}
#endif

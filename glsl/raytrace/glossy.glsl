// Twin: reference/raytrace/glossy.py
// Glossy reflection (docs/conventions.md, "Glossy reflection"), included by trace.glsl, whose
// g_pixel, g_sample and g_ray_key it reads. Compiled under GLOSSY (renderer/gpu/raytracer.py).
#ifdef GLOSSY
#include "raytrace/sampling.glsl"
#include "raytrace/warp.glsl"
// The direction D of the ray reflected at the hit being shaded, with mirror direction R,
// outward geometric normal Ng_in on the incoming side and lobe exponent `gloss`:
// square_to_phong_lobe of the hit's GLOSSY_DIMENSION point in the basis (orthonormal_basis(R),
// R). False where D lies below the surface (D.Ng_in <= 0): the ray is absorbed. A mirror
// (gloss inf) takes R exactly.
bool glossy_direction(vec3 R, vec3 Ng_in, float gloss, out vec3 D) {
    D = R;
    if (isinf(gloss)) return true;
    vec2 u = distributed_2d(g_pixel, g_sample, 1u + g_ray_key, GLOSSY_DIMENSION, 0u, 1u);
    vec3 lobe = square_to_phong_lobe(u, gloss);
    vec3 b1, b2;
    orthonormal_basis(R, b1, b2);
    D = lobe.x * b1 + lobe.y * b2 + lobe.z * R;
    return dot(D, Ng_in) > 0.0;
}
#endif

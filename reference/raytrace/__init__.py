"""The ray tracer's NumPy twin, stage by stage (glsl/raytrace/ holds the GLSL of the same names):
random.py (the counter-based hash), intersect.py (ray against plane, sphere, triangle), camera.py
(primary rays), optics.py (reflection, refraction, Schlick, the self-intersection offset) and
bvh.py (the closest hit through a BVH)."""

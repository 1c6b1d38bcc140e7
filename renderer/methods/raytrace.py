"""The ray tracer (docs/conventions.md, "Ray tracing"; glsl/raytrace/, twin
reference/raytrace/pipeline.py), registered as method "raytrace": RayTracer on the GPU, the
reference ray tracer behind the same protocol. Its options are RayOptions, whose lens
overrides open_renderer applies to the scene before either backend sees it."""

from __future__ import annotations

from renderer.core.frame import Frame
from renderer.core.memory import raytrace_need
from renderer.core.ray_options import RayOptions
from renderer.methods.reference_backend import ReferenceRenderer
from renderer.methods.registry import Method


class ReferenceRayTracer(ReferenceRenderer):
    """reference/raytrace/pipeline.py's render for the Renderer protocol: the scene's
    surfaces and BVH (ray_scene) made on the first frame and kept until update()."""

    default_precision = "float32"          # the GPU's twin; float64 is the truth

    def __init__(self, scene, width, height, options: RayOptions, precision=None,
                 subpixel_bits=None):
        super().__init__(scene, width, height, options, precision)
        self._ray_scene = None

    @property
    def ray_scene(self):
        """The scene's surfaces and BVH (renderer/core/raytrace_scene.py), made once."""
        if self._ray_scene is None:
            from renderer.core.raytrace_scene import ray_scene
            self._ray_scene = ray_scene(self.scene)
        return self._ray_scene

    @ray_scene.setter
    def ray_scene(self, made) -> None:
        """One made before for this scene (a study's settings share its BVH)."""
        self._ray_scene = made

    def _scene_changed(self) -> None:
        self._ray_scene = None

    def reseed(self, seed: int) -> None:
        self.options = self.options.replace(seed=seed)

    def _frame(self, *, linear: bool, depth: bool, progress=None, first_sample: int = 0) -> Frame:
        from reference.raytrace.pipeline import render
        o = self.options
        rows = self.height
        told = None if progress is None else (lambda share: progress(int(rows * share), rows))
        return render(self.scene, self.width, self.height, samples=o.samples, pattern=o.pattern,
                      max_depth=o.max_depth, seed=o.seed, shadows=o.shadows, rs=self.ray_scene,
                      first_sample=first_sample, adaptive_threshold=o.adaptive_threshold,
                      dtype=self.dtype, light_samples=o.light_samples, progress=told,
                      **self._render_keywords())

    def _render_keywords(self) -> dict:
        """More of reference/raytrace/pipeline.py render's keywords (the path tracer's tracer)."""
        return {}


def _open_gpu(scene, width, height, options: RayOptions, context, context_kind):
    from renderer.gpu.raytracer import RayTracer
    return RayTracer(scene, width, height, options, context=context, context_kind=context_kind)


def _open_reference(scene, width, height, options, precision, subpixel_bits):
    return ReferenceRayTracer(scene, width, height, options, precision)


def _samples(options: RayOptions) -> int:
    return options.samples * options.light_samples


def _need(size, backends, options: RayOptions):
    return raytrace_need(size, backends, _samples(options))


def samples_fired(frame: Frame) -> str:
    """What an adaptive frame traced: 'mean 4.72 spp, 6.0% of pixels refined'."""
    from renderer.core.ray_sampling import FIRST_SET
    return f"mean {frame.samples.mean():.2f} spp, {(frame.samples > FIRST_SET).mean():.1%} of pixels refined"


def _words(options: RayOptions, frame: Frame) -> str:
    if options.pattern == "adaptive":
        return f"raytrace adaptive up to {options.samples} spp: {samples_fired(frame)}"
    return f"raytrace {options.samples} spp"


METHOD = Method("raytrace", "ray tracer", RayOptions, _open_gpu, _open_reference, _need,
                _words, _samples, progressive=True, seeded=True, shutter=True)

"""Write the manual's pictures that no other tool makes, each from the current code
(tests/test_docs_images.py makes them again and holds them to the committed files):

classic-raytrace.png   (docs/ray-tracing.md) the built-in `classic` scene ray traced at
                       640 x 480, 16 jittered samples per pixel: the pixels of
                       `renderer render classic --method raytrace --spp 16 --pattern jittered`.
distributed-soft_shadows.png, distributed-depth_of_field.png, distributed-motion_blur.png,
distributed-glossy.png (docs/ray-tracing.md, "Distributed ray tracing") each built-in scene
                       ray traced at 320 x 240, 64 jittered samples per pixel, and for
                       `soft_shadows` 4 light samples per hit: `renderer render SCENE --method
                       raytrace --spp 64 --pattern jittered [--light-samples 4]`.
shadow-scenes.png      (docs/ray-tracing.md, "Shadows against ray-cast truth") 960 x 480: the
                       three shadow scenes (`shadow_plane`, `shadow_room`, `shadow_curved`)
                       rasterised with their shadow maps at 320 x 240 (default settings: pcf2x2,
                       automatic bias and resolution) on top and, below each, its pixels held
                       against ray-cast truth (renderer/checks/shadow_truth.py, the image of
                       `renderer compare SCENE --shadows-vs-truth`: lit grey, shadowed dark grey,
                       wrongly lit within a texel of the true edge yellow, not held black).
gallery.png            (README) a contact sheet (tools/contact_sheet.py), 4 x 2 labelled panels
                       of 240 x 180 (GALLERY below): rasterised with default settings `sphere`
                       (Phong), `gouraud_vs_phong`, `shadow_room` (cube shadow maps), `globe`
                       (trilinear texture); ray traced with jittered samples `classic` (16 per
                       pixel), `soft_shadows` (16, and 4 light samples per hit),
                       `depth_of_field` (32); and `coloured_lights` rasterised, its linear
                       colour through the GPU output stage at 1 bit per channel with blue noise
                       (sRGB transfer).

Every GPU picture is drawn on EGL (llvmpipe here), with the scene's own settings otherwise
and the ray tracer's default seed and depth: deterministic on one machine. The pixels written
are each frame's rgba8 (what `renderer render -o X.png` writes), the output stage's codes for
the 1-bit panel.

    PYTHONPATH=. .venv/bin/python tools/make_docs_images.py                  # every image, into docs/images/
    PYTHONPATH=. .venv/bin/python tools/make_docs_images.py gallery.png      # only those named
    PYTHONPATH=. .venv/bin/python tools/make_docs_images.py --folder /tmp/imgs  # elsewhere
"""

from __future__ import annotations

import argparse
import io
from pathlib import Path

import numpy as np

from contact_sheet import contact_sheet

ROOT = Path(__file__).resolve().parent.parent
FOLDER = ROOT / "docs" / "images"

CLASSIC = ("classic", (640, 480), dict(samples=16, pattern="jittered"))
DISTRIBUTED = {name: (name, (320, 240), dict(samples=64, pattern="jittered",
                                            light_samples=4 if name == "soft_shadows" else 1))
               for name in ("soft_shadows", "depth_of_field", "motion_blur", "glossy")}
SHADOW_SCENES = ("shadow_plane", "shadow_room", "shadow_curved")
SHADOW_SIZE = (320, 240)

GALLERY_SIZE = (240, 180)
GALLERY_COLUMNS = 4
GALLERY_LABEL_HEIGHT = 20
# (label, scene, what draws it): "raster" (default settings), ("raytrace", RayOptions fields),
# ("output", OutputSettings fields) the rasterised frame's linear colour through the GPU
# output stage (the transfer always sRGB, `renderer render --transfer srgb ...`).
GALLERY = (
    ("sphere: Phong shading", "sphere", "raster"),
    ("gouraud_vs_phong: Gouraud | Phong", "gouraud_vs_phong", "raster"),
    ("shadow_room: cube shadow maps", "shadow_room", "raster"),
    ("globe: trilinear texture", "globe", "raster"),
    ("classic: ray traced mirror and glass", "classic", ("raytrace", dict(samples=16, pattern="jittered"))),
    ("soft_shadows: ray traced area light", "soft_shadows",
     ("raytrace", dict(samples=16, pattern="jittered", light_samples=4))),
    ("depth_of_field: ray traced thin lens", "depth_of_field",
     ("raytrace", dict(samples=32, pattern="jittered"))),
    ("coloured_lights: 1 bit, blue noise", "coloured_lights", ("output", dict(bits=1, dither="blue-noise"))),
)


def _context():
    from renderer.gpu.context import make_context
    global _CTX
    if _CTX is None:
        _CTX = make_context("egl")
    return _CTX


_CTX = None


def raster(scene_name: str, size: tuple[int, int]) -> np.ndarray:
    """(H, W, 3) uint8: the scene rasterised on the GPU path, default settings."""
    from renderer.core.scene_file import load_scene
    from renderer.methods import open_renderer
    with open_renderer(load_scene(scene_name), size, context=_context()) as gpu:
        return gpu.render().rgba8[..., :3].copy()


def raytrace(scene_name: str, size: tuple[int, int], options: dict) -> np.ndarray:
    """(H, W, 3) uint8: the scene ray traced on the GPU path with RayOptions(**options)."""
    from renderer.core.ray_options import RayOptions
    from renderer.core.scene_file import load_scene
    from renderer.methods import open_renderer
    with open_renderer(load_scene(scene_name), size, method="raytrace", options=RayOptions(**options),
                       context=_context()) as gpu:
        return gpu.render().rgba8[..., :3].copy()


def output_stage(scene_name: str, size: tuple[int, int], settings: dict) -> np.ndarray:
    """(H, W, 3) uint8: the scene rasterised, its linear colour through the GPU output stage
    with the sRGB transfer and OutputSettings(**settings), its codes (1 bit: 0 or 1) scaled to
    0..255 (make_output_figure.py shows its 1-bit panels so)."""
    from renderer.core.output_settings import OutputSettings, Transfer
    from renderer.core.scene_file import load_scene
    from renderer.gpu.output import OutputPass
    from renderer.methods import open_renderer
    with open_renderer(load_scene(scene_name), size, context=_context()) as gpu:
        frame = gpu.render(linear=True, depth=False)
        stage = OutputPass(gpu.ctx)
        try:
            codes = stage.apply(frame.linear, OutputSettings(Transfer("srgb"), **settings))
        finally:
            stage.release()
    return (np.asarray(codes)[..., :3] * 255).astype(np.uint8)


def shadow_scenes() -> np.ndarray:
    """(480, 960, 3) uint8: each shadow scene rasterised (top), its truth classes (bottom)."""
    from renderer.checks.shadow_truth import shadows_vs_truth
    from renderer.core.scene_file import load_scene
    top = [raster(name, SHADOW_SIZE) for name in SHADOW_SCENES]
    bottom = [shadows_vs_truth(load_scene(name), *SHADOW_SIZE).image() for name in SHADOW_SCENES]
    return np.concatenate([np.concatenate(top, axis=1), np.concatenate(bottom, axis=1)], axis=0)


def gallery() -> bytes:
    panels = []
    for label, scene, how in GALLERY:
        if how == "raster":
            image = raster(scene, GALLERY_SIZE)
        elif how[0] == "raytrace":
            image = raytrace(scene, GALLERY_SIZE, how[1])
        else:
            image = output_stage(scene, GALLERY_SIZE, how[1])
        panels.append((label, image))
    return contact_sheet(panels, GALLERY_COLUMNS, GALLERY_LABEL_HEIGHT, font_size=13)


def png(image: np.ndarray) -> bytes:
    from PIL import Image
    buffer = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(image), "RGB").save(buffer, format="PNG", optimize=True)
    return buffer.getvalue()


# Each image's name in docs/images/ -> its PNG bytes, made now.
IMAGES = {
    "classic-raytrace.png": lambda: png(raytrace(*CLASSIC)),
    **{f"distributed-{name}.png": (lambda args=args: png(raytrace(*args)))
       for name, args in DISTRIBUTED.items()},
    "shadow-scenes.png": lambda: png(shadow_scenes()),
    "gallery.png": gallery,
}


def write(name: str, folder: Path = FOLDER) -> Path:
    """Make image `name` (a key of IMAGES) into `folder`; its path."""
    data = IMAGES[name]()
    folder.mkdir(parents=True, exist_ok=True)
    out = folder / name
    out.write_bytes(data)
    return out


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("names", nargs="*", metavar="NAME.png",
                        help=f"the images to make (default: all of {', '.join(IMAGES)})")
    parser.add_argument("--folder", type=Path, default=FOLDER, metavar="FOLDER",
                        help="the folder to write into (default: docs/images/)")
    args = parser.parse_args(argv)
    unknown = [name for name in args.names if name not in IMAGES]
    if unknown:
        parser.error(f"no maker here for {', '.join(unknown)}; one of {', '.join(IMAGES)}")
    for name in args.names or IMAGES:
        out = write(name, args.folder)
        print(f"{out}: {out.stat().st_size:,} bytes")


if __name__ == "__main__":
    main()

"""Write the generated textures and the textured glTF in assets/ (run from anywhere; the
output is deterministic: every pixel is computed here, nothing is downloaded).

    python tools/make_texture_assets.py

textures/globe.png   512 x 256 equirectangular "globe" (scene globe): u = 1/2 + longitude /
                     360 degrees, v = 1/2 + latitude / 180 (docs/conventions.md, "Texture
                     coordinates"); a colour per 30-degree latitude band (warm north, cool
                     south), the eastern hemisphere lighter than the western, graticule
                     lines every 30 degrees, the prime meridian white with a magenta disc
                     where it meets the equator (what faces +z), so a rotation shows
textures/crate.png   256 x 256 crate: planks, a frame, a diagonal brace
textures/heights.png 64 x 64 height image (scene displaced_plane; linear, grey: the red channel
                     is the height): a low dome, two crossed ridges and a ring of ripples,
                     0.1 to 0.9, every step between neighbouring texels small
meshes/textured_box.glb
                     a 2 x 1.2 x 1 box whose every face carries the whole 160 x 96 (NPOT)
                     label texture embedded as its base colour (TEXCOORD_0 and
                     baseColorTexture, written by trimesh's exporter; scene textured_mesh).
                     The label's corners are marked: top left red, top right green, bottom
                     left blue, bottom right yellow; an arrow points up the image (+v)

The images are sRGB-encoded 8-bit PNGs; colours below are sRGB bytes.
"""

from __future__ import annotations

import io
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

ASSETS = ROOT / "assets"

# Latitude bands from the north pole down, 30 degrees each (sRGB).
BANDS = np.array([[200, 60, 50], [230, 140, 40], [225, 205, 60],
                  [70, 170, 80], [50, 150, 190], [70, 70, 180]], dtype=np.float64)
LABEL_CORNERS = {"top_left": (220, 30, 30), "top_right": (30, 190, 60),
                 "bottom_left": (40, 70, 220), "bottom_right": (240, 210, 30)}
LABEL_SIZE = (160, 96)                                         # width, height: NPOT
BOX_SIZE = (2.0, 1.2, 1.0)


def globe(width: int = 512, height: int = 256) -> np.ndarray:
    """The equirectangular globe (module docstring), (H, W, 3) uint8, row 0 at the top."""
    u = (np.arange(width) + 0.5) / width
    v = 1.0 - (np.arange(height) + 0.5) / height
    longitude = (u - 0.5) * 360.0                              # degrees, east positive (+x)
    latitude = (v - 0.5) * 180.0
    lon, lat = np.meshgrid(longitude, latitude)
    band = np.clip(((90.0 - lat) // 30.0).astype(int), 0, 5)
    image = BANDS[band] * np.where(lon > 0.0, 1.0, 0.7)[..., None]
    texel = 360.0 / width                                      # degrees per texel
    near_line = lambda a, step: np.abs((a + step / 2) % step - step / 2) < texel   # noqa: E731
    image[near_line(lon, 30.0) | near_line(lat, 30.0)] = (25, 25, 25)
    image[np.abs(lon) < 1.5 * texel] = (255, 255, 255)         # the prime meridian
    image[np.hypot(lon, lat) < 8.0] = (230, 40, 200)           # longitude 0, latitude 0
    return np.round(image).astype(np.uint8)


def crate(size: int = 256) -> np.ndarray:
    """Planks (alternating browns, a dark gap every 32 texels), a frame 24 texels wide and a
    diagonal brace from bottom left to top right, (size, size, 3) uint8."""
    y, x = np.mgrid[0:size, 0:size].astype(np.float64) + 0.5
    plank = (y // 32).astype(int) % 2
    grain = 8.0 * np.sin(x / 9.0 + 3.0 * plank) * np.sin(y / 3.0)
    image = np.where(plank[..., None] == 0, [150, 105, 60], [135, 92, 52]) + grain[..., None]
    image[(y % 32) < 2] = (70, 45, 25)
    frame = (np.minimum(np.minimum(x, size - x), np.minimum(y, size - y)) < 24)
    brace = np.abs(x - (size - y)) < 18
    image[frame | brace] = (175, 125, 70)
    edge = (np.abs(np.minimum(np.minimum(x, size - x), np.minimum(y, size - y)) - 24) < 1.5)
    image[edge] = (70, 45, 25)
    return np.round(np.clip(image, 0, 255)).astype(np.uint8)


def label(width: int = LABEL_SIZE[0], height: int = LABEL_SIZE[1]) -> np.ndarray:
    """Cardboard with a dark border, corner squares (LABEL_CORNERS) and an arrow pointing to
    the top of the image, (height, width, 3) uint8."""
    y, x = np.mgrid[0:height, 0:width].astype(np.float64) + 0.5
    image = np.empty((height, width, 3))
    image[:] = (196, 160, 110)
    border = np.minimum(np.minimum(x, width - x), np.minimum(y, height - y)) < 4
    image[border] = (90, 60, 35)
    corner = 16
    left, top = x < corner, y < corner
    right, bottom = x > width - corner, y > height - corner
    for name, mask in (("top_left", top & left), ("top_right", top & right),
                       ("bottom_left", bottom & left), ("bottom_right", bottom & right)):
        image[mask] = LABEL_CORNERS[name]
    cx = width / 2
    shaft = (np.abs(x - cx) < 8) & (y > height * 0.45) & (y < height * 0.85)
    head = (y > height * 0.15) & (y <= height * 0.45) & (np.abs(x - cx) < (y - height * 0.15) * 0.9)
    image[shaft | head] = (40, 30, 25)
    return image.astype(np.uint8)


def heights(size: int = 64) -> np.ndarray:
    """The height image (module docstring), (H, W, 3) uint8 grey, row 0 at the top (v = 1)."""
    u = (np.arange(size) + 0.5) / size
    v = 1.0 - (np.arange(size) + 0.5) / size
    x, y = np.meshgrid(u - 0.5, v - 0.5)
    r = np.hypot(x, y)
    dome = 0.35 * np.exp(-(r / 0.22) ** 2)
    ridges = 0.12 * (np.exp(-((x - y) / 0.05) ** 2) + np.exp(-((x + y - 0.3) / 0.06) ** 2))
    ripples = 0.08 * np.cos(2 * np.pi * r / 0.12) * np.exp(-((r - 0.36) / 0.08) ** 2)
    height = np.clip(0.15 + dome + ridges + ripples, 0.1, 0.9)
    return np.repeat(np.round(height * 255).astype(np.uint8)[..., None], 3, axis=2)


def png_bytes(image: np.ndarray) -> bytes:
    from PIL import Image

    buffer = io.BytesIO()
    Image.fromarray(image, "RGB").save(buffer, format="PNG", optimize=True)
    return buffer.getvalue()


def textured_box() -> bytes:
    """The box as GLB bytes: primitives.cube's faces and UVs (each face [0, 1]² seen from
    outside), scaled to BOX_SIZE, the label as the embedded base-colour texture."""
    import trimesh
    from PIL import Image

    from renderer.core.primitives import cube

    box = cube(2.0)
    positions = box.positions / 2.0 * np.asarray(BOX_SIZE)
    material = trimesh.visual.material.PBRMaterial(
        name="label", baseColorTexture=Image.fromarray(label(), "RGB"),
        baseColorFactor=[255, 255, 255, 255], metallicFactor=0.0, roughnessFactor=1.0)
    mesh = trimesh.Trimesh(positions, box.faces, vertex_normals=box.normals, process=False,
                           visual=trimesh.visual.TextureVisuals(uv=box.uvs, material=material))
    return trimesh.Scene(mesh).export(file_type="glb")


def main() -> None:
    outputs = {
        ASSETS / "textures" / "globe.png": png_bytes(globe()),
        ASSETS / "textures" / "crate.png": png_bytes(crate()),
        ASSETS / "textures" / "heights.png": png_bytes(heights()),
        ASSETS / "meshes" / "textured_box.glb": textured_box(),
    }
    for path, data in outputs.items():
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data)
        print(f"{path.relative_to(ROOT)}: {len(data):,} bytes")


if __name__ == "__main__":
    main()

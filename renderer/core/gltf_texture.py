"""A glTF / GLB file's base-colour texture as the material texture of the mesh it holds.

trimesh reads the geometry and TEXCOORD_0 (renderer/core/meshio.py); this module reads the
file's own JSON for what trimesh does not keep: which image the materials' base-colour
texture is, its sampler's wrap modes and the baseColorFactor. The result (scene files use it
where the object sets no texture itself: docs/scene-format.md):

- the image, decoded as sRGB (glTF's rule for base colour), times baseColorFactor's RGB
  (linear; its alpha is ignored, as all alpha is) before the mip chain is made;
- wrap: the sampler's wrapS, which must equal its wrapT (a material has one wrap mode);
  repeat without a sampler; filter trilinear (the sampler's filters are not read);
- one texture per mesh: every primitive the file draws must have the same base colour
  (texture, factor, sampler), since the file becomes one Mesh with one material;
- TEXCOORD_0 only (a texture naming texCoord 1 is refused); KHR_texture_transform is not read.
"""

from __future__ import annotations

import base64
import json
import struct
from pathlib import Path
from urllib.parse import unquote

from renderer.core import gl_rules
from renderer.core.user_files import MESH_FILE, FileRefused, read_resource, read_user_file
from renderer.core.textures import MaterialTexture, Sampler, texture_from_bytes
from renderer.errors import SceneError

GLB_MAGIC = b"glTF"
GLB_JSON, GLB_BIN = 0x4E4F534A, 0x004E4942          # chunk types "JSON", "BIN\0"
# glTF's sampler names wrap modes by their GL enums
WRAP_MODES = {enum: wrap for wrap, enum in gl_rules.TEXTURE_WRAP_MODES.items()}


class _Problem(Exception):
    pass


def base_colour_texture(path, *, source: str | None = None,
                        key: str | None = None) -> MaterialTexture | None:
    """The file's base-colour texture (module docstring), None where its materials have
    none, or a one-line SceneError naming `source`, `key` and the file."""
    path = Path(path)
    try:
        header, binary = _read(path)
        used = _base_colours(header)
        if not used or all(colour is None for colour in used):
            return None
        if len(set(used)) > 1:
            raise _Problem("its primitives have different base colours (textures, factors or "
                           "samplers) or some have no texture; a mesh takes one texture: set "
                           "the object's material texture instead")
        image, factor, wrap = used[0]
        data = _image_bytes(header, binary, image, path.parent)
    except _Problem as problem:
        if source is not None:
            raise SceneError(f"{path}: {problem}", file=source, key=key) from None
        raise SceneError(str(problem), file=str(path), key=key) from None
    texture = texture_from_bytes(data, f"{path} (base colour)", "srgb", tint=factor,
                                 source=source, key=key)
    return MaterialTexture(texture, Sampler(wrap=wrap))


def _read(path: Path) -> tuple[dict, bytes]:
    """The JSON header and the GLB's binary chunk (b"" for .gltf)."""
    try:
        data = read_user_file(path, MESH_FILE)
    except FileRefused as refused:
        raise _Problem(refused.reason) from None
    binary = b""
    if data[:4] == GLB_MAGIC:
        offset, chunks = 12, {}
        while offset + 8 <= len(data):
            length, kind = struct.unpack_from("<II", data, offset)
            chunks.setdefault(kind, data[offset + 8:offset + 8 + length])
            offset += 8 + length
        text, binary = chunks.get(GLB_JSON, b""), chunks.get(GLB_BIN, b"")
    else:
        text = data
    try:
        header = json.loads(text)
    except (ValueError, UnicodeDecodeError) as exc:
        raise _Problem(f"its glTF JSON could not be read: {exc}") from None
    if not isinstance(header, dict):
        raise _Problem("its glTF JSON is not an object")
    return header, binary


def _base_colours(header: dict) -> list:
    """(image index, factor RGB, wrap) or None per primitive the meshes draw, in order."""
    used = []
    for mesh in header.get("meshes", []):
        for primitive in mesh.get("primitives", []):
            used.append(_base_colour(header, primitive.get("material")))
    return used


def _base_colour(header: dict, material):
    try:
        pbr = header["materials"][material].get("pbrMetallicRoughness", {}) \
            if material is not None else {}
        reference = pbr.get("baseColorTexture")
        if reference is None:
            return None
        if reference.get("texCoord", 0) != 0:
            raise _Problem(f"material {material}'s base-colour texture uses TEXCOORD_"
                           f"{reference['texCoord']}; only TEXCOORD_0 is read")
        texture = header["textures"][reference["index"]]
        factor = tuple(float(x) for x in pbr.get("baseColorFactor", (1.0, 1.0, 1.0, 1.0))[:3])
        sampler = header["samplers"][texture["sampler"]] if "sampler" in texture else {}
        wrap_s, wrap_t = sampler.get("wrapS", gl_rules.GL_REPEAT), sampler.get("wrapT", gl_rules.GL_REPEAT)
        if wrap_s != wrap_t:
            raise _Problem(f"material {material}'s base-colour sampler has wrapS {wrap_s} and "
                           f"wrapT {wrap_t}; a material has one wrap mode")
        if wrap_s not in WRAP_MODES:
            raise _Problem(f"material {material}'s base-colour sampler has an unknown wrap "
                           f"mode {wrap_s}")
        return texture["source"], factor, WRAP_MODES[wrap_s]
    except (KeyError, IndexError, TypeError, ValueError, AttributeError) as exc:
        raise _Problem(f"material {material}'s base-colour texture is not valid glTF "
                       f"({type(exc).__name__}: {exc})") from None


def _image_bytes(header: dict, binary: bytes, index: int, folder: Path) -> bytes:
    """The encoded image `index`: a buffer view (of the GLB's chunk or a buffer's uri) or its
    own uri (a data: URI or a file in the glTF's own folder: `_uri_bytes`)."""
    try:
        image = header["images"][index]
        if "bufferView" in image:
            view = header["bufferViews"][image["bufferView"]]
            buffer = header["buffers"][view["buffer"]]
            data = _uri_bytes(buffer["uri"], folder) if "uri" in buffer else binary
            start = view.get("byteOffset", 0)
            return data[start:start + view["byteLength"]]
        return _uri_bytes(image["uri"], folder)
    except (KeyError, IndexError, TypeError) as exc:
        raise _Problem(f"image {index} is not valid glTF ({type(exc).__name__}: {exc})") from None


def _uri_bytes(uri: str, folder: Path) -> bytes:
    """A buffer's or image's bytes: a data: URI's, or those of the file the uri names in the
    glTF's own `folder` (docs/scene-format.md: an absolute path, or one that leaves the
    folder, is refused, as trimesh refuses such buffers), read through user_files."""
    if not isinstance(uri, str):
        raise _Problem(f"a uri is {type(uri).__name__}, not a string")
    if uri.startswith("data:"):
        try:
            return base64.b64decode(uri.split(",", 1)[1])
        except (IndexError, ValueError) as exc:
            raise _Problem(f"a data URI could not be decoded: {exc}") from None
    try:
        return read_resource(folder, unquote(uri), "uri")
    except FileRefused as refused:
        raise _Problem(refused.reason) from None

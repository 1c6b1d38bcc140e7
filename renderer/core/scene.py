"""The scene model shared by the GPU path and the reference.

A scene is plain data: camera, objects (mesh + transform + material), lights, background.
An object may also carry an analytic shape (`Sphere`, `Plane`) for the ray tracer; its `mesh`
is then the shape's tessellation (renderer/core/shapes.py). The rasteriser's camera pass draws
a sphere's tessellation, and for a plane, each frame, the polygon where the plane meets the
view volume (renderer/core/drawn.py).
Both pipelines read it, and both take their matrices from `Scene.matrices()` so that the
only thing they do differently is the pipeline itself. Units and conventions:
docs/conventions.md; the file format: docs/scene-format.md.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np

from renderer.core import transforms
from renderer.core.shadow_settings import Shadow
from renderer.core.textures import MaterialTexture

Projection = Literal["perspective", "parallel"]
ShadingMode = Literal["flat", "gouraud", "phong"]
Cull = Literal["none", "back", "front"]
SHADING_MODES = ("flat", "gouraud", "phong")


@dataclass
class Camera:
    """Eye, look point and up vector as in the notes; projection and clip planes."""
    eye: tuple = (0.0, 0.0, 5.0)
    look: tuple = (0.0, 0.0, 0.0)
    up: tuple = (0.0, 1.0, 0.0)
    projection: Projection = "perspective"
    fov_y: float = 45.0          # degrees, full vertical field of view (perspective)
    height: float = 2.0          # scene units, height of the view volume (parallel)
    near: float = 0.1            # scene units along the viewing axis
    far: float = 100.0
    reversed_z: bool = False     # depth 1 at near, 0 at far (glClipControl ZERO_TO_ONE, GL_GREATER)
    # The ray tracer's thin lens (docs/conventions.md, "Depth of field"; the rasteriser is a
    # pinhole): the lens radius in scene units, None for no lens at all (0 is a lens of radius
    # 0, the pinhole exactly, whose code the reference still runs), and the view depth in
    # focus, None for |look - eye|.
    aperture: float | None = None
    focus_distance: float | None = None
    # The ray tracer's shutter (open, close), open <= close, in the units of time that object
    # velocities are given in; a sample's time lies in [open, close] (renderer/core/motion.py).
    # The rasteriser draws time 0.
    shutter: tuple = (0.0, 0.0)

    def view(self) -> np.ndarray:
        return transforms.look_at(self.eye, self.look, self.up)

    def projection_matrix(self, aspect: float) -> np.ndarray:
        if self.projection == "perspective":
            return transforms.perspective(math.radians(self.fov_y), aspect, self.near, self.far,
                                          self.reversed_z)
        return transforms.orthographic(self.height, aspect, self.near, self.far, self.reversed_z)

    @property
    def focus(self) -> float:
        """The view depth in focus: focus_distance, or the look point's |look - eye|."""
        if self.focus_distance is not None:
            return float(self.focus_distance)
        return float(np.linalg.norm(np.subtract(self.look, self.eye, dtype=np.float64)))

    @property
    def has_lens(self) -> bool:
        """Whether the ray tracer defocuses: an aperture above 0."""
        return self.aperture is not None and self.aperture > 0.0


@dataclass
class Material:
    """The notes' reflection coefficients (RGB, linear) and Phong exponent n."""
    ka: tuple = (0.8, 0.8, 0.8)
    kd: tuple = (0.8, 0.8, 0.8)
    ks: tuple = (0.0, 0.0, 0.0)
    n: float = 32.0
    two_sided: bool = False
    shading: ShadingMode = "phong"
    # The ray tracer's terms (the rasteriser ignores them): reflectance k_r and transmittance
    # k_t (RGB, linear), index of refraction `ior` (> 0). Energy rule: k_r + k_t <= 1 in each
    # channel (ENERGY_SLACK allowed for decimal rounding), so that the reflected and refracted
    # rays together never carry more than the light arriving (docs/scene-format.md).
    kr: tuple = (0.0, 0.0, 0.0)
    kt: tuple = (0.0, 0.0, 0.0)
    ior: float = 1.5
    # Glossy reflection (ray tracer only): the Phong-lobe exponent (>= 0) about the mirror
    # direction from which the reflected ray is drawn (docs/conventions.md, "Glossy
    # reflection"). None, not set, is a mirror as inf is; the reference traces the lobe's code
    # wherever some material sets it, inf included, so that inf = mirror is tested, not assumed.
    gloss: float | None = None
    # A texture (renderer/core/textures.py): its texel multiplies the coefficients it names
    # (texture.modulate) before lighting; None: untextured. The object's mesh needs UVs.
    texture: MaterialTexture | None = None
    # The ray tracer's Fresnel reflectance at a refracting surface: Schlick's approximation
    # (the notes', the default) or the exact dielectric Fresnel equations (FRESNEL_MODES).
    fresnel: str = "schlick"
    # Emitted radiosity E (exitance, linear RGB, >= 0): the light a surface gives off itself.
    # Radiosity (renderer/core/radiosity.py) and the path tracer (renderer/core/path_emitters.py)
    # read it; the rasteriser and the ray tracer light with their lights (docs/scene-format.md).
    emission: tuple = (0.0, 0.0, 0.0)

    @property
    def textured(self) -> bool:
        """Whether a texture modulates this material's coefficients."""
        return self.texture is not None

    @property
    def has_specular(self) -> bool:
        """Whether the lighting has a specular term at all (some k_s not 0). Both pipelines
        leave the term out otherwise (renderer/gpu/shaders.py, reference/lighting.py)."""
        return any(float(k) != 0.0 for k in self.ks)

    @property
    def gloss_exponent(self) -> float:
        """The reflected rays' lobe exponent: `gloss`, or inf (a mirror) where it is not set."""
        return math.inf if self.gloss is None else float(self.gloss)

    @property
    def is_glossy(self) -> bool:
        """Whether the ray tracer draws this material's reflected rays from a lobe: it
        reflects (some k_r or k_t > 0) and its gloss is finite (the GLSL's GLOSSY)."""
        reflects = any(float(k) > 0.0 for k in (*self.kr, *self.kt))
        return reflects and math.isfinite(self.gloss_exponent)


ENERGY_SLACK = 1e-9
FRESNEL_MODES = ("schlick", "exact")


def energy_excess(kr, kt) -> int | None:
    """The first channel in which k_r + k_t > 1 (beyond ENERGY_SLACK), else None."""
    for channel, (r, t) in enumerate(zip(kr, kt)):
        if float(r) + float(t) > 1.0 + ENERGY_SLACK:
            return channel
    return None


@dataclass
class Mesh:
    """A triangle mesh: positions (V, 3) float64, unit normals (V, 3) float64, faces (F, 3) int64,
    and texture coordinates `uvs` (V, 2) float64, or None where it has none.

    Faces are counter-clockwise seen from the side their normals point to. UVs follow GL
    (docs/conventions.md, "Texture coordinates"): u along the image left to right, v from its
    bottom row (0) to its top row (1); a seam has its vertices duplicated.
    """
    positions: np.ndarray
    normals: np.ndarray
    faces: np.ndarray
    source: str = ""             # where it came from, for messages
    # How a primitive was made: (name in renderer.core.primitives.PRIMITIVES, its arguments), so
    # that it can be rebuilt at another tessellation (renderer/study/tessellation.py); None for
    # mesh files.
    recipe: tuple[str, dict] | None = None
    uvs: np.ndarray | None = None

    @property
    def triangle_count(self) -> int:
        return int(len(self.faces))


@dataclass
class Transform:
    """Model transform in the notes' order: scale, shear, rotate (x, y, z), translate."""
    scale: tuple = (1.0, 1.0, 1.0)
    shear: dict = field(default_factory=dict)      # factors named as transforms.SHEAR_FACTORS
    rotate: tuple = (0.0, 0.0, 0.0)                # degrees about x, y, z
    translate: tuple = (0.0, 0.0, 0.0)

    def matrix(self) -> np.ndarray:
        return transforms.model_matrix(self.scale, self.shear,
                                       tuple(math.radians(a) for a in self.rotate),
                                       self.translate)


@dataclass(frozen=True)
class Sphere:
    """An analytic sphere (P - C)·(P - C) = r² in the object's own coordinates, r > 0."""
    centre: tuple = (0.0, 0.0, 0.0)
    radius: float = 1.0


@dataclass(frozen=True)
class Plane:
    """An analytic plane P·N + d = 0 (the notes' form) in the object's own coordinates;
    N not zero, need not be unit. Its front (lit) side is the one N points to."""
    normal: tuple = (0.0, 1.0, 0.0)
    offset: float = 0.0


Shape = Sphere | Plane

# A sphere stays a sphere only under a similarity: the world matrix's linear part A must be
# s·R (R a rotation, s > 0), tested as |A^T A - s² I| <= SIMILARITY_TOLERANCE · s² entrywise
# with s² = trace(A^T A) / 3. Rounding in rotations and parent chains stays far below it.
SIMILARITY_TOLERANCE = 1e-9


@dataclass(frozen=True)
class WorldSphere:
    """A sphere for the ray tracer: centre camera-relative (world centre - origin), radius in
    scene units."""
    centre: np.ndarray
    radius: float


@dataclass(frozen=True)
class WorldPlane:
    """A plane for the ray tracer, P·N + d = 0 with P camera-relative (world P - origin) and N
    a unit vector (the side the object's N points to stays its front)."""
    normal: np.ndarray
    offset: float


def world_shape(shape: Shape, model: np.ndarray, origin=(0.0, 0.0, 0.0)) -> WorldSphere | WorldPlane:
    """The shape through the world matrix `model` (parents applied), relative to `origin`.

    Sphere: under a similarity A = s·R it stays analytic (centre M·C, radius s·r); any other
    linear part (non-uniform scale, shear, a zero scale) is a ValueError: an ellipsoid is not
    a sphere, and the rule is to refuse rather than trace something else (make it a mesh:
    `mesh = { primitive = "icosphere" }`). Plane: any affine M with det A > 0 maps it to a
    plane: N' = cof(A) N (the normal matrix rule, conventions.md), d' = det(A) d - N'·t, then
    normalised; A that flattens the plane onto a line or point (N' = 0) is a ValueError.
    """
    m = np.asarray(model, dtype=np.float64)
    a, t = m[:3, :3], m[:3, 3]
    origin = np.asarray(origin, dtype=np.float64)
    if isinstance(shape, Sphere):
        gram = a.T @ a
        s2 = float(np.trace(gram)) / 3.0
        if not s2 > 0.0 or np.abs(gram - s2 * np.eye(3)).max() > SIMILARITY_TOLERANCE * s2 \
                or np.linalg.det(a) <= 0.0:
            raise ValueError("a sphere's transform (with its parents') must be a uniform scale, "
                             "rotation and translation; a non-uniform or zero scale or a shear "
                             "would make an ellipsoid (use mesh = { primitive = \"icosphere\" } "
                             "for one)")
        centre = a @ np.asarray(shape.centre, dtype=np.float64) + (t - origin)
        return WorldSphere(centre, float(shape.radius) * math.sqrt(s2))
    if isinstance(shape, Plane):
        cofactor = np.cross(a[[1, 2, 0]], a[[2, 0, 1]])     # cof(A) = det(A) A^-T
        det = float(np.linalg.det(a))
        n = cofactor @ np.asarray(shape.normal, dtype=np.float64)
        length = float(np.linalg.norm(n))
        if not length > 0.0 or not math.isfinite(length):
            raise ValueError("the transform (with its parents') flattens the plane onto a line "
                             "or a point: its normal has no direction left")
        d = det * float(shape.offset) - float(n @ t)       # world: N'·P + d = 0
        d += float(n @ origin)                              # camera-relative: P = P_rel + origin
        return WorldPlane(n / length, d / length)
    raise TypeError(f"not a shape: {shape!r}")


@dataclass
class SceneObject:
    name: str
    # What the rasteriser draws: a mesh's triangles, a sphere's tessellation; for a plane, the
    # square of renderer/core/shapes.py, which only the shadow passes draw (the camera pass
    # draws the plane's polygon in its view volume: renderer/core/drawn.py).
    mesh: Mesh
    material: Material = field(default_factory=Material)
    transform: Transform = field(default_factory=Transform)
    parent: str | None = None    # name of another object; its world matrix applies after ours
    cull: Cull = "none"          # which faces GL culls (window-space winding; CCW is front)
    shape: Shape | None = None   # an analytic shape the ray tracer intersects; None: triangles
    casts_shadows: bool = True   # drawn into the lights' shadow maps (renderer/core/shadows.py)
    receives_shadows: bool = True  # looks itself up in them: lit only where a light reaches it
    # Motion blur (the ray tracer; renderer/core/motion.py): scene units per unit time, and
    # degrees per unit time about that axis through the object's world origin. None: the
    # object declares no motion (a zero vector declares it, still). Children do not follow.
    velocity: tuple | None = None
    angular_velocity: tuple | None = None
    # The rasteriser's camera pass draws it through the tessellation stages
    # (renderer/core/tessellation.py Tessellation; an analytic sphere only, for now). None: not.
    tessellation: object | None = None

    def texture_coordinates(self, mesh: Mesh | None = None) -> np.ndarray | None:
        """The UVs (V, 2) of `mesh` (default: the object's own; the camera pass passes what it
        draws, renderer/core/drawn.py) where the material is textured (what its lookup
        reads), None where it is not; a ValueError naming the object for a textured material
        on a mesh without UVs (a scene file is refused so as it loads,
        renderer/core/scene_file.py)."""
        mesh = self.mesh if mesh is None else mesh
        if self.material.texture is None:
            return None
        if mesh.uvs is None:
            raise ValueError(f"object {self.name!r}: its material has a texture but its mesh "
                             f"({mesh.source or 'made in code'}) has no texture coordinates")
        return mesh.uvs


@dataclass
class DirectionalLight:
    """An infinitely distant light; `direction` is the way its light travels."""
    direction: tuple = (0.0, 0.0, -1.0)
    intensity: tuple = (1.0, 1.0, 1.0)
    shadow: Shadow = field(default_factory=Shadow)   # its shadow map (renderer/core/shadows.py)


AreaShape = Literal["rectangle", "disc", "sphere"]
AREA_SHAPES = ("rectangle", "disc", "sphere")


@dataclass(frozen=True)
class LightArea:
    """The area a point light emits from, centred on its position, for the ray tracer's soft
    shadows (docs/conventions.md, "Area lights"; the rasteriser lights from the centre):
    "rectangle" of `size` (w, h) along b1, b2 of the orthonormal basis of `normal`
    (renderer/core/light_areas.py), "disc" of `radius` across `normal`, or "sphere" of
    `radius`. Every point of it is an isotropic point emitter with the light's intensity and
    attenuation (the normal says where the shape lies, not where it shines); size 0 is the
    point light."""
    shape: AreaShape = "rectangle"
    size: tuple = (0.0, 0.0)             # rectangle: (w, h), scene units, each >= 0
    radius: float = 0.0                  # disc, sphere: scene units, >= 0
    normal: tuple = (0.0, -1.0, 0.0)     # rectangle, disc: the plane's normal, not zero

    @property
    def has_size(self) -> bool:
        """Whether the area is more than its centre (some extent > 0)."""
        extents = self.size if self.shape == "rectangle" else (self.radius,)
        return any(float(x) > 0.0 for x in extents)


@dataclass
class PointLight:
    """A local light at `position`, attenuated by 1 / (c + l d + q d^2); with an `area`, the
    ray tracer's area light centred there (LightArea)."""
    position: tuple = (0.0, 0.0, 5.0)
    intensity: tuple = (1.0, 1.0, 1.0)
    attenuation: tuple = (1.0, 0.0, 0.0)
    shadow: Shadow = field(default_factory=Shadow)   # its shadow map: six cube faces
    area: LightArea | None = None


@dataclass
class ObjectMatrices:
    model: np.ndarray            # (4, 4) world matrix, camera-relative: T(-origin) M_world
    normal: np.ndarray           # (3, 3) normal matrix of M_world (transforms.normal_matrix)


@dataclass
class FrameMatrices:
    """Everything both pipelines need from the scene's geometry for one image size.

    Camera-relative coordinates (docs/conventions.md): world positions are handed to the
    pipelines relative to `origin` (the eye), so that float32 keeps its precision near the
    camera however far the scene lies from the world origin. `view` is then a rotation only;
    the eye and point lights go through `relative()`.
    """
    view: np.ndarray
    projection: np.ndarray
    objects: list[ObjectMatrices]
    origin: np.ndarray = field(default_factory=lambda: np.zeros(3))
    size: tuple[int, int] = (1, 1)           # (width, height) of the image they are for
    # The projection before a sample offset's jitter (None: `projection` has none). What the
    # camera pass draws is made for it, the same at every sample offset (renderer/core/drawn.py).
    unjittered_projection: np.ndarray | None = None

    @property
    def camera_projection(self) -> np.ndarray:
        """The projection without the sample offset's jitter."""
        return self.projection if self.unjittered_projection is None else self.unjittered_projection

    def relative(self, points) -> np.ndarray:
        """World points (..., 3) relative to the origin, in float64."""
        return np.asarray(points, dtype=np.float64) - self.origin


@dataclass
class Scene:
    camera: Camera = field(default_factory=Camera)
    objects: list[SceneObject] = field(default_factory=list)
    directional_lights: list[DirectionalLight] = field(default_factory=list)
    point_lights: list[PointLight] = field(default_factory=list)
    ambient: tuple = (0.1, 0.1, 0.1)
    background: tuple = (0.0, 0.0, 0.0)
    name: str = "scene"
    source: str = ""             # file it was read from, if any
    # "phong" (the notes' lighting equation) or "physical" (radiometric units: renderer/core/
    # physical.py, which each method's options' scene_for applies)
    model: str = "phong"

    def world_matrices(self) -> list[np.ndarray]:
        """World matrix of each object, parents applied (M_world = M_parent_world · M_local).

        Iterative, so that a parent chain of any length works: each object's chain is walked
        up to the first object whose world matrix is known (or a root), then multiplied back
        down in the same order as the recursive definition. A parent cycle is a ValueError
        (scene files refuse one first: renderer/core/scene_file.py)."""
        by_name = {obj.name: obj for obj in self.objects}
        cache: dict[str, np.ndarray] = {}
        for start in self.objects:
            chain: list[SceneObject] = []          # start, its parent, ... up to a known one
            on_chain: set[str] = set()
            obj: SceneObject | None = start
            while obj is not None and obj.name not in cache:
                if obj.name in on_chain:
                    raise ValueError(f"parent cycle through object {obj.name!r}")
                chain.append(obj)
                on_chain.add(obj.name)
                obj = None if obj.parent is None else by_name[obj.parent]
            above = None if obj is None else cache[obj.name]
            for link in reversed(chain):
                local = link.transform.matrix()
                above = local if above is None else above @ local
                cache[link.name] = above
        return [cache[obj.name] for obj in self.objects]

    def matrices(self, width: int, height: int, sample_offset=(0.0, 0.0)) -> FrameMatrices:
        """View, projection and per-object matrices, camera-relative (FrameMatrices), in float64.
        `sample_offset` (dx, dy): where in each pixel to sample, in pixels from its centre
        (GL window coordinates); the projection becomes transforms.jitter(dx, dy, W, H) @ P."""
        origin = np.asarray(self.camera.eye, dtype=np.float64)
        to_origin = transforms.translate(*(-origin))
        cam = self.camera
        unjittered = projection = cam.projection_matrix(width / height)
        if tuple(sample_offset) != (0.0, 0.0):
            projection = transforms.jitter(*sample_offset, width, height) @ projection
        return FrameMatrices(
            view=transforms.look_at_rotation(cam.eye, cam.look, cam.up),
            projection=projection,
            objects=[ObjectMatrices(to_origin @ m, transforms.normal_matrix(m))
                     for m in self.world_matrices()],
            origin=origin,
            size=(int(width), int(height)),
            unjittered_projection=None if projection is unjittered else unjittered,
        )

    def world_shapes(self) -> list[WorldSphere | WorldPlane | None]:
        """Each object's analytic shape in camera-relative world coordinates (relative to the
        eye, as `matrices()` hands meshes to the pipelines), None for an object of triangles;
        a ValueError where a transform breaks the shape (`world_shape`)."""
        origin = np.asarray(self.camera.eye, dtype=np.float64)
        return [None if obj.shape is None else world_shape(obj.shape, m, origin)
                for obj, m in zip(self.objects, self.world_matrices())]

    def shading_modes(self) -> list[str]:
        """The shading modes the scene uses, in a fixed order."""
        used = {obj.material.shading for obj in self.objects}
        return [mode for mode in SHADING_MODES if mode in used]

    def with_shading(self, mode: ShadingMode) -> "Scene":
        """A copy in which every material uses shading `mode`; meshes are shared, not copied."""
        if mode not in SHADING_MODES:
            raise ValueError(f"shading must be one of {', '.join(SHADING_MODES)}, got {mode!r}")
        objects = [replace(obj, material=replace(obj.material, shading=mode)) for obj in self.objects]
        return replace(self, objects=objects)

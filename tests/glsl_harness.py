"""A test shader of tests/glsl/ run over a small image (the GLSL-against-twin tests): one
fragment per pixel of a full-screen triangle, its output read back as a (height, width,
components) array, row 0 at the bottom (GL's, so pixel (x, y) is gl_FragCoord.xy)."""

from pathlib import Path

import numpy as np

from renderer.gpu.context import activate
from renderer.gpu.shaders import shader_source

GLSL = Path(__file__).parent / "glsl"


class ShaderProbe:
    """`with ShaderProbe(ctx, "x.frag", defines, (W, H), components=2) as shader:` then
    `shader.run(u_k=3)` -> uint32 (or float32 with dtype="f4") array (H, W, components)."""

    def __init__(self, ctx, fragment: str, defines: dict, size, components: int, dtype: str = "u4"):
        activate(ctx)             # another test may have left another context current
        self.size, self.components, self.dtype = size, components, dtype
        self.program = ctx.program(vertex_shader=shader_source("fullscreen.vert", directory=GLSL).text,
                                   fragment_shader=shader_source(fragment, defines, directory=GLSL).text)
        self.texture = ctx.texture(size, components, dtype=dtype)
        self.framebuffer = ctx.framebuffer([self.texture])
        self.vao = ctx.vertex_array(self.program, [])

    def write(self, uniforms: dict) -> None:
        """Raw uniform values (NumPy arrays, as RaySampling.uniforms()) where the program has them."""
        for name, value in uniforms.items():
            if name in self.program:
                self.program[name].write(np.asarray(value).tobytes())

    def run(self, **values) -> np.ndarray:
        for name, value in values.items():
            if name in self.program:           # a uniform the variant does not use is left out
                self.program[name].value = value
        self.framebuffer.use()
        self.framebuffer.clear()
        self.vao.render(vertices=3)
        kind = np.uint32 if self.dtype == "u4" else np.float32
        width, height = self.size
        return np.frombuffer(self.texture.read(), kind).reshape(height, width, self.components)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        for thing in (self.vao, self.framebuffer, self.texture, self.program):
            thing.release()


def float_probe(ctx, fragment: str, inputs: dict, outputs: int, defines: dict | None = None,
                uniforms: dict | None = None) -> list[np.ndarray]:
    """Run test shader `fragment` once over the size of its inputs: `inputs` {sampler name:
    (H, W, 3) float32 array}, each bound as an RGB32F texture read with texelFetch at the
    fragment's pixel; `uniforms` {name: value} set with .value; the `outputs` RGBA32F colour
    attachments read back, (H, W, 4) each, row 0 at the bottom."""
    activate(ctx)
    height, width = next(iter(inputs.values())).shape[:2]
    program = ctx.program(vertex_shader=shader_source("fullscreen.vert", directory=GLSL).text,
                          fragment_shader=shader_source(fragment, defines or {}, directory=GLSL).text)
    textures = [ctx.texture((width, height), 3, np.ascontiguousarray(a, np.float32).tobytes(), dtype="f4")
                for a in inputs.values()]
    targets = [ctx.texture((width, height), 4, dtype="f4") for _ in range(outputs)]
    framebuffer = ctx.framebuffer(targets)
    vao = ctx.vertex_array(program, [])
    try:
        for unit, (texture, name) in enumerate(zip(textures, inputs)):
            texture.filter = (ctx.NEAREST, ctx.NEAREST)
            texture.use(unit)
            program[name].value = unit
        for name, value in (uniforms or {}).items():
            program[name].value = value
        framebuffer.use()
        vao.render(vertices=3)
        return [np.frombuffer(t.read(), np.float32).reshape(height, width, 4) for t in targets]
    finally:
        for thing in (vao, framebuffer, program, *textures, *targets):
            thing.release()
